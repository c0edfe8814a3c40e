//! What sampling a BSDF returns (WGSL side: `shaders/materials/bsdf.wgsl`).

use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub dir: Vec3,
    /// f · cos / pdf, or the reflectance of a delta lobe; zero when the path is absorbed.
    pub weight: Vec3,
    /// Solid-angle pdf of `dir`; 0 for delta lobes.
    pub pdf: f32,
    /// Light sampling cannot find `dir`, so what the ray reaches counts in full: delta lobes,
    /// smooth refraction among them (material.rs's `transmits_roughly` says which is rough).
    pub is_delta: bool,
}
