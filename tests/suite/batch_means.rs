//! The variance of bidirectional renders, from batch means (src/render/batch_means.rs):
//! - it predicts the spread of independent renders' means (seeds), where the camera
//!   strategies' own variance, blind to the splats, does not;
//! - without splats (path tracing through the same wrapper) it estimates the very quantity the
//!   samples' own variance does;
//! - `glint render --integrator bdpt` writes it with `--variance` and stops on it with
//!   `--target-error`, a resumed render's is the same bytes as a render made at once, and a
//!   merge of shards gives the single render's to rounding; `--adaptive` stays refused.
//!
//! The GPU's is checked against the CPU's in bdpt.rs, with the kernel those tests compile.

use crate::common;
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::image::output::Image;
use glint::kernel::types::INTEGRATOR_PATH;
use glint::kernel::KernelScene;
use glint::render::batch_means::BatchMeans;
use glint::render::partial::Partial;
use glint::render::{relative_error, Renderer};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// The bound on |z| of every test here, as statistics.rs and bdpt.rs use.
const MAX_Z: f64 = 4.0;

/// Seeds of the spread test, and the samples per pixel of each render (7 batches).
/// The spread test: renders of `SIZE`² pixels at `SPP` (7 batches) with `SEEDS` seeds, and
/// `WEIGHT_SEEDS` more for the pixels' weights.
const SEEDS: u32 = 128;
const WEIGHT_SEEDS: u32 = 16;
const SPP: u32 = 64;
const SIZE: u32 = 8;

/// One render's mean, its batch-means variance and its camera strategies' own variance.
fn render(scene: &KernelScene, spp: u32) -> (Image, Image, Image) {
    let mut r = BatchMeans::new(Box::new(CpuRenderer::new(scene)));
    r.add_samples(spp).unwrap();
    let own = r.inner().read_variance().unwrap();
    (r.read_mean().unwrap(), r.read_variance().unwrap(), own)
}

/// How well per-render variance images predict the spread of the renders' means over seeds,
/// image-wide: the ratio of Σₚ s²ₚ (the sample variance over the R renders of pixel channel
/// p's mean, unbiased for its variance) to Σₚ v̄ₚ (the mean of the R reported variances), and
/// its standard error.
///
/// Both sums are means over the renders of per-render terms, Aᵣ = R/(R − 1) Σₚ (xᵣₚ − x̄ₚ)² and
/// Bᵣ = Σₚ vᵣₚ (nearly independent over r: only x̄ ties them), so the ratio Ā/B̄ has by the delta
/// method the standard error √(Var(A − ratio·B) / R) / B̄. Its spread comes from the data, heavy
/// tails included, not from a normal model; a batch-means estimate has few degrees of freedom
/// per pixel (6 here), which is why the image sums are compared, not pixels.
fn spread_ratio(means: &[Image], variances: &[Image], weights: &[f64]) -> (f64, f64) {
    let r = means.len() as f64;
    let channels = means[0].pixels.len() * 3;
    let value = |image: &Image, p: usize| image.pixels[p / 3][p % 3] as f64;
    let centre: Vec<f64> = (0..channels)
        .map(|p| means.iter().map(|m| value(m, p)).sum::<f64>() / r)
        .collect();
    let a: Vec<f64> = means
        .iter()
        .map(|m| {
            (0..channels)
                .map(|p| weights[p] * (value(m, p) - centre[p]).powi(2))
                .sum::<f64>()
                * r
                / (r - 1.0)
        })
        .collect();
    let b: Vec<f64> = variances
        .iter()
        .map(|v| (0..channels).map(|p| weights[p] * value(v, p)).sum())
        .collect();
    let (a_mean, b_mean) = (a.iter().sum::<f64>() / r, b.iter().sum::<f64>() / r);
    let ratio = a_mean / b_mean;
    let residuals: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a - ratio * b).collect();
    let spread = residuals.iter().map(|x| x * x).sum::<f64>() / (r - 1.0);
    (ratio, (spread / r).sqrt() / b_mean)
}

