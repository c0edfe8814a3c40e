//! The denoiser's auxiliary images (AOVs), as a renderer reads them back: the per-pixel mean of
//! the albedo and shading normal at each path's first non-specular vertex, and of the first
//! hit's camera distance. The kernel side is `shaders/integrator/aov.wgsl` (mirror: `src/cpu/integrator/aov.rs`).

use crate::image::output::Image;

/// Depth of a camera ray that leaves the scene: +inf stands for it, as a finite value, so
/// running means stay finite (the kernel's `shaders/integrator/aov.wgsl` has the same).
pub const BACKGROUND_DEPTH: f32 = 1e30;

#[derive(Clone, Debug, PartialEq)]
pub struct Aovs {
    /// Reflectance in [0, 1] (emitters and the background: their radiance clamped to 1).
    pub albedo: Image,
    /// World-space shading normal, facing the incoming ray; averaged, not renormalised, so
    /// pixels on edges are shorter than 1. The background contributes zero.
    pub normal: Image,
    /// Camera distance of the first hit, the same value in all three channels.
    pub depth: Image,
}

impl Aovs {
    /// The three images from per-pixel [albedo r, g, b, depth] and [normal x, y, z, _].
    pub fn from_vec4s(
        width: u32,
        height: u32,
        albedo_depth: &[[f32; 4]],
        normal: &[[f32; 4]],
    ) -> Aovs {
        let image = |pixels: Vec<[f32; 3]>| Image {
            width,
            height,
            pixels,
        };
        Aovs {
            albedo: image(albedo_depth.iter().map(|p| [p[0], p[1], p[2]]).collect()),
            normal: image(normal.iter().map(|p| [p[0], p[1], p[2]]).collect()),
            depth: image(albedo_depth.iter().map(|p| [p[3]; 3]).collect()),
        }
    }
}
