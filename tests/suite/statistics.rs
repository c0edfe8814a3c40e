//! Renders tested as Mitsuba and pbrt test them: per-pixel Z-tests with variance images, GPU
//! against CPU (different seeds), GPU against the committed references (tests/references/), and
//! light sampling on against off; the honesty of the variance images (the squared difference of
//! two independent renders against the sum of their variances); `--target-error` against a scene
//! whose exact image is known. All seeds are fixed, so every run passes or fails the same way.
//!
//! Why the thresholds are what they are:
//! - Each pixel channel's mean is approximately normal, so |z| ≤ 2.576 holds for 99% of them
//!   when two renders estimate the same image. The pixel distributions are skewed (paths that
//!   find the light through the mirror are rare) and the channels correlated, so the rate
//!   varies around that: we measured 98.2% to 99.7% across the tests below, and require 97%.
//!   A renderer that is wrong in a part of the image (a missing light path, a wrong material
//!   on one object) fails more pixels than that.
//! - A bias small in every pixel but common to all (a wrong constant factor) barely moves the
//!   pass rate, so we also test the difference of the image means, whose variance is the sum
//!   of all pixel variances / N²: |z| < 4 (two-sided false alarm 6·10⁻⁵ per test). At 256 spp
//!   on the 64² Cornell box this detects a 3% bias.

use crate::common;
use common::gpu;
use glint::cpu::core::rng::{SAMPLER_INDEPENDENT, SAMPLER_SOBOL};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::gpu::GpuRenderer;
use glint::image::compare::{compare, ZTest};
use glint::image::output::Image;
use glint::kernel::KernelScene;
use glint::render::Renderer;
use glint::scene::{RenderOverrides, Scene};
use std::path::Path;

const MIN_PASS_RATE: f64 = 0.97;
const MAX_Z_OF_MEANS: f64 = 4.0;

/// With independent samples, as the Z-tests' variance estimates assume.
fn cornell_64(seed: u32) -> KernelScene {
    let mut scene = common::cornell_at(64, seed);
    scene.params.sampler = SAMPLER_INDEPENDENT;
    scene
}

/// Mean and variance images after `spp` samples.
fn render(renderer: &mut dyn Renderer, spp: u32) -> (Image, Image) {
    while renderer.samples() < spp {
        renderer
            .add_samples(256.min(spp - renderer.samples()))
            .unwrap();
    }
    (
        renderer.read_mean().unwrap(),
        renderer.read_variance().unwrap(),
    )
}

fn scaled(image: &Image, factor: f32) -> Image {
    Image {
        pixels: image.pixels.iter().map(|p| p.map(|v| v * factor)).collect(),
        ..image.clone()
    }
}

fn z_test(a: &(Image, Image), b: &(Image, Image)) -> ZTest {
    compare(&a.0, &b.0, Some((&a.1, &b.1)))
        .unwrap()
        .z_test
        .unwrap()
}

fn assert_same_image(what: &str, z: &ZTest) {
    eprintln!(
        "{what}: Z-test pass rate {:.2}% of {}, z of means {:.2}, variance ratio {:.3}",
        100.0 * z.pass_rate,
        z.tested,
        z.z_of_means,
        z.variance_ratio
    );
    assert!(
        z.pass_rate >= MIN_PASS_RATE,
        "{what}: pass rate {}",
        z.pass_rate
    );
    assert!(
        z.z_of_means.abs() < MAX_Z_OF_MEANS,
        "{what}: z of means {}",
        z.z_of_means
    );
}

#[test]
fn gpu_and_cpu_with_different_seeds_render_the_same_image() {
    let Some(ctx) = gpu() else { return };
    let a = render(&mut GpuRenderer::new(ctx, &cornell_64(1)).unwrap(), 256);
    let b = render(&mut CpuRenderer::new(&cornell_64(2)), 256);
    assert_same_image("GPU seed 1 vs CPU seed 2", &z_test(&a, &b));
    // The same test catches a 5% error in the overall brightness.
    let dimmer = z_test(&(scaled(&a.0, 0.95), a.1.clone()), &b);
    assert!(dimmer.z_of_means.abs() > MAX_Z_OF_MEANS, "{dimmer:?}");
}

