//! Environment maps, on the CPU and the GPU: a constant map equals the same constant background
//! (per-pixel Z-test and z of the means), with and without light sampling; white spheres of every
//! material vanish under a white map; a floor under a map bright above the horizon has radiance
//! ρ·L; a map turned by α equals the camera turned by −α; GPU ≡ CPU on scenes/sun.toml; sampling
//! the map lowers the relative MSE at least tenfold; every class of bad map is an exit-2 error;
//! negative texels clamped with a warning; every EXR compression reads back within its codec's
//! error, and OpenEXR's DWAB (tests/images/) as OpenEXR decodes it. The sampler's χ² is in chi2.rs.

use crate::common;
use common::{largest_deviation, render_both, with_light_sampling, write_map, PathAgreement};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::image::compare::compare;
use glint::image::output::Image;
use glint::kernel::KernelScene;
use glint::render::render_image;
use glint::scene::Scene;
use std::path::Path;

/// A scene file's text: `camera`, `render` lines, then `rest`, in `dir` as scene.toml.
fn scene_in(dir: &Path, text: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn header(eye: [f32; 3], target: [f32; 3], vfov: f32, size: u32, bounces: u32) -> String {
    format!(
        "[camera]\neye = {eye:?}\ntarget = {target:?}\nup = [0.0, 1.0, 0.0]\nvfov = {vfov:?}\n\
         [render]\nwidth = {size}\nheight = {size}\nspp = 1\nmax_bounces = {bounces}\n\
         russian_roulette = false\n"
    )
}

/// Renders on the CPU and, where there is one, the GPU, with variance images.
fn render_both_with_variance(scene: &KernelScene, spp: u32) -> Vec<(&'static str, Image, Image)> {
    common::renderers(scene)
        .into_iter()
        .map(|(device, mut renderer)| {
            let (image, variance) = common::render_with_variance(renderer.as_mut(), spp);
            (device, image, variance)
        })
        .collect()
}

const OBJECTS: &str = r#"
[materials.clay]
type = "diffuse"
color = [0.7, 0.4, 0.3]
[materials.floor]
type = "diffuse"
color = [0.5, 0.6, 0.5]
[materials.gold]
type = "metal"
color = [0.9, 0.7, 0.3]
roughness = 0.4
[[spheres]]
center = [-0.6, 0.5, 0.0]
radius = 0.5
material = "clay"
[[spheres]]
center = [0.6, 0.5, 0.2]
radius = 0.5
material = "gold"
[[quads]]
corner = [-3.0, 0.0, -3.0]
u = [0.0, 0.0, 6.0]
v = [6.0, 0.0, 0.0]
material = "floor"
"#;

/// A constant map lights the scene exactly as the same constant background does; with light
/// sampling the map is also sampled as an emitter (MIS with the BSDF), so the two agree in
/// expectation, not sample by sample. The per-pixel Z-test and the z of the image means
/// (glint::image::compare, variances from both renders' variance images) catch any bias; |z| < 5 for
/// the means fails wrongly with probability 6·10⁻⁷, and a 1% Z-test passes ≥ 97% of pixel
/// channels unless something is wrong (its expected rate is 99%, with a standard deviation of
/// 0.4% over 3·24² channels).
#[test]
fn a_constant_map_equals_the_constant_background() {
    let dir = tempfile::tempdir().unwrap();
    let colour = [0.6f32, 0.8, 1.0];
    let map = write_map(dir.path(), "constant.exr", 8, 4, |_, _| colour);
    let camera = header([0.0, 1.5, -3.5], [0.0, 0.4, 0.0], 40.0, 24, 4);
    let background = scene_in(
        dir.path(),
        &format!("{camera}background = {colour:?}\n{OBJECTS}"),
    );
    let environment = scene_in(
        dir.path(),
        &format!(
            "{camera}{OBJECTS}[environment]\nfile = {:?}\n",
            map.file_name().unwrap()
        ),
    );
    let reference = render_both_with_variance(&with_light_sampling(&background, true, 1), 256);
    let (_, b, vb) = &reference[0];
    for light_sampling in [true, false] {
        let scene = with_light_sampling(&environment, light_sampling, 2);
        for (device, a, va) in render_both_with_variance(&scene, 256) {
            let c = compare(&a, b, Some((&va, vb))).unwrap();
            let z = c.z_test.as_ref().unwrap();
            assert!(
                z.z_of_means.abs() < 5.0 && z.pass_rate > 0.97,
                "{device}, light sampling {light_sampling}: {c:?}"
            );
        }
    }
}

/// The white furnace under a white map: an object that neither absorbs nor emits vanishes,
/// every pixel exactly the map's radiance 1. Without light sampling each path ends in the map
/// with weight exactly 1 (f32 rounding aside); with it, delta materials still do (they take no
/// light samples), and a diffuse sphere is 1 in expectation (z of the image mean < 5, its
/// variance from the variance image).
#[test]
fn white_furnace_under_a_white_map() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path(), "white.exr", 16, 8, |_, _| [1.0; 3]);
    for material in [
        "type = \"diffuse\"\ncolor = [1.0, 1.0, 1.0]",
        "type = \"specular\"\ncolor = [1.0, 1.0, 1.0]",
        "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = 0.0",
        "type = \"dielectric\"\nior = 1.5",
    ] {
        let scene = scene_in(
            dir.path(),
            &format!(
                "{}[environment]\nfile = {:?}\n[materials.m]\n{material}\n\
                 [[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"m\"\n",
                header([0.0, 0.0, -4.0], [0.0; 3], 35.0, 24, 64),
                map.file_name().unwrap()
            ),
        );
        for (device, image) in render_both(&with_light_sampling(&scene, false, 3), 8) {
            let worst = largest_deviation(&image, 1.0);
            assert!(worst < 1e-5, "{device}, {material:?}: off by {worst}");
        }
        let delta = !material.contains("diffuse");
        for (device, image, variance) in
            render_both_with_variance(&with_light_sampling(&scene, true, 4), 16)
        {
            if delta {
                let worst = largest_deviation(&image, 1.0);
                assert!(
                    worst < 1e-5,
                    "{device}, {material:?} with light sampling: {worst}"
                );
            } else {
                let sigma = (variance.mean() / image.pixels.len() as f64).sqrt();
                let z = (image.mean() - 1.0) / sigma;
                assert!(
                    z.abs() < 5.0,
                    "{device}, {material:?}: mean {} (z {z})",
                    image.mean()
                );
            }
        }
    }
}

