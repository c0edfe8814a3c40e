//! The denoiser's AOVs (shaders/integrator/aov.wgsl, src/cpu/integrator/aov.rs): a diffuse wall's albedo is exactly its
//! colour and its normal exactly the quad's; a mirror facing the camera shows the wall behind it;
//! the background and emitters give their clamped radiance; GPU and CPU record the same AOVs;
//! accumulating them leaves the image bit for bit unchanged. And the firefly clamp: it bounds
//! scattered light and never light seen directly.

use crate::common;
use common::{gpu, kernel_scene, PathAgreement};
use glint::gpu::GpuRenderer;
use glint::image::aov::{Aovs, BACKGROUND_DEPTH};
use glint::image::output::Image;
use glint::kernel::KernelScene;
use glint::render::render_image;

/// Renders `spp` samples in batches of `batch` with AOVs on, on the CPU and (where there is
/// one) the GPU: (device, mean, AOVs).
fn render_aovs(scene: &KernelScene, spp: u32, batch: u32) -> Vec<(&'static str, Image, Aovs)> {
    let mut scene = scene.clone();
    scene.params.aovs = 1;
    common::renderers(&scene)
        .into_iter()
        .map(|(name, mut r)| {
            let mean = render_image(r.as_mut(), spp, batch).unwrap();
            (name, mean, r.read_aovs().unwrap())
        })
        .collect()
}