/// Over 128 seeds of a diffuse box whose light tracing splats carry much of the light, the
/// batch-means variance of each render predicts the spread of the renders' means: the
/// weighted ratio is 1 within 4 standard errors, and precise enough to tell (measured
/// 0.995 ± 0.018). The camera strategies' own variance, which misses the splats, fails the same
/// test (measured 1.59 ± 0.03), and so does batch means divided by K instead of K − 1 (1.16 ±
/// 0.02).
///
/// Pixel channels are weighted by 1 / their variance (from other seeds), so that each counts
/// about as much as another; unweighted, the sums are the light's own pixels, where the camera
/// strategies do all the work. The scene has no fireflies: with heavy-tailed samples (light
/// seen through glass) batch means stay unbiased, but a firefly in one of the first, small
/// batches weighs on SSB up to 10× its share of the spread, and one in the last, large batch
/// a sixth, so a few dozen seeds do not show the balance (measured on the glass box's 8²,
/// 128 seeds: 1.5 ± 0.13 weighted).
#[test]
fn batch_means_predict_the_spread_of_independent_renders() {
    let (mut means, mut batch, mut own) = (Vec::new(), Vec::new(), Vec::new());
    for seed in 0..SEEDS {
        let (mean, variance, camera) = render(&common::bdpt_diffuse_box(SIZE, 100 + seed), SPP);
        means.push(mean);
        batch.push(variance);
        own.push(camera);
    }
    // Weights from other renders (seeds 1000 on), independent of those compared: each pixel
    // channel counts about as much as another, not as much as its variance.
    let mut reference = vec![0.0f64; (SIZE * SIZE * 3) as usize];
    for seed in 0..WEIGHT_SEEDS {
        let (_, variance, _) = render(&common::bdpt_diffuse_box(SIZE, 1000 + seed), SPP);
        for (p, v) in reference.iter_mut().enumerate() {
            *v += variance.pixels[p / 3][p % 3] as f64 / WEIGHT_SEEDS as f64;
        }
    }
    let floor = 1e-2 * reference.iter().sum::<f64>() / reference.len() as f64;
    let weighted: Vec<f64> = reference.iter().map(|v| 1.0 / (v + floor)).collect();
    let weights = &weighted;
    let (ratio, se) = spread_ratio(&means, &batch, weights);
    let (own_ratio, own_se) = spread_ratio(&means, &own, weights);
    // K = 7 batches at 64 spp: 1, 1, 2, 4, 8, 16, 32.
    let k = 7.0;
    let by_k: Vec<Image> = batch
        .iter()
        .map(|v| Image {
            pixels: v
                .pixels
                .iter()
                .map(|p| p.map(|x| x * (k - 1.0) / k))
                .collect(),
            ..v.clone()
        })
        .collect();
    let (by_k_ratio, by_k_se) = spread_ratio(&means, &by_k, weights);
    eprintln!(
        "spread / batch means {ratio:.3} ± {se:.3}; spread / camera-only variance \
         {own_ratio:.3} ± {own_se:.3}; spread / (batch means with K) {by_k_ratio:.3} ± {by_k_se:.3}"
    );
    // Precise enough to tell a 1/7 bias at 4 standard errors (measured: ± 0.018).
    assert!(se < 0.035, "too imprecise to tell: ± {se}");
    assert!(
        (ratio - 1.0).abs() < MAX_Z * se,
        "batch means: {ratio} ± {se}"
    );
    assert!(
        (own_ratio - 1.0).abs() > MAX_Z * own_se,
        "the camera strategies' own variance passes: {own_ratio} ± {own_se}"
    );
    assert!(
        (by_k_ratio - 1.0).abs() > MAX_Z * by_k_se,
        "dividing by K passes: {by_k_ratio} ± {by_k_se}"
    );
}

/// Without splats the batch means estimate what the samples' own variance does: path
/// tracing of the diffuse box (no fireflies) through the same wrapper, the same samples, both unbiased estimates of each pixel's
/// σ²/n. Each pixel's difference dₚ (channels summed, each weighted by 1 / its variance in a
/// render of another seed, so that no few noisy pixels decide) has mean 0, and pixels are
/// independent in path tracing, so z = Σ dₚ / √Σ dₚ² must be within 4 (measured at 64²:
/// −1.4, the image means' ratio 0.96). Dividing SSB by K instead of K − 1 (a 1/7 bias at 64
/// spp) fails that (measured z −9.5).
#[test]
fn without_splats_batch_means_estimate_the_samples_own_variance() {
    let path = |seed| {
        let mut scene = common::bdpt_diffuse_box(64, seed);
        scene.params.integrator = INTEGRATOR_PATH;
        scene
    };
    let scene = path(11);
    let mut other = CpuRenderer::new(&path(12));
    other.add_samples(SPP).unwrap();
    let reference = other.read_variance().unwrap();
    let floor = 1e-2 * reference.mean() as f32;
    let mut r = BatchMeans::new(Box::new(CpuRenderer::new(&scene)));
    r.add_samples(SPP).unwrap();
    let own = r.inner().read_variance().unwrap();
    let batch = r.read_variance().unwrap();
    let z = |scale: f32| {
        let d: Vec<f64> = (0..own.pixels.len())
            .map(|i| {
                (0..3)
                    .map(|c| {
                        let weight = 1.0 / (reference.pixels[i][c] + floor);
                        (weight * (batch.pixels[i][c] * scale - own.pixels[i][c])) as f64
                    })
                    .sum()
            })
            .collect();
        d.iter().sum::<f64>() / d.iter().map(|x| x * x).sum::<f64>().sqrt()
    };
    let (z_right, z_by_k) = (z(1.0), z(6.0 / 7.0));
    let ratio = batch.mean() / own.mean();
    eprintln!("batch means / own variance {ratio:.4}, z {z_right:.2}; divided by K: z {z_by_k:.2}");
    assert!(z_right.abs() < MAX_Z, "z {z_right}");
    assert!(z_by_k.abs() > MAX_Z, "dividing by K passes: z {z_by_k}");
}

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

