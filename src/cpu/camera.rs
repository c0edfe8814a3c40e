//! Pinhole camera (WGSL side: `shaders/camera.wgsl`).

use super::Ray;
use crate::shader_types::Params;
use glam::Vec3;

pub fn camera_ray(params: &Params, px: u32, py: u32, jitter: (f32, f32)) -> Ray {
    let ndc_x = (px as f32 + jitter.0) / params.width as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - (py as f32 + jitter.1) / params.height as f32 * 2.0;
    let dir = (Vec3::from(params.forward)
        + ndc_x * Vec3::from(params.right)
        + ndc_y * Vec3::from(params.up))
    .normalize();
    Ray {
        origin: Vec3::from(params.eye),
        dir,
    }
}
