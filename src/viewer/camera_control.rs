//! Camera moves for the viewer: orbit, pan, dolly and fly, as pure functions of a
//! [`Camera`], so they are tested without a window.
//!
//! Screen deltas are in window pixels, x to the right and y down, as winit reports the cursor.
//! Every move keeps `up` as the scene gave it; orbiting stops short of the poles so the view
//! direction never becomes parallel to `up` (the camera basis would be undefined there).
//!
//! An orthographic camera orbits, pans and flies as a perspective one does (it pans by its
//! view's height per window height); its dolly zooms instead, scaling the view's height by
//! the same factor per step and leaving the eye where it is: moving an orthographic camera
//! along its view changes nothing in the image but where the image plane cuts the scene.

use crate::scene::limits::{MAX_COORDINATE, MIN_LENGTH};
use crate::scene::{Camera, Projection};
use glam::Quat;

/// Orbit angle per pixel of drag, in radians: a drag across a 512-pixel window turns ~147°.
pub const ORBIT_RADIANS_PER_PIXEL: f32 = 0.005;
/// Distance factor per wheel step towards the target.
pub const DOLLY_FACTOR_PER_STEP: f32 = 0.85;
/// Closest approach of the eye to the target, as a fraction of the distance a dolly starts at;
/// also an absolute floor so the basis stays finite.
const MIN_DISTANCE: f32 = 1e-4;
/// Smallest angle between the view direction and ±up, in radians (1°).
const POLE_MARGIN: f32 = 0.017_453_3;

fn distance(cam: &Camera) -> f32 {
    (cam.eye - cam.target).length()
}

/// Turns the eye around the target: dragging right moves the eye to the camera's left (the
/// scene turns with the cursor), dragging down raises the eye. The distance is kept.
pub fn orbit(cam: &Camera, dx: f32, dy: f32) -> Camera {
    let up = cam.up.normalize();
    let offset = cam.eye - cam.target;
    let dist = offset.length();
    let along_up = offset.dot(up);
    let horizontal = offset - along_up * up;
    // The polar angle from +up; horizontal is never zero because no move reaches a pole.
    let theta = horizontal.length().atan2(along_up);
    let theta = (theta - dy * ORBIT_RADIANS_PER_PIXEL)
        .clamp(POLE_MARGIN, std::f32::consts::PI - POLE_MARGIN);
    let yaw = Quat::from_axis_angle(up, -dx * ORBIT_RADIANS_PER_PIXEL);
    let heading = yaw * horizontal.normalize_or(cam.basis().right.cross(up));
    let eye = cam.target + dist * (theta.cos() * up + theta.sin() * heading);
    Camera { eye, ..cam.clone() }
}

/// Slides eye and target in the image plane so the point at the target's depth (any point,
/// for an orthographic camera) follows the cursor; `viewport_height` is the window height in
/// pixels.
pub fn pan(cam: &Camera, dx: f32, dy: f32, viewport_height: u32) -> Camera {
    let b = cam.basis();
    let visible_height = match cam.projection {
        Projection::Perspective { vfov } => 2.0 * distance(cam) * (vfov.to_radians() * 0.5).tan(),
        Projection::Orthographic { height } => height,
    };
    let world_per_pixel = visible_height / viewport_height.max(1) as f32;
    let delta = (-dx * b.right + dy * b.image_up) * world_per_pixel;
    Camera {
        eye: cam.eye + delta,
        target: cam.target + delta,
        ..cam.clone()
    }
}

/// Moves the eye towards the target (`steps` > 0, wheel up) or away from it; it never reaches
/// or passes the target. An orthographic camera zooms instead: its view's height shrinks (or
/// grows) by the same factor, within the lengths a scene file takes.
pub fn dolly(cam: &Camera, steps: f32) -> Camera {
    if let Projection::Orthographic { height } = cam.projection {
        let height = (height * DOLLY_FACTOR_PER_STEP.powf(steps)).clamp(MIN_LENGTH, MAX_COORDINATE);
        return Camera {
            projection: Projection::Orthographic { height },
            ..cam.clone()
        };
    }
    let b = cam.basis();
    let dist = (distance(cam) * DOLLY_FACTOR_PER_STEP.powf(steps)).max(MIN_DISTANCE);
    Camera {
        eye: cam.target + dist * b.w,
        ..cam.clone()
    }
}