/// The references in tests/references were rendered on the CPU at 16384 spp
/// (tests/references/regenerate.sh); the GPU renders 4096 spp with another seed.
///
/// The reference scenes have no specular surfaces. Light that reaches a diffuse surface
/// through a mirror (a caustic) is found only by BSDF sampling and only rarely, so a render
/// with caustics usually misses some: its pixel means are skewed low and its variances too
/// small, and the normal approximation behind the Z-test fails. With the Cornell box's mirror
/// sphere we measured, at 4096 spp against a converged reference, a 97.1% pass rate and a
/// variance ratio of 0.64, and for the sky scene's chrome sphere a z of means of −2.9 and a
/// variance ratio of 3.2, while the same renders at 16384 spp agree with light sampling on and
/// off to 0.007%. Specular materials are tested by the white furnace, the GGX quadrature and
/// the χ² tests instead.
#[test]
fn gpu_matches_the_committed_references() {
    let Some(ctx) = gpu() else { return };
    let refs = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references");
    for (scene, width, height, name) in [
        ("cornell-diffuse.toml", 64, 64, "cornell-diffuse-64"),
        ("sky-diffuse.toml", 64, 36, "sky-diffuse-64x36"),
    ] {
        let scene = Scene::load(&refs.join(scene))
            .unwrap()
            .with_overrides(&RenderOverrides {
                width: Some(width),
                height: Some(height),
                seed: Some(77),
                ..Default::default()
            })
            .unwrap()
            .kernel_scene();
        let rendered = render(&mut GpuRenderer::new(ctx, &scene).unwrap(), 4096);
        let reference = (
            Image::read_exr(&refs.join(format!("{name}.exr"))).unwrap(),
            Image::read_exr(&refs.join(format!("{name}.variance.exr"))).unwrap(),
        );
        assert_same_image(
            &format!("GPU vs reference {name}"),
            &z_test(&rendered, &reference),
        );
    }
}

/// Over two independent renders, E[(A − B)²] = VA + VB per pixel channel, so the ratio of
/// the means is 1 when the variance images are honest. The tolerance is 4 standard errors
/// of that ratio, estimated from the data by the delta method (pixels independent), which
/// accounts for the heavy tails of a scene without light sampling; we also require ±10%.
#[test]
fn variance_images_predict_the_real_squared_differences() {
    let Some(ctx) = gpu() else { return };
    let a = render(&mut GpuRenderer::new(ctx, &cornell_64(3)).unwrap(), 256);
    let b = render(&mut GpuRenderer::new(ctx, &cornell_64(4)).unwrap(), 256);
    let (ratio, standard_error) = variance_ratio(&a, &b);
    eprintln!("variance ratio {ratio:.4} ± {standard_error:.4}");
    assert!(
        (ratio - 1.0).abs() < (4.0 * standard_error).min(0.1),
        "{ratio} ± {standard_error}"
    );
    // Variance images off by 2× in either direction fail.
    for factor in [0.5, 2.0] {
        let (wrong, _) = variance_ratio(
            &(a.0.clone(), scaled(&a.1, factor)),
            &(b.0.clone(), scaled(&b.1, factor)),
        );
        assert!((wrong - 1.0).abs() > 0.3, "{factor}: {wrong}");
    }
}

/// Σ(A − B)² / Σ(VA + VB) over pixel channels, and its standard error.
fn variance_ratio(a: &(Image, Image), b: &(Image, Image)) -> (f64, f64) {
    // One term per pixel: its channels come from the same paths, so only pixels are independent.
    let terms: Vec<(f64, f64)> = (0..a.0.pixels.len())
        .map(|i| {
            (0..3).fold((0.0, 0.0), |(d2, v), c| {
                let d = (a.0.pixels[i][c] - b.0.pixels[i][c]) as f64;
                (d2 + d * d, v + (a.1.pixels[i][c] + b.1.pixels[i][c]) as f64)
            })
        })
        .collect();
    let (sd, sv): (f64, f64) = terms
        .iter()
        .fold((0.0, 0.0), |(x, y), (d, v)| (x + d, y + v));
    let ratio = sd / sv;
    // Delta method: Var(Σd/Σv) ≈ Σ(d − ratio·v)² / (Σv)².
    let spread: f64 = terms.iter().map(|(d, v)| (d - ratio * v).powi(2)).sum();
    (ratio, spread.sqrt() / sv)
}