/// A diffuse floor of albedo ρ under a map of radiance L above the horizon and 0 below:
/// irradiance π L, so radiance ρ L. The map's horizon is a row edge (even height), and the
/// floor is wide enough that no pixel sees past it. BSDF sampling alone sends every bounce up,
/// into L: exact. With light sampling, the map's samples below the horizon have pdf 0 and MIS
/// combines the rest; the mean is ρ L within 5σ of the variance image.
#[test]
fn floor_under_a_bright_upper_hemisphere_has_radiance_rho_l() {
    let dir = tempfile::tempdir().unwrap();
    let (rho, l) = (0.6f32, 2.0f32);
    let map = write_map(dir.path(), "upper.exr", 32, 16, |x, y| {
        if y < 8 {
            // Varying above the horizon: the irradiance is π × the mean, which must be l.
            let ripple = if (x + y) % 2 == 0 { 0.5 } else { -0.5 };
            [l + ripple; 3]
        } else {
            [0.0; 3]
        }
    });
    let scene = scene_in(
        dir.path(),
        &format!(
            "{}[environment]\nfile = {:?}\n[materials.floor]\ntype = \"diffuse\"\n\
             color = [{rho:?}, {rho:?}, {rho:?}]\n[[quads]]\ncorner = [-10000.0, 0.0, -10000.0]\n\
             u = [0.0, 0.0, 20000.0]\nv = [20000.0, 0.0, 0.0]\nmaterial = \"floor\"\n",
            header([0.0, 1.0, -1.0], [0.0, 0.0, 0.0], 30.0, 24, 1),
            map.file_name().unwrap()
        ),
    );
    let expected = (rho * l) as f64;
    for (device, image, variance) in
        render_both_with_variance(&with_light_sampling(&scene, true, 5), 64)
    {
        let sigma = (variance.mean() / image.pixels.len() as f64).sqrt();
        let z = (image.mean() - expected) / sigma;
        assert!(
            z.abs() < 5.0,
            "{device}: {} vs {expected} (z {z})",
            image.mean()
        );
    }
    // The checkered ripple averages out only over many BSDF samples, so this is statistical
    // too, but tighter: each sample is ρ(L ± 0.5).
    for (device, image, variance) in
        render_both_with_variance(&with_light_sampling(&scene, false, 6), 64)
    {
        let sigma = (variance.mean() / image.pixels.len() as f64).sqrt();
        let z = (image.mean() - expected) / sigma;
        assert!(
            z.abs() < 5.0,
            "{device}, BSDF only: {} vs {expected} (z {z})",
            image.mean()
        );
    }
}

