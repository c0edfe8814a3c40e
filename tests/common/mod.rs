//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod chi2;
pub mod probe;

use glint::cpu::renderer::CpuRenderer;
use glint::gpu::{GpuContext, GpuRenderer};
use glint::output::Image;
use glint::render::render_image;
use glint::scene::{KernelScene, Scene};
use std::path::Path;
use std::sync::OnceLock;

/// The test GPU: a Vulkan adapter (lavapipe in CI). A missing device fails the test, so a
/// broken driver install cannot pass as green; set GLINT_SKIP_GPU_TESTS=1 to skip on purpose.
pub fn gpu() -> Option<&'static GpuContext> {
    static CTX: OnceLock<Option<GpuContext>> = OnceLock::new();
    CTX.get_or_init(|| {
        if std::env::var_os("GLINT_SKIP_GPU_TESTS").is_some() {
            eprintln!("GLINT_SKIP_GPU_TESTS is set: skipping GPU checks");
            return None;
        }
        let ctx = GpuContext::new().unwrap_or_else(|e| {
            panic!(
                "no Vulkan device ({e}); install mesa-vulkan-drivers or set GLINT_SKIP_GPU_TESTS=1"
            )
        });
        // wgpu must not have fallen back to another API: the GL path renders differently.
        assert_eq!(ctx.adapter_info.backend, wgpu::Backend::Vulkan);
        Some(ctx)
    })
    .as_ref()
}

pub fn scene(toml: &str) -> Scene {
    Scene::parse(toml, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

pub fn kernel_scene(toml: &str) -> KernelScene {
    scene(toml).kernel_scene()
}

pub fn render_cpu(scene: &KernelScene, spp: u32) -> Image {
    render_image(&mut CpuRenderer::new(scene), spp, spp).unwrap()
}

pub fn render_gpu(ctx: &GpuContext, scene: &KernelScene, spp: u32) -> Image {
    render_image(&mut GpuRenderer::new(ctx, scene).unwrap(), spp, spp).unwrap()
}

/// Renders on the CPU and, where there is a GPU, on the GPU too: (device name, image) pairs.
pub fn render_both(scene: &KernelScene, spp: u32) -> Vec<(&'static str, Image)> {
    let mut out = vec![("cpu", render_cpu(scene, spp))];
    if let Some(ctx) = gpu() {
        out.push(("gpu", render_gpu(ctx, scene, spp)));
    }
    out
}

/// The Cornell box from scenes/cornell.toml.
pub fn cornell() -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml")).unwrap()
}
