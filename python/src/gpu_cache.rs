//! The process's GPU and each scene's cached GPU renderer: what `glint.Scene` keeps between
//! renders and `glint.render` reuses.

use glint::gpu::{GpuContext, GpuRenderer, Traversal};
use glint::scene as scenes;
use std::sync::OnceLock;

/// The process's GPU, opened by the first render that wants one and kept: opening a Vulkan
/// device takes longer than a small render.
static GPU: OnceLock<Result<GpuContext, String>> = OnceLock::new();

pub fn gpu_context() -> Result<&'static GpuContext, &'static str> {
    GPU.get_or_init(|| GpuContext::new().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(String::as_str)
}

/// A scene's GPU renderer with its compiled kernel, reused by the next render of the scene
/// when only the camera and the per-render settings differ (`same_objects`).
pub struct GpuCache {
    /// The scene the renderer was made for (its objects, image size and features).
    pub scene: scenes::Scene,
    /// Whether its kernel accumulates AOVs.
    pub aovs: bool,
    pub traversal: Traversal,
    pub renderer: GpuRenderer<'static>,
}

/// Whether a renderer made for `a` renders `b` once given `b`'s parameters: everything but
/// the camera, spp, seed, max_bounces, the background, light sampling and the sampler (all in
/// `Params`) is the same. The light sampler is not only `Params`: the tree is its own buffer.
pub fn same_objects(a: &scenes::Scene, b: &scenes::Scene) -> bool {
    a.render.width == b.render.width
        && a.render.height == b.render.height
        && a.render.russian_roulette == b.render.russian_roulette
        && a.render.light_sampler == b.render.light_sampler
        && a.materials == b.materials
        && a.spheres == b.spheres
        && a.quads == b.quads
        && a.lights == b.lights
        && a.environment == b.environment
        && a.textures == b.textures
        && a.triangles == b.triangles
}
