//! Thin-lens camera (WGSL side: `shaders/core/camera.wgsl`); a pinhole when the lens radius is
//! 0, or an orthographic camera (`Params::projection`).

use crate::cpu::core::frame::PI;
use crate::cpu::core::ray::Ray;
use crate::kernel::types::{Params, PROJECTION_ORTHOGRAPHIC};
use glam::{Vec2, Vec3};

/// Uniform point in the unit disk (polar mapping; r = √u makes it uniform in area).
pub fn sample_unit_disk(u: (f32, f32)) -> Vec2 {
    let r = u.0.sqrt();
    let phi = 2.0 * PI * u.1;
    Vec2::new(r * phi.cos(), r * phi.sin())
}

pub fn camera_ray(params: &Params, px: u32, py: u32, jitter: (f32, f32), lens: (f32, f32)) -> Ray {
    let ndc_x = (px as f32 + jitter.0) / params.width as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - (py as f32 + jitter.1) / params.height as f32 * 2.0;
    if params.projection == PROJECTION_ORTHOGRAPHIC {
        // The jittered point on the image plane (through the eye, across the view; `right` and
        // `up` span half the view in world units), looking along the view direction. No lens:
        // `lens` goes unused.
        return Ray {
            origin: Vec3::from(params.eye)
                + ndc_x * Vec3::from(params.right)
                + ndc_y * Vec3::from(params.up),
            dir: Vec3::from(params.forward),
        };
    }
    // `forward` is unit length, so this point lies on the focus plane.
    let through = Vec3::from(params.forward)
        + ndc_x * Vec3::from(params.right)
        + ndc_y * Vec3::from(params.up);
    let disk = sample_unit_disk(lens);
    let offset = disk.x * Vec3::from(params.lens_right) + disk.y * Vec3::from(params.lens_up);
    let dir = (through * params.focus_distance - offset).normalize();
    Ray {
        origin: Vec3::from(params.eye) + offset,
        dir,
    }
}

/// The film's area: on the plane at unit distance (perspective) or in world units
/// (orthographic). `right` and `up` span half of it each.
pub fn film_area(params: &Params) -> f32 {
    4.0 * Vec3::from(params.right).length() * Vec3::from(params.up).length()
}

/// The solid-angle density with which a camera ray, through a point of the film uniform over
/// the whole image, leaves a point of a perspective camera's lens along `dir`: 1 / (A cos³ θ),
/// A the film's area at unit distance, θ the angle to `forward`; 0 behind the camera.
/// Bidirectional path tracing compares its strategies with it (and weights light tracing's
/// splats by it): one camera path per pixel sample spreads over the whole film just as one
/// light path per pixel sample does.
pub fn camera_direction_pdf(params: &Params, dir: Vec3) -> f32 {
    let cos_theta = dir.dot(Vec3::from(params.forward));
    if cos_theta <= 0.0 {
        return 0.0;
    }
    1.0 / (film_area(params) * cos_theta * cos_theta * cos_theta)
}

/// A point seen through the camera: the lens point it is seen from, the unit direction to it
/// from there, the pixel it lands in, and the density of that direction
/// ([`camera_direction_pdf`]).
#[derive(Clone, Copy, Debug)]
pub struct CameraView {
    pub lens_point: Vec3,
    pub dir: Vec3,
    pub distance: f32,
    pub pixel_x: u32,
    pub pixel_y: u32,
    pub pdf_direction: f32,
    /// False when the point is behind the camera or outside the image.
    pub visible: bool,
}

/// Where a perspective camera sees `point` from the lens point at `lens` (uniform numbers, as
/// `camera_ray` takes them): the inverse of `camera_ray`. The ray from the lens point through
/// the point meets the focus plane where the pinhole ray of the same film position does.
pub fn camera_view(params: &Params, point: Vec3, lens: (f32, f32)) -> CameraView {
    let disk = sample_unit_disk(lens);
    let offset = disk.x * Vec3::from(params.lens_right) + disk.y * Vec3::from(params.lens_up);
    let lens_point = Vec3::from(params.eye) + offset;
    let to_point = point - lens_point;
    let distance = to_point.length();
    let mut view = CameraView {
        lens_point,
        dir: Vec3::Z,
        distance,
        pixel_x: 0,
        pixel_y: 0,
        pdf_direction: 0.0,
        visible: false,
    };
    if distance <= 0.0 {
        return view;
    }
    view.dir = to_point / distance;
    let forward = Vec3::from(params.forward);
    let cos_theta = view.dir.dot(forward);
    if cos_theta <= 0.0 {
        return view;
    }
    // The film position: (focus-plane point − eye) / focus distance = forward + x right + y up.
    let through = (offset + view.dir * (params.focus_distance / cos_theta)) / params.focus_distance;
    let right = Vec3::from(params.right);
    let up = Vec3::from(params.up);
    let ndc_x = through.dot(right) / right.dot(right);
    let ndc_y = through.dot(up) / up.dot(up);
    let fx = (ndc_x + 1.0) * 0.5 * params.width as f32;
    let fy = (1.0 - ndc_y) * 0.5 * params.height as f32;
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(fx >= 0.0 && fx < params.width as f32 && fy >= 0.0 && fy < params.height as f32) {
        return view;
    }
    view.pixel_x = (fx as u32).min(params.width - 1);
    view.pixel_y = (fy as u32).min(params.height - 1);
    view.pdf_direction = camera_direction_pdf(params, view.dir);
    view.visible = true;
    view
}
