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