/// Turning the map by α about +y looks the same as turning the camera by −α: with the same
/// seed, every camera ray of one render is the other's turned, so the images agree up to f32
/// rounding (which can move a ray across a texel edge; the map is smooth, so that is small).
#[test]
fn a_rotated_map_equals_a_rotated_camera() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path(), "gradient.exr", 64, 32, |x, y| {
        let u = x as f32 / 64.0;
        [
            1.0 + (u * std::f32::consts::TAU).sin(),
            y as f32 / 32.0,
            1.0 + (2.0 * u * std::f32::consts::TAU).cos(),
        ]
    });
    let alpha = 70.0f32;
    let target = glam::Vec3::new(0.3, 0.2, 1.0);
    let turned = glam::Quat::from_rotation_y(-alpha.to_radians()) * target;
    let render = |rotate: f32, target: glam::Vec3| {
        let scene = scene_in(
            dir.path(),
            &format!(
                "{}[environment]\nfile = {:?}\nrotate = {rotate:?}\n",
                header([0.0; 3], target.into(), 60.0, 32, 1),
                map.file_name().unwrap()
            ),
        );
        render_both(&scene.kernel_scene(), 4)
    };
    let rotated_map = render(alpha, target);
    let rotated_camera = render(0.0, turned);
    let unrotated = render(0.0, target);
    for ((device, a), (_, b)) in rotated_map.iter().zip(&rotated_camera) {
        let c = compare(a, b, None).unwrap();
        assert!(c.relative_mse < 1e-4, "{device}: {c:?}");
        // The test can fail: not turning the map at all changes the image.
        let (_, u) = unrotated.iter().find(|(d, _)| d == device).unwrap();
        assert!(compare(a, u, None).unwrap().relative_mse > 1e-2, "{device}");
    }
}

/// The GPU kernel and the CPU mirror trace the same paths under a map with a sun (the shipped
/// scenes/sun.toml: sampling of the map, MIS on escape), seed by seed.
#[test]
fn gpu_and_cpu_trace_the_same_paths_under_a_map() {
    let Some(ctx) = common::gpu() else { return };
    let mut agreement = PathAgreement::default();
    for seed in 0..2 {
        let scene = common::sized(common::shipped_scene("sun.toml"), 32, seed);
        let cpu = common::render_cpu(&scene, 1);
        let gpu = common::render_gpu(ctx, &scene, 1);
        agreement.add(&cpu, &gpu);
    }
    agreement.check(0.97);
}

