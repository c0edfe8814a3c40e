//! Auxiliary outputs for the denoiser (WGSL side: `shaders/integrator/aov.wgsl`): per camera path, the
//! albedo and shading normal at the first non-specular vertex (mirror and glass chains are
//! followed, as Open Image Denoise asks) and the camera distance of the first hit.

use crate::cpu::geometry::hit::Hit;
use crate::cpu::materials::material::is_delta;
use crate::image::aov::BACKGROUND_DEPTH;
use crate::kernel::types::{Material, Params};
use glam::Vec3;

/// Whether the render is asked for AOVs (the kernel also needs them compiled in).
pub fn aovs_on(params: &Params) -> bool {
    params.aovs != 0
}

/// One path's AOVs, filled in as the path meets its first surfaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathAov {
    pub albedo: Vec3,
    pub normal: Vec3,
    pub depth: f32,
    /// True once the first non-specular vertex (or an emitter, or the background) is recorded.
    pub found: bool,
}

pub fn aov_start() -> PathAov {
    PathAov {
        albedo: Vec3::ZERO,
        normal: Vec3::ZERO,
        depth: BACKGROUND_DEPTH,
        found: false,
    }
}

/// The path's ray left the scene: the clamped radiance it sees there (the background, or the
/// environment map in its direction) is the albedo.
pub fn aov_record_miss(aov: &mut PathAov, escaped: Vec3) {
    if !aov.found {
        aov.albedo = escaped.clamp(Vec3::ZERO, Vec3::ONE);
        aov.found = true;
    }
}

/// The ray of segment `bounce` hit material `m`: the first hit gives the depth; the first
/// emitter or non-specular surface gives the albedo (an emitter's clamped radiance) and normal.
pub fn aov_record_hit(aov: &mut PathAov, bounce: u32, hit: &Hit, m: &Material) {
    if bounce == 0 {
        aov.depth = hit.t;
    }
    if aov.found {
        return;
    }
    let emission = Vec3::from(m.emission);
    if emission.cmpgt(Vec3::ZERO).any() {
        aov.albedo = emission.clamp(Vec3::ZERO, Vec3::ONE);
    } else if !is_delta(m) {
        aov.albedo = Vec3::from(m.albedo);
    } else {
        return;
    }
    aov.normal = hit.shading_normal;
    aov.found = true;
}

/// Running mean of path AOVs: a batch's in the kernel, and the pixel's totals.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AovMean {
    pub albedo: Vec3,
    pub normal: Vec3,
    pub depth: f32,
}

/// Adds the (done + 1)-th sample of the batch.
pub fn aov_mean_add(mean: &mut AovMean, aov: &PathAov, done: u32) {
    let w = 1.0 / (done + 1) as f32;
    mean.albedo += (aov.albedo - mean.albedo) * w;
    mean.normal += (aov.normal - mean.normal) * w;
    mean.depth += (aov.depth - mean.depth) * w;
}

/// Merges the batch's means (`n_new` samples) into the pixel's (`n_old` samples before them).
pub fn aov_merge(pixel: &mut AovMean, batch: &AovMean, n_old: f32, n_new: f32) {
    let w = n_new / (n_old + n_new);
    pixel.albedo += (batch.albedo - pixel.albedo) * w;
    pixel.depth += (batch.depth - pixel.depth) * w;
    pixel.normal += (batch.normal - pixel.normal) * w;
}
