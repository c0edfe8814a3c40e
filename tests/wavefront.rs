//! The wavefront layout (src/gpu/wavefront.rs) traces the megakernel's paths stage by stage:
//! each path draws the same random numbers and does the same arithmetic, and the samples are
//! folded into the accumulators in the same order, so the images must be bit-identical.

mod common;
use common::{gpu, shipped_scene, sized};
use glint::gpu::GpuRenderer;
use glint::output::Image;
use glint::render::{render_image, Renderer};
use glint::scene::KernelScene;

fn render(scene: &KernelScene, wave_paths: Option<u32>, spp: u32, batch: u32) -> (Image, Image) {
    let ctx = gpu().unwrap();
    let mut renderer = GpuRenderer::new(ctx, scene).unwrap();
    if let Some(paths) = wave_paths {
        renderer.use_wavefront(paths).unwrap();
    }
    let mean = render_image(&mut renderer, spp, batch).unwrap();
    (mean, renderer.read_variance().unwrap())
}

fn differing_pixels(a: &Image, b: &Image) -> usize {
    assert_eq!(a.pixels.len(), b.pixels.len());
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(x, y)| x != y)
        .count()
}

fn assert_same_as_megakernel(scene: &KernelScene, wave_paths: u32, spp: u32, batch: u32) {
    let (mega_mean, mega_var) = render(scene, None, spp, batch);
    let (wave_mean, wave_var) = render(scene, Some(wave_paths), spp, batch);
    let differing = differing_pixels(&mega_mean, &wave_mean);
    eprintln!(
        "{differing} of {} pixel means differ",
        mega_mean.pixels.len()
    );
    assert_eq!(differing, 0);
    assert_eq!(differing_pixels(&mega_var, &wave_var), 0);
}

/// Glass, metal and light sampling, several waves per batch (3 spp a wave: 7 spp in batches
/// of 5 is waves of 3, 2 and 2), and batches merged into the totals.
#[test]
fn wavefront_renders_the_megakernels_image() {
    if gpu().is_none() {
        return;
    }
    let scene = sized(shipped_scene("cornell-materials.toml"), 40, 3);
    assert_same_as_megakernel(&scene, 3 * 40 * 40, 7, 5);
}

#[test]
fn wavefront_renders_the_megakernels_image_without_light_sampling() {
    if gpu().is_none() {
        return;
    }
    let mut scene = sized(shipped_scene("cornell.toml"), 40, 5);
    scene.params.light_sampling = 0;
    assert_same_as_megakernel(&scene, 1 << 16, 6, 6);
}