/// Relative MSE (glint::image::compare's, against a 1024-spp light-sampled reference) of 16-spp
/// renders of a diffuse scene under the shipped sky with its small sun, averaged over four
/// seeds: importance sampling the map must lower it at least tenfold against BSDF sampling
/// alone, as the issue asks. (Measured: about 200×; the sun is 2·10⁻³ sr, so BSDF sampling
/// finds it about once in 2000 samples.)
#[test]
fn environment_sampling_lowers_the_relative_mse_tenfold() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = format!(
        "{}[environment]\nfile = \"skies/sky.hdr\"\n{OBJECTS}",
        header([0.0, 1.5, -3.5], [0.0, 0.4, 0.0], 40.0, 24, 2)
    )
    .replace(
        "type = \"metal\"\ncolor = [0.9, 0.7, 0.3]\nroughness = 0.4",
        "type = \"diffuse\"\ncolor = [0.9, 0.7, 0.3]",
    );
    let scene = Scene::parse(&text, &dir.join("sun-test.toml")).unwrap();
    let render = |light_sampling: bool, seed: u32, spp: u32| {
        render_image(
            &mut CpuRenderer::new(&with_light_sampling(&scene, light_sampling, seed)),
            spp,
            spp,
        )
        .unwrap()
    };
    let reference = render(true, 100, 1024);
    let mean_rel_mse = |light_sampling: bool| {
        (0..4)
            .map(|seed| {
                compare(&render(light_sampling, seed, 16), &reference, None)
                    .unwrap()
                    .relative_mse
            })
            .sum::<f64>()
            / 4.0
    };
    let (sampled, bsdf_only) = (mean_rel_mse(true), mean_rel_mse(false));
    eprintln!("relative MSE at 16 spp: {sampled:.3e} with environment sampling, {bsdf_only:.3e} without ({:.0}×)", bsdf_only / sampled);
    assert!(bsdf_only > 10.0 * sampled, "{sampled} vs {bsdf_only}");
}

// ---- Bad input ---------------------------------------------------------------------------

const BAD_SCENE: &str = "[camera]\neye = [0.0, 0.0, -4.0]\ntarget = [0.0, 0.0, 0.0]\n\
    up = [0.0, 1.0, 0.0]\nvfov = 40.0\n[render]\nwidth = 8\nheight = 8\nspp = 1\nmax_bounces = 1\n";

/// Loads BAD_SCENE plus `extra` from a folder holding `files`: the error message.
fn load_error(extra: &str, files: &[(&str, Vec<u8>)]) -> String {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, format!("{BAD_SCENE}{extra}")).unwrap();
    Scene::load(&path)
        .map(|_| ())
        .expect_err("the scene should be rejected")
        .to_string()
}

fn exr_bytes(texels: &[[f32; 3]], width: u32, height: u32) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = write_map(dir.path(), "m.exr", width, height, |x, y| {
        texels[(y * width + x) as usize]
    });
    std::fs::read(path).unwrap()
}

/// A Radiance HDR header for a `width`×`height` image with no pixel data.
fn hdr_header_only(width: u32, height: u32) -> Vec<u8> {
    format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n").into_bytes()
}