/// `glint render` of the glass Cornell box, bidirectional, small, on the CPU.
fn render_args<'a>(more: &[&'a str]) -> Vec<&'a str> {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cornell-glass.toml");
    let mut args = vec![
        "render",
        scene,
        "--cpu",
        "--integrator",
        "bdpt",
        "--width",
        "12",
        "--height",
        "12",
        "--max-bounces",
        "4",
        "--seed",
        "5",
    ];
    args.extend(more);
    args
}

fn read(path: &Path) -> Partial {
    Partial::read(path).unwrap_or_else(|e| panic!("{e}"))
}

fn variance_file(path: &Path) -> Image {
    Image::read_exr(path).unwrap()
}

/// --variance writes the batch-means variance; a render resumed at 64 spp is a render made at
/// once (the same bytes: the sums of squares go on from the file's f32 values, as the render's
/// own do); two shards of 64 merge to its variance to rounding.
///
/// The rounding: the merge's term n₁n₂/n (Ȳ₁ − Ȳ₂)² and the single render's last batch's
/// N_prev N / nₖ (Ȳ − Ȳ_prev)² are equal in exact arithmetic, but each difference of two f32
/// means carries some ε|Ȳ| of rounding (ε = 2⁻²⁴), relative to a difference of about σ/√64:
/// 1e-3 of the pixel's variance covers a pixel whose σ is 1e-4 of its mean, and an absolute
/// 1e-6 of the image's mean variance covers the darkest.
#[test]
fn bdpt_variance_is_written_resumed_and_merged() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    common::glint_ok(
        d,
        &render_args(&[
            "--spp",
            "128",
            "-o",
            "single.exr",
            "--variance",
            "single.var.exr",
        ]),
    );
    let single = read(&d.join("single.exr"));
    let variance = variance_file(&d.join("single.var.exr"));
    assert_eq!(single.accumulation.batches, 8);
    assert_eq!(variance, single.accumulation.variance_image());
    assert!(variance.mean() > 0.0);

    // Resumed: 64, then on to 128.
    common::glint_ok(d, &render_args(&["--spp", "64", "-o", "resumed.exr"]));
    common::glint_ok(
        d,
        &render_args(&[
            "--spp",
            "128",
            "--resume",
            "resumed.exr",
            "--variance",
            "resumed.var.exr",
        ]),
    );
    assert_eq!(
        read(&d.join("resumed.exr")).accumulation,
        single.accumulation
    );
    assert_eq!(variance_file(&d.join("resumed.var.exr")), variance);

    // Shards 0..64 and 64..128, merged.
    for shard in ["0/2", "1/2"] {
        let out = format!("part-{}.exr", &shard[..1]);
        common::glint_ok(
            d,
            &render_args(&["--spp", "128", "--shard", shard, "-o", &out]),
        );
    }
    common::glint_ok(
        d,
        &[
            "merge",
            "part-0.exr",
            "part-1.exr",
            "-o",
            "merged.exr",
            "--variance",
            "merged.var.exr",
        ],
    );
    let merged = variance_file(&d.join("merged.var.exr"));
    assert_eq!(read(&d.join("merged.exr")).accumulation.batches, 8);
    let floor = 1e-6 * variance.mean();
    let mut worst = 0.0f64;
    for (m, s) in merged.pixels.iter().zip(&variance.pixels) {
        for c in 0..3 {
            let bound = 1e-3 * s[c] as f64 + floor;
            worst = worst.max((m[c] - s[c]).abs() as f64 / bound);
        }
    }
    eprintln!("merged vs single variance: worst {worst:.3} of the bound");
    assert!(worst <= 1.0, "{worst}");
}

/// --target-error stops a bidirectional render on the batch-means variance: before the spp
/// cap, at a block end, with the relative error it reports, which is the written variance
/// image's. --adaptive, which would stop pixels the batch means need, is refused.
#[test]
fn target_error_stops_a_bdpt_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = common::glint_ok(
        d,
        &render_args(&[
            "--spp",
            "4096",
            "--target-error",
            "0.15",
            "-o",
            "te.exr",
            "--variance",
            "te.var.exr",
            "--json",
        ]),
    );
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    eprintln!("{summary}");
    assert_eq!(summary["stopped_by"], "target-error");
    let spp = summary["spp"].as_u64().unwrap() as u32;
    assert!((8..4096).contains(&spp), "{spp}");
    assert!(glint::kernel::schedule::is_block_end(spp), "{spp}");
    let reported = summary["relative_error"].as_f64().unwrap();
    assert!(reported <= 0.15, "{reported}");
    let partial = read(&d.join("te.exr"));
    let variance = variance_file(&d.join("te.var.exr"));
    assert_eq!(variance, partial.accumulation.variance_image());
    let error = relative_error(&partial.accumulation.mean_image(), &variance).unwrap();
    assert!(
        (error / reported - 1.0).abs() < 1e-6,
        "{error} vs {reported}"
    );

    let refused = Command::new(GLINT)
        .args(render_args(&[
            "--spp",
            "64",
            "--target-error",
            "0.1",
            "--adaptive",
            "-o",
            "adaptive.exr",
        ]))
        .current_dir(d)
        .output()
        .unwrap();
    common::assert_refused(&refused, &d.join("adaptive.exr"), &["--adaptive", "bdpt"]);
}
