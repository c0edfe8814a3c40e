//! Texels split over several storage bindings (src/kernel/texels.rs): a scene whose two images
//! straddle forced 256-texel windows renders on the GPU bit for bit as the one-binding kernel
//! does, and traces the CPU's paths; a scene needing more windows than four is exit-2 input.

use crate::common;

use glint::error::InputError;
use glint::gpu::GpuRenderer;
use glint::kernel::texels::TexelBinding;
use glint::kernel::types::TEXTURE_CHECKER;
use glint::kernel::KernelScene;
use glint::render::render_image;
use glint::scene::Scene;
use std::path::Path;

/// The artificial binding limit: 256 texels of 16 bytes per window.
const WINDOW_BYTES: u64 = 4096;
const TEXELS_PER_WINDOW: u64 = WINDOW_BYTES / 16;

/// A PNG of `width`×`height` texels whose channels vary from texel to texel.
fn write_png(path: &Path, width: u32, height: u32, salt: u32) {
    let image = image::RgbImage::from_fn(width, height, |x, y| {
        image::Rgb([0, 1, 2].map(|c| ((37 * x + 91 * y + 53 * c + salt) % 200 + 40) as u8))
    });
    image.save(path).unwrap();
}

/// A box of diffuse walls under a quad light: an image-textured floor and back wall (24×20
/// texels) and a rough gold sphere whose roughness is a 20×20 image. Its 880 texels take four
/// windows of 256, and each image straddles a window boundary whichever is stored first.
fn scene(dir: &Path, size: u32, seed: u32) -> KernelScene {
    write_png(&dir.join("color.png"), 24, 20, 0);
    write_png(&dir.join("roughness.png"), 20, 20, 7);
    let text = format!(
        r#"[camera]
eye = [0.0, 1.0, -3.4]
target = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
[render]
width = {size}
height = {size}
spp = 1
max_bounces = 4
background = [0.0, 0.0, 0.0]
seed = {seed}
[materials.white]
type = "diffuse"
color = [0.73, 0.73, 0.73]
[materials.poster]
type = "diffuse"
color = {{ texture = "color.png" }}
[materials.gold]
type = "metal"
color = [1.0, 0.78, 0.34]
roughness = {{ texture = "roughness.png" }}
[materials.light]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
strength = 6.0
# Floor, back wall, ceiling, left and right walls.
[[quads]]
corner = [-1.0, 0.0, -1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "poster"
[[quads]]
corner = [-1.0, 0.0, 1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "poster"
[[quads]]
corner = [-1.0, 2.0, -1.0]
u = [0.0, 0.0, 2.0]
v = [2.0, 0.0, 0.0]
material = "white"
[[quads]]
corner = [-1.0, 0.0, -1.0]
u = [0.0, 0.0, 2.0]
v = [0.0, 2.0, 0.0]
material = "white"
[[quads]]
corner = [1.0, 0.0, -1.0]
u = [0.0, 2.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "white"
[[quads]]
corner = [-0.3, 1.99, -0.3]
u = [0.6, 0.0, 0.0]
v = [0.0, 0.0, 0.6]
material = "light"
[[spheres]]
center = [0.2, 0.5, 0.2]
radius = 0.5
material = "gold"
"#
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene()
}

#[test]
fn every_image_straddles_a_window_boundary() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), 8, 0);
    assert_eq!(scene.texels.len(), 880);
    let images: Vec<_> = scene
        .textures
        .iter()
        .filter(|t| t.kind != TEXTURE_CHECKER)
        .collect();
    assert_eq!(images.len(), 2);
    for t in images {
        let first = t.first_texel as u64;
        let last = first + (t.width * t.height) as u64 - 1;
        assert_ne!(
            first / TEXELS_PER_WINDOW,
            last / TEXELS_PER_WINDOW,
            "texels {first}..={last} lie in one window"
        );
    }
}

/// The split kernel renders the image of the one-binding kernel bit for bit (the same texels,
/// read through another path), and the CPU's by the criterion of tests/suite/gpu_vs_cpu.rs.
#[test]
fn split_texels_render_the_same_image() {
    let Some(ctx) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let mut agreement = common::PathAgreement::default();
    for seed in [3, 4] {
        let scene = scene(dir.path(), 48, seed);
        let mut split = GpuRenderer::with_texel_window(ctx, &scene, WINDOW_BYTES).unwrap();
        assert_eq!(
            split.texel_binding(),
            TexelBinding::Windows {
                texels_per_window: TEXELS_PER_WINDOW as u32
            }
        );
        let split = render_image(&mut split, 1, 1).unwrap();
        let mut one = GpuRenderer::new(ctx, &scene).unwrap();
        assert_eq!(one.texel_binding(), TexelBinding::One);
        let one = render_image(&mut one, 1, 1).unwrap();
        let differing = split
            .pixels
            .iter()
            .zip(&one.pixels)
            .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
            .count();
        assert_eq!(differing, 0, "seed {seed}: {differing} pixels differ");
        agreement.add(&common::render_cpu(&scene, 1), &split);
    }
    agreement.check(0.99);
}

/// Texels needing more windows than the kernel has (here 7 of 128 texels) are bad input, named
/// with their size and the binding limit, before anything is uploaded.
#[test]
fn texels_beyond_every_window_are_refused() {
    let Some(ctx) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path(), 8, 0);
    let Err(e) = GpuRenderer::with_texel_window(ctx, &scene, 2048) else {
        panic!("880 texels were bound in windows of 128");
    };
    let e = e
        .downcast_ref::<InputError>()
        .unwrap_or_else(|| panic!("not bad input: {e}"))
        .to_string();
    assert!(e.contains("texture texels need 14080 bytes"), "{e}");
    assert!(e.contains("is 2048 bytes"), "{e}");
}