#[test]
fn bad_environments_are_named_errors() {
    let env = |file: &str, more: &str| format!("[environment]\nfile = \"{file}\"\n{more}");
    // (scene lines, files beside the scene, what the message must say)
    type Case<'a> = (String, Vec<(&'a str, Vec<u8>)>, Vec<&'a str>);
    let cases: Vec<Case> = vec![
        (
            env("missing.exr", ""),
            vec![],
            vec![
                "scene.toml:",
                "environment.file",
                "missing.exr",
                "cannot read",
            ],
        ),
        (
            env("nan.exr", ""),
            vec![(
                "nan.exr",
                exr_bytes(&[[1.0; 3], [f32::NAN, 0.0, 0.0]], 2, 1),
            )],
            vec!["environment.file", "texel (1, 0)", "finite radiances ≥ 0"],
        ),
        (
            env("negative.exr", ""),
            vec![(
                "negative.exr",
                exr_bytes(
                    &[[1.0; 3], [1.0; 3], [1.0; 3], [0.0, f32::NEG_INFINITY, 0.0]],
                    2,
                    2,
                ),
            )],
            vec!["texel (1, 1)", "finite radiances ≥ 0"],
        ),
        (
            env("inf.exr", ""),
            vec![("inf.exr", exr_bytes(&[[f32::INFINITY, 0.0, 0.0]], 1, 1))],
            vec!["texel (0, 0)"],
        ),
        (
            env("text.hdr", ""),
            vec![("text.hdr", b"not an image".to_vec())],
            vec!["environment.file", "text.hdr"],
        ),
        (
            env("empty.hdr", ""),
            vec![("empty.hdr", hdr_header_only(0, 0))],
            vec!["environment.file", "empty.hdr"],
        ),
        (
            env("huge.hdr", ""),
            vec![("huge.hdr", hdr_header_only(8192, 4096))],
            vec!["8192×4096", "the limit is 16777216 texels"],
        ),
        (
            format!("background = [1.0, 1.0, 1.0]\n{}", env("m.exr", "")),
            vec![("m.exr", exr_bytes(&[[1.0; 3]], 1, 1))],
            vec!["either render.background", "not both"],
        ),
        (
            env("m.exr", "strength = -1.0\n"),
            vec![("m.exr", exr_bytes(&[[1.0; 3]], 1, 1))],
            vec!["environment.strength", "got -1"],
        ),
        (
            env("m.exr", "rotate = nan\n"),
            vec![("m.exr", exr_bytes(&[[1.0; 3]], 1, 1))],
            vec!["environment.rotate", "finite"],
        ),
        (
            env("m.exr", "strength = 1e30\n"),
            vec![("m.exr", exr_bytes(&[[1.0; 3]], 1, 1))],
            vec!["environment.strength"],
        ),
        (env("m.exr", "sun = 1.0\n"), vec![], vec!["sun"]),
    ];
    for (extra, files, needles) in cases {
        let message = load_error(&extra, &files);
        assert!(!message.contains('\n'), "{message}");
        for needle in needles {
            assert!(
                message.contains(needle),
                "{extra}: {message:?} lacks {needle:?}"
            );
        }
    }
}

#[test]
fn the_cli_rejects_a_bad_map_with_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        format!("{BAD_SCENE}[environment]\nfile = \"missing.hdr\"\n"),
    )
    .unwrap();
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &scene, &out);
    common::assert_refused(&run, &out, &["missing.hdr"]);
}

/// A `width`×`height` Radiance HDR of one colour (run-length encoded, so a map larger than the
/// device allows is a small file).
fn constant_hdr(width: u32, height: u32, rgbe: [u8; 4]) -> Vec<u8> {
    let mut out = hdr_header_only(width, height);
    for _ in 0..height {
        out.extend([2, 2, (width >> 8) as u8, width as u8]);
        for channel in rgbe {
            let mut left = width;
            while left > 0 {
                let run = left.min(127);
                out.extend([128 + run as u8, channel]);
                left -= run;
            }
        }
    }
    out
}

/// A map within glint's texel limit but larger than the device's storage binding (lavapipe:
/// 128 MiB; 4096×2100 texels of 16 bytes are 131 MiB) is refused before rendering: exit 2,
/// one line naming the buffer and the limit, nothing written.
#[test]
fn a_map_larger_than_the_device_allows_is_refused() {
    let Some(ctx) = common::gpu() else { return };
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let height = (limit / 16 / 4096 + 1) as u32;
    if 4096 * height as u64 > glint::scene::image::MAX_IMAGE_TEXELS {
        eprintln!("this device holds any map glint reads; nothing to test");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("big.hdr"),
        constant_hdr(4096, height, [128, 128, 128, 129]),
    )
    .unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        format!("{BAD_SCENE}[environment]\nfile = \"big.hdr\"\n"),
    )
    .unwrap();
    let out = dir.path().join("out.png");
    let run = common::run_render("--gpu", &scene, &out);
    common::assert_refused(&run, &out, &["environment map", "MiB"]);
}