/// Translates eye and target together along image-right, `up` and the view direction, in
/// units of the eye–target distance, so the fly speed scales with the scene.
pub fn fly(cam: &Camera, right: f32, up: f32, forward: f32) -> Camera {
    let b = cam.basis();
    let delta = distance(cam) * (right * b.right + up * cam.up.normalize() - forward * b.w);
    Camera {
        eye: cam.eye + delta,
        target: cam.target + delta,
        ..cam.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn cornell() -> Camera {
        Camera {
            eye: Vec3::new(278.0, 278.0, -800.0),
            target: Vec3::new(278.0, 278.0, 0.0),
            up: Vec3::Y,
            projection: Projection::Perspective { vfov: 40.0 },
            aperture: 0.0,
            focus_distance: 800.0,
        }
    }

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn zero_moves_are_identities() {
        let c = cornell();
        assert!(close(orbit(&c, 0.0, 0.0).eye, c.eye, 1e-3));
        assert_eq!(pan(&c, 0.0, 0.0, 512), c);
        assert!(close(dolly(&c, 0.0).eye, c.eye, 1e-3));
        assert_eq!(fly(&c, 0.0, 0.0, 0.0), c);
    }

    #[test]
    fn orbit_keeps_target_and_distance_and_turns_with_the_cursor() {
        let c = cornell();
        let b = c.basis();
        let right = orbit(&c, 40.0, 0.0);
        assert_eq!(right.target, c.target);
        assert!((distance(&right) - distance(&c)).abs() < 1e-2);
        // Dragging right moves the eye to the camera's left, horizontally.
        assert!((right.eye - c.eye).dot(b.right) < 0.0);
        assert!((right.eye.y - c.eye.y).abs() < 1e-3);
        let down = orbit(&c, 0.0, 40.0);
        assert!(down.eye.y > c.eye.y, "dragging down raises the eye");
        assert!((distance(&down) - distance(&c)).abs() < 1e-2);
        // 200 px is 1 radian.
        let turned = (right.eye - c.target)
            .normalize()
            .angle_between((c.eye - c.target).normalize());
        assert!((turned - 40.0 * ORBIT_RADIANS_PER_PIXEL).abs() < 1e-4);
    }

    #[test]
    fn orbit_stops_short_of_the_poles() {
        let c = cornell();
        for dy in [1e5, -1e5] {
            let o = orbit(&c, 13.0, dy);
            let w = (o.eye - o.target).normalize();
            assert!(w.dot(Vec3::Y).abs() < POLE_MARGIN.cos() + 1e-4);
            assert!(o.eye.is_finite());
            // The basis the kernel builds stays defined.
            assert!(o.basis().right.is_finite());
            // And orbiting back from the pole works.
            assert!(orbit(&o, 5.0, -dy.signum() * 10.0).eye.is_finite());
        }
    }

    #[test]
    fn pan_moves_eye_and_target_together_with_the_cursor() {
        let c = cornell();
        let p = pan(&c, 10.0, 0.0, 512);
        assert_eq!(p.eye - c.eye, p.target - c.target);
        // The scene follows the cursor, so the camera goes the other way.
        assert!((p.eye - c.eye).dot(c.basis().right) < 0.0);
        // A full-height drag moves the view by the visible height at the target's depth.
        let full = pan(&c, 0.0, 512.0, 512);
        let visible = 2.0 * 800.0 * (20f32).to_radians().tan();
        assert!(((full.eye.y - c.eye.y) - visible).abs() < 1e-2);
    }

    #[test]
    fn dolly_approaches_the_target_without_passing_it() {
        let c = cornell();
        let d = dolly(&c, 1.0);
        assert!((distance(&d) - 800.0 * DOLLY_FACTOR_PER_STEP).abs() < 1e-2);
        assert_eq!(d.target, c.target);
        let far = dolly(&c, -2.0);
        assert!(distance(&far) > 800.0);
        let very_close = dolly(&c, 1e4);
        assert!(distance(&very_close) > 0.0);
        assert!(very_close.basis().w.dot(c.basis().w) > 0.999);
    }

    fn orthographic(height: f32) -> Camera {
        Camera {
            projection: Projection::Orthographic { height },
            ..cornell()
        }
    }

    #[test]
    fn an_orthographic_camera_pans_by_its_height_and_dollies_by_zooming() {
        let c = orthographic(600.0);
        assert_eq!(pan(&c, 0.0, 0.0, 512), c);
        // A full-height drag moves the view by its height, whatever the distance.
        let full = pan(&c, 0.0, 512.0, 512);
        assert!(((full.eye.y - c.eye.y) - 600.0).abs() < 1e-3);
        assert_eq!(full.eye - c.eye, full.target - c.target);
        // The dolly zooms: the eye stays, the height scales by the dolly's factor.
        let d = dolly(&c, 1.0);
        assert_eq!((d.eye, d.target), (c.eye, c.target));
        let Projection::Orthographic { height } = d.projection else {
            panic!("{d:?}")
        };
        assert!((height - 600.0 * DOLLY_FACTOR_PER_STEP).abs() < 1e-3);
        // Within the lengths a scene file takes, either way.
        for (steps, bound) in [(1e4, MIN_LENGTH), (-1e4, MAX_COORDINATE)] {
            let z = dolly(&c, steps);
            assert_eq!(z.projection, Projection::Orthographic { height: bound });
        }
        // Orbiting keeps the distance and the projection.
        let o = orbit(&c, 40.0, 10.0);
        assert_eq!(o.projection, c.projection);
        assert!((distance(&o) - distance(&c)).abs() < 1e-2);
    }

    #[test]
    fn fly_translates_along_the_view() {
        let c = cornell();
        let f = fly(&c, 0.0, 0.0, 0.5);
        assert!(close(f.eye, c.eye + Vec3::new(0.0, 0.0, 400.0), 1e-2));
        assert!(close(f.target, c.target + Vec3::new(0.0, 0.0, 400.0), 1e-2));
        let up = fly(&c, 0.0, 0.25, 0.0);
        assert!(close(up.eye, c.eye + Vec3::new(0.0, 200.0, 0.0), 1e-2));
        let r = fly(&c, 0.1, 0.0, 0.0);
        assert!(close(r.eye - c.eye, 80.0 * c.basis().right, 1e-2));
    }
}