/// A camera 10 units in front of a large quad at z = 0 (normal along −z, towards the camera)
/// of material "wall", lit by a small lamp.
fn facing_wall(wall: &str, extra: &str) -> KernelScene {
    kernel_scene(&format!(
        r#"
[camera]
eye = [0.0, 0.0, -10.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
[render]
width = 16
height = 16
spp = 4
max_bounces = 4
[materials.wall]
{wall}
[materials.green]
type = "diffuse"
color = [0.1, 0.7, 0.2]
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
strength = 4.0
[[quads]]
corner = [-100.0, -100.0, 0.0]
u = [200.0, 0.0, 0.0]
v = [0.0, 200.0, 0.0]
material = "wall"
[[spheres]]
center = [0.0, 40.0, -5.0]
radius = 1.0
material = "lamp"
{extra}
"#
    ))
}

/// The camera distance of the plane z = 0 through the image corners of `facing_wall`:
/// 10·|(tan 20°, tan 20°, 1)|, and a little more for rounding.
fn corner_depth() -> f32 {
    10.0 * (1.0 + 2.0 * 20f32.to_radians().tan().powi(2)).sqrt() * 1.0001
}

#[test]
fn albedo_of_a_diffuse_wall_is_its_colour_and_its_normal_is_exact() {
    let scene = facing_wall("type = \"diffuse\"\ncolor = [0.3, 0.5, 0.7]", "");
    for (device, _, aovs) in render_aovs(&scene, 4, 2) {
        for (i, (albedo, normal)) in aovs
            .albedo
            .pixels
            .iter()
            .zip(&aovs.normal.pixels)
            .enumerate()
        {
            assert_eq!(*albedo, [0.3, 0.5, 0.7], "{device} pixel {i}");
            // The quad's normal, facing the incoming ray: exactly −z.
            assert_eq!(*normal, [0.0, 0.0, -1.0], "{device} pixel {i}");
        }
        // Depth: the distance along the ray to the plane z = 0, from 10 (straight ahead) to
        // 10·|(tan 20°, tan 20°, 1)| in the corners.
        let max_depth = corner_depth();
        for d in &aovs.depth.pixels {
            assert!(d[0] >= 10.0 && d[0] <= max_depth, "{device}: {d:?}");
        }
    }
}

/// A mirror facing the camera reflects the camera rays back past it onto a green wall behind:
/// the albedo is the wall's green (the mirror is followed, not recorded), the normal the wall's
/// facing the reflected rays (+z), and the depth the mirror's distance.
#[test]
fn a_mirror_in_front_of_a_green_wall_shows_green() {
    let green_wall_behind = r#"
[[quads]]
corner = [-100.0, -100.0, -20.0]
u = [200.0, 0.0, 0.0]
v = [0.0, 200.0, 0.0]
material = "green"
"#;
    let scene = facing_wall(
        "type = \"specular\"\ncolor = [0.9, 0.9, 0.9]",
        green_wall_behind,
    );
    for (device, _, aovs) in render_aovs(&scene, 4, 4) {
        for (i, p) in aovs.albedo.pixels.iter().enumerate() {
            assert_eq!(*p, [0.1, 0.7, 0.2], "{device} pixel {i}");
            assert_eq!(aovs.normal.pixels[i], [0.0, 0.0, 1.0], "{device} pixel {i}");
            let depth = aovs.depth.pixels[i][0];
            assert!(
                (10.0..=corner_depth()).contains(&depth),
                "{device} pixel {i}: {depth}"
            );
        }
    }
}

/// Rays that miss everything: the background's radiance clamped to 1 as albedo, a zero normal
/// and the background depth. An emitter seen directly: its clamped emission.
#[test]
fn background_and_emitters_give_their_clamped_radiance() {
    let mut scene = facing_wall(
        "type = \"diffuse\"\ncolor = [0.0, 0.0, 0.0]\nemission = [0.5, 2.0, 1.0]",
        "",
    );
    let (_, _, aovs) = &render_aovs(&scene, 1, 1)[0];
    assert!(aovs.albedo.pixels.iter().all(|p| *p == [0.5, 1.0, 1.0]));
    // Turn the camera away from everything.
    scene.params.forward = [0.0, 0.0, -1.0];
    scene.params.right = [-scene.params.right[0], 0.0, 0.0];
    scene.params.background = [0.25, 3.0, 0.0];
    for (device, _, aovs) in render_aovs(&scene, 2, 1) {
        assert!(
            aovs.albedo.pixels.iter().all(|p| *p == [0.25, 1.0, 0.0]),
            "{device}"
        );
        assert!(
            aovs.normal.pixels.iter().all(|p| *p == [0.0; 3]),
            "{device}"
        );
        assert!(
            aovs.depth.pixels.iter().all(|p| p[0] == BACKGROUND_DEPTH),
            "{device}"
        );
    }
}

/// The GPU and the CPU record the same AOVs for the same paths (a few pixels may differ where
/// f32 rounding sends a path elsewhere, as tests/suite/gpu_vs_cpu.rs explains), over several batches.
#[test]
fn gpu_and_cpu_aovs_agree() {
    if gpu().is_none() {
        return;
    }
    let scene = common::cornell_at(32, 3);
    let renders = render_aovs(&scene, 3, 2);
    let (cpu, gpu_render) = (&renders[0].2, &renders[1].2);
    for (name, a, b) in [
        ("albedo", &cpu.albedo, &gpu_render.albedo),
        ("normal", &cpu.normal, &gpu_render.normal),
        ("depth", &cpu.depth, &gpu_render.depth),
    ] {
        eprintln!("{name}:");
        let mut agreement = PathAgreement::default();
        let abs = |image: &Image| Image {
            pixels: image.pixels.iter().map(|p| p.map(f32::abs)).collect(),
            ..image.clone()
        };
        agreement.add(&abs(a), &abs(b));
        agreement.check(0.99);
    }
}

/// Accumulating AOVs changes no radiance: the mean is bit for bit the same with them on or
/// off, on both devices, and the kernel with AOVs compiled in but not asked for agrees too.
#[test]
fn aovs_do_not_change_the_image() {
    let scene = common::cornell_at(24, 4);
    let plain = common::render_both(&scene, 3);
    let with_aovs = render_aovs(&scene, 3, 3);
    for ((device, a), (_, b, _)) in plain.iter().zip(&with_aovs) {
        assert!(a == b, "{device}: AOVs changed the image");
    }
    if let Some(ctx) = gpu() {
        let variant = glint::kernel::variant::KernelVariant {
            features: glint::kernel::variant::KernelFeatures::ALL,
            ..GpuRenderer::new(ctx, &scene).unwrap().variant()
        };
        let mut all = GpuRenderer::with_variant(ctx, &scene, variant).unwrap();
        assert!(render_image(&mut all, 3, 3).unwrap() == plain[1].1);
    }
}

/// The firefly clamp: a floor lit by a lamp, seen only through one scattering event, so every
/// contribution to a sample is scattered light. Each sample adds at most two (light sampling
/// and the BSDF-sampled hit), so with L = 0.05 no pixel's mean exceeds 0.1, where the unclamped
/// image is 0.6. A clamp above every contribution changes nothing, bit for bit.
#[test]
fn firefly_clamp_limits_scattered_light_only() {
    let scene = common::floor_under_lamp(8, 16, 1);
    let unclamped = common::render_both(&scene, 16);
    let mut clamped = scene.clone();
    clamped.params.radiance_clamp = 0.05;
    let mut loose = scene.clone();
    loose.params.radiance_clamp = 1e30;
    for (((device, free), (_, tight)), (_, high)) in unclamped
        .iter()
        .zip(common::render_both(&clamped, 16))
        .zip(common::render_both(&loose, 16))
    {
        assert!(free.mean() > 0.5, "{device}: {}", free.mean());
        let brightest = tight.pixels.iter().flatten().fold(0.0f32, |m, v| m.max(*v));
        assert!(brightest <= 0.1 + 1e-6, "{device}: {brightest}");
        assert!(tight.mean() > 0.0, "{device}");
        assert!(
            *free == high,
            "{device}: a clamp above every contribution changed the image"
        );
    }
    // Light that has not scattered is never clamped: with no bounces, a camera that sees the
    // lamp sees its full radiance.
    let mut direct = common::floor_under_lamp(8, 1, 1);
    direct.params.max_bounces = 0;
    direct.params.radiance_clamp = 0.05;
    let eye = glam::Vec3::from(direct.params.eye);
    direct.params.forward = (glam::Vec3::new(0.0, 2.0, 0.0) - eye).normalize().into();
    for (device, image) in common::render_both(&direct, 1) {
        let brightest = image.pixels.iter().flatten().fold(0.0f32, |m, v| m.max(*v));
        assert_eq!(brightest, 4.0, "{device}");
    }
}