/// The denoiser's albedo guide where a ray escapes is the clamped radiance it sees there: the
/// map's, in its direction (here one colour, one channel above 1), on both devices.
#[test]
fn the_albedo_aov_of_escaping_rays_is_the_maps_clamped_radiance() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path(), "m.exr", 8, 4, |_, _| [0.25, 0.5, 2.0]);
    let scene = scene_in(
        dir.path(),
        &format!(
            "{}[environment]\nfile = {:?}\n",
            header([0.0; 3], [0.0, 0.0, 1.0], 60.0, 8, 1),
            map.file_name().unwrap()
        ),
    );
    let mut kernel = scene.kernel_scene();
    kernel.params.aovs = 1;
    for (device, mut renderer) in common::renderers(&kernel) {
        renderer.add_samples(2).unwrap();
        let aovs = renderer.read_aovs().unwrap();
        assert!(
            aovs.albedo.pixels.iter().all(|p| *p == [0.25, 0.5, 1.0]),
            "{device}: {:?}",
            &aovs.albedo.pixels[..2]
        );
    }
}

// ---- Files as they come: EXR compressions and lossy codecs' negatives ----

/// A map with tiny negative texels (what lossy EXR compression leaves near black) renders,
/// with those set to 0 and one warning line saying how many and the most negative.
#[test]
fn tiny_negative_texels_are_clamped_with_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "m.exr", 2, 1, |x, _| {
        if x == 0 {
            [1.0, -4.5e-6, -1e-7]
        } else {
            [0.5; 3]
        }
    });
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        format!("{BAD_SCENE}[environment]\nfile = \"m.exr\"\n"),
    )
    .unwrap();
    let loaded = Scene::load(&scene).unwrap_or_else(|e| panic!("{e}"));
    let image = &loaded.environment.as_ref().unwrap().image;
    assert_eq!(image.texels[0], [1.0, 0.0, 0.0]);
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &scene, &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    let warnings: Vec<_> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].contains("m.exr: 2 negative values (the most negative -4.5e-6) set to 0"),
        "{stderr}"
    );
}

/// How far a codec may move a value, relative to it: 0 for the lossless ones (and for the
/// lossy ones on channels they store as they are); PXR24 rounds f32 to 15 mantissa bits
/// (relative error ≤ 2⁻¹⁶ ≈ 1.5e-5, reached here); B44 stores each 4×4 block
/// of halves as a base and 6-bit differences (1.8e-3 measured); DWA quantizes a DCT (1.0e-2
/// measured). The bounds are about twice what these smooth images measure.
fn codec_tolerance(compression: exr::prelude::Compression, half: bool) -> f32 {
    use exr::prelude::Compression::*;
    match compression {
        Uncompressed | RLE | ZIP1 | ZIP16 | PIZ => 0.0,
        PXR24 if half => 0.0,
        PXR24 => 3e-5,
        B44 | B44A if half => B44_TOLERANCE,
        B44 | B44A => 0.0,
        _ => DWA_TOLERANCE,
    }
}
const B44_TOLERANCE: f32 = 4e-3;
const DWA_TOLERANCE: f32 = 0.02;