/// `--target-error` stops when the estimated relative error reaches the target, and the
/// estimate is the real error. The scene is the floor under an emitting sphere from
/// tests/suite/closed_form.rs, whose every pixel is ρ L (r/d)² = 0.6 exactly, so the real error
/// needs no reference: √(mean (pixel − 0.6)²) / 0.6. With 16×16 pixels that RMS is known to
/// ±1/√(2·256) = ±4.4% (one σ) of itself; the ±25% band between the real and the estimated
/// error is about 6σ wide. Where the render stops depends on the batch sizes (timed, so they
/// vary with the machine's load), and below 64 spp batches end at powers of two (the fixed
/// merge schedule), so the spp can grow up to 4× between checks: the error at the stop lies
/// between half the target and the target, less the estimate's noise (hence 0.4×).
#[test]
fn target_error_stops_with_the_real_error_near_the_target() {
    let Some(ctx) = gpu() else { return };
    let scene = common::floor_under_lamp(16, 100_000, 5);
    let target = 0.02;
    let mut renderer = GpuRenderer::new(ctx, &scene).unwrap();
    let stats = glint::render::render_progressive(
        &mut renderer,
        100_000,
        glint::render::StopRules {
            time_limit: None,
            target_error: Some(target),
            ..Default::default()
        },
        &mut glint::render::BatchSizer::new(std::time::Duration::from_millis(50)),
        |_, _| Ok(()),
    )
    .unwrap();
    assert_eq!(stats.stop_reason, glint::render::StopReason::TargetError);
    let estimated = stats.relative_error.unwrap();
    let image = renderer.read_mean().unwrap();
    let truth = 0.6f64;
    let mse = image
        .pixels
        .iter()
        .flatten()
        .map(|&v| (v as f64 - truth).powi(2))
        .sum::<f64>()
        / (image.pixels.len() * 3) as f64;
    let real = mse.sqrt() / truth;
    eprintln!(
        "target {target}: stopped at {} spp, estimated {estimated:.4}, real {real:.4}",
        stats.spp
    );
    assert!(estimated <= target);
    assert!(
        estimated >= 0.4 * target,
        "stopped far too late: {estimated}"
    );
    assert!(
        (real / estimated - 1.0).abs() < 0.25,
        "real error {real}, estimated {estimated}"
    );
}

/// Light sampling changes the variance, not the expectation: the Cornell box rendered with and
/// without it (4096 spp each, GPU, different seeds) passes the same Z-tests. Both need 4096 spp
/// for their pixel means to be close enough to normal: paths that find the light only through
/// the mirror sphere are rare in both modes. With fewer samples we measured a 97.5% pass rate
/// (2048 spp each) and, with light sampling at 1024 spp, a z of means of 3.3, while each mode
/// at 4096 spp stays within 1σ of the committed reference. A light-sampling estimator that
/// double-counts or drops the directly seen light shifts the image mean by tens of σ.
#[test]
fn light_sampling_on_and_off_converge_to_the_same_image() {
    let Some(ctx) = gpu() else { return };
    let mut on = cornell_64(21);
    on.params.light_sampling = 1;
    let mut off = cornell_64(22);
    off.params.light_sampling = 0;
    let a = render(&mut GpuRenderer::new(ctx, &on).unwrap(), 4096);
    let b = render(&mut GpuRenderer::new(ctx, &off).unwrap(), 4096);
    assert_same_image("light sampling on vs off", &z_test(&a, &b));
    // Light sampling is the lower-variance estimator here.
    let (va, vb) = (a.1.mean(), b.1.mean());
    eprintln!("variance of the pixel means at 4096 spp: on {va:.3e}, off {vb:.3e}");
    assert!(va < vb);
}

/// The Sobol sampler changes the error, not the expectation: Sobol renders of the Cornell box
/// pass the Z-tests against independent ones (256 spp, other seeds), on the CPU and, where
/// there is one, across CPU and GPU both ways. A Sobol render's variance image assumes
/// independent samples and so overstates the error of its means, which makes the test
/// conservative, but a 5% error in brightness still fails it.
#[test]
fn sobol_and_independent_samplers_render_the_same_image() {
    let sobol = |seed| {
        let mut scene = cornell_64(seed);
        scene.params.sampler = SAMPLER_SOBOL;
        scene
    };
    let a = render(&mut CpuRenderer::new(&sobol(31)), 256);
    let b = render(&mut CpuRenderer::new(&cornell_64(32)), 256);
    assert_same_image("CPU sobol vs CPU independent", &z_test(&a, &b));
    let dimmer = z_test(&(scaled(&a.0, 0.95), a.1.clone()), &b);
    assert!(dimmer.z_of_means.abs() > MAX_Z_OF_MEANS, "{dimmer:?}");
    let Some(ctx) = gpu() else { return };
    let c = render(&mut GpuRenderer::new(ctx, &sobol(33)).unwrap(), 256);
    assert_same_image("GPU sobol vs CPU independent", &z_test(&c, &b));
    let d = render(&mut GpuRenderer::new(ctx, &cornell_64(34)).unwrap(), 256);
    assert_same_image("CPU sobol vs GPU independent", &z_test(&a, &d));
}