/// Every compression the exr crate writes (all of OpenEXR's but HTJ2K), with f32 and with f16
/// texels: glint reads back what was written, exactly for the lossless codecs and within each
/// lossy codec's error.
#[test]
fn every_exr_compression_loads() {
    use exr::prelude::*;
    use glint::scene::image::{load_linear_image, Encoding as Decode};
    let (width, height) = (48usize, 40usize);
    // Smooth, positive and bright enough that no lossy codec goes below 0.
    let value = |x: usize, y: usize, c: usize| {
        0.2 + 0.5 * (x as f32 / width as f32) + 0.3 * (y as f32 / height as f32) + 0.1 * c as f32
    };
    let dir = tempfile::tempdir().unwrap();
    for compression in [
        Compression::Uncompressed,
        Compression::RLE,
        Compression::ZIP1,
        Compression::ZIP16,
        Compression::PIZ,
        Compression::PXR24,
        Compression::B44,
        Compression::B44A,
        Compression::DWAA(None),
        Compression::DWAB(None),
    ] {
        for half in [false, true] {
            let name = format!("{compression}-{}", if half { "f16" } else { "f32" });
            let path = dir.path().join(format!("{name}.exr").replace(' ', "_"));
            let encoding = Encoding {
                compression,
                blocks: Blocks::ScanLines,
                line_order: LineOrder::Increasing,
            };
            let written = if half {
                let channels = SpecificChannels::rgb(|Vec2(x, y)| {
                    (
                        f16::from_f32(value(x, y, 0)),
                        f16::from_f32(value(x, y, 1)),
                        f16::from_f32(value(x, y, 2)),
                    )
                });
                Image::from_encoded_channels((width, height), encoding, channels)
                    .write()
                    .to_file(&path)
            } else {
                let channels = SpecificChannels::rgb(|Vec2(x, y)| {
                    (value(x, y, 0), value(x, y, 1), value(x, y, 2))
                });
                Image::from_encoded_channels((width, height), encoding, channels)
                    .write()
                    .to_file(&path)
            };
            written.unwrap_or_else(|e| panic!("{name}: {e}"));
            let image =
                load_linear_image(&path, Decode::Linear).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!((image.width, image.height), (width as u32, height as u32));
            let tolerance = codec_tolerance(compression, half);
            let mut worst = 0.0f32;
            for y in 0..height {
                for x in 0..width {
                    let texel = image.texel(x as u32, y as u32);
                    for (c, read) in texel.iter().enumerate() {
                        let mut expected = value(x, y, c);
                        if half {
                            expected = f16::from_f32(expected).to_f32();
                        }
                        worst = worst.max((read - expected).abs() / expected);
                    }
                }
            }
            eprintln!("{name}: largest relative error {worst:.2e}");
            assert!(
                worst <= tolerance,
                "{name}: relative error {worst} > {tolerance}"
            );
        }
    }
}

/// A DWAB map written by OpenEXR itself (tests/images/make_dwab.py says how): glint's decoder
/// (the exr crate) reads the texels OpenEXR's own decoder does, negatives included, which
/// are then clamped and reported.
#[test]
fn an_openexr_dwab_map_loads_as_openexr_decodes_it() {
    use glint::scene::image::{load_linear_image, Encoding};
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/images");
    let dwab = load_linear_image(&folder.join("dwab.exr"), Encoding::Linear).unwrap();
    let reference = load_linear_image(&folder.join("dwab-decoded.exr"), Encoding::Linear).unwrap();
    let clamped = dwab.clamped.expect("the DWAB map holds negatives");
    assert_eq!(clamped.count, 94);
    assert_eq!(clamped.most_negative, -2.574_920_7e-5);
    assert_eq!(reference.clamped, dwab.clamped);
    assert_eq!((dwab.width, dwab.height), (32, 16));
    assert!(
        dwab.texels == reference.texels,
        "texels differ from OpenEXR's"
    );
}

/// A compression the exr crate cannot read (OpenEXR 3.5's ZSTD, and HTJ2K) is refused with an
/// error naming the file and the compression.
#[test]
fn an_unreadable_compression_is_named() {
    let mut bytes = exr_bytes(&[[1.0; 3]; 4], 2, 2);
    let key = b"compression\0compression\0\x01\0\0\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("a compression attribute")
        + key.len();
    for (code, name) in [(13, "ZSTD"), (10, "HTJ2K256")] {
        bytes[at] = code;
        let message = load_error(
            "[environment]\nfile = \"m.exr\"\n",
            &[("m.exr", bytes.clone())],
        );
        assert!(
            message.contains("environment.file: m.exr: cannot decode the image")
                && message.contains(&format!(
                    "its EXR compression, {name}, is not one glint reads"
                )),
            "{message}"
        );
    }
}
