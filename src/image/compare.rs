//! Comparing two renders: error metrics and, given variance images, per-pixel Z-tests.
//! `glint compare` prints these; the statistical tests assert on them.

use crate::image::output::Image;

/// Two-sided significance of the per-pixel Z-test.
pub const Z_TEST_ALPHA: f64 = 0.01;
/// |z| above which a pixel channel fails the test at [`Z_TEST_ALPHA`] (the 99.5% normal quantile).
pub const Z_CRITICAL: f64 = 2.575_829_303_548_901;
/// Added to B² in the relative MSE so black reference pixels do not divide by zero.
pub const REL_MSE_EPSILON: f64 = 0.01;

#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// √(mean over pixels and channels of (A − B)²).
    pub rmse: f64,
    /// Mean over pixels and channels of (A − B)² / (B² + 0.01), B being the reference.
    pub relative_mse: f64,
    pub mean_a: [f64; 3],
    pub mean_b: [f64; 3],
    /// Largest |A − B| of any pixel channel.
    pub max_difference: f64,
    /// With variances: the Z-test results.
    pub z_test: Option<ZTest>,
    /// Pixel channels of A that are NaN or infinite. Every figure above leaves out the pixel
    /// channels where A or B (or, in the Z-test, a variance) is not finite, so one NaN cannot
    /// turn them all into NaN; these counts say how many there were.
    pub nonfinite_a: usize,
    pub nonfinite_b: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ZTest {
    /// Fraction of pixel channels with |z| ≤ [`Z_CRITICAL`], z = (A − B) / √(VA + VB).
    pub pass_rate: f64,
    /// Pixel channels tested: those where A, B and both variances are finite.
    pub tested: usize,
    /// z of the difference of the image means, whose variance is Σ(VA + VB) / N²: a sensitive
    /// test for a bias that is small in every pixel but common to all.
    pub z_of_means: f64,
    /// Mean of (A − B)² over mean of (VA + VB): 1 when the variance images are honest.
    pub variance_ratio: f64,
}

fn check_same_size(a: &Image, b: &Image, what: &str) -> Result<(), String> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(format!(
            "{what}: sizes differ ({}×{} and {}×{})",
            a.width, a.height, b.width, b.height
        ));
    }
    Ok(())
}

/// Compares A against the reference B; `variances` are the variance images of A's and B's
/// pixel means (σ²/n), as `render --variance` writes them.
pub fn compare(
    a: &Image,
    b: &Image,
    variances: Option<(&Image, &Image)>,
) -> Result<Comparison, String> {
    check_same_size(a, b, "A and B")?;
    let mut n = 0usize;
    let mut squared = 0.0;
    let mut relative = 0.0;
    let mut max_difference = 0.0f64;
    let mut mean_a = [0.0; 3];
    let mut mean_b = [0.0; 3];
    let mut per_channel = [0usize; 3];
    let (mut nonfinite_a, mut nonfinite_b) = (0, 0);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let (x, y) = (pa[c] as f64, pb[c] as f64);
            nonfinite_a += !x.is_finite() as usize;
            nonfinite_b += !y.is_finite() as usize;
            if !(x.is_finite() && y.is_finite()) {
                continue;
            }
            n += 1;
            per_channel[c] += 1;
            let d = x - y;
            squared += d * d;
            relative += d * d / (y * y + REL_MSE_EPSILON);
            max_difference = max_difference.max(d.abs());
            mean_a[c] += x;
            mean_b[c] += y;
        }
    }
    let n = n.max(1) as f64;
    let z_test = match variances {
        Some((va, vb)) => {
            check_same_size(a, va, "A and its variance")?;
            check_same_size(b, vb, "B and its variance")?;
            Some(z_test(a, b, va, vb))
        }
        None => None,
    };
    let channel_mean =
        |sums: [f64; 3]| std::array::from_fn(|c| sums[c] / per_channel[c].max(1) as f64);
    Ok(Comparison {
        rmse: (squared / n).sqrt(),
        relative_mse: relative / n,
        mean_a: channel_mean(mean_a),
        mean_b: channel_mean(mean_b),
        max_difference,
        z_test,
        nonfinite_a,
        nonfinite_b,
    })
}

fn z_test(a: &Image, b: &Image, va: &Image, vb: &Image) -> ZTest {
    let mut passed = 0usize;
    let mut tested = 0usize;
    let (mut diff_sum, mut var_sum, mut squared_sum) = (0.0, 0.0, 0.0);
    for i in 0..a.pixels.len() {
        for c in 0..3 {
            let d = a.pixels[i][c] as f64 - b.pixels[i][c] as f64;
            let (var_a, var_b) = (va.pixels[i][c], vb.pixels[i][c]);
            // f32::max would turn a NaN variance into 0: leave such channels out instead.
            if !(d.is_finite() && var_a.is_finite() && var_b.is_finite()) {
                continue;
            }
            let v = var_a.max(0.0) as f64 + var_b.max(0.0) as f64;
            diff_sum += d;
            var_sum += v;
            squared_sum += d * d;
            tested += 1;
            // Zero variance on both sides (e.g. the sky seen directly): the values must agree.
            let pass = if v > 0.0 {
                d.abs() <= Z_CRITICAL * v.sqrt()
            } else {
                d.abs() <= 1e-6 * (a.pixels[i][c].abs() as f64).max(1.0)
            };
            passed += pass as usize;
        }
    }
    ZTest {
        pass_rate: passed as f64 / tested.max(1) as f64,
        tested,
        z_of_means: if var_sum > 0.0 {
            diff_sum / var_sum.sqrt()
        } else {
            0.0
        },
        variance_ratio: if var_sum > 0.0 {
            squared_sum / var_sum
        } else {
            f64::NAN
        },
    }
}

/// A false-colour picture of A − B (channel mean): red where A is brighter, blue where B is,
/// black where they agree. The scale is 3σ of the combined noise when variances are given
/// (so saturated colour means a significant difference), else the largest difference.
pub fn difference_image(a: &Image, b: &Image, variances: Option<(&Image, &Image)>) -> Image {
    let diffs: Vec<f64> = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(pa, pb)| (0..3).map(|c| pa[c] as f64 - pb[c] as f64).sum::<f64>() / 3.0)
        .collect();
    let scales: Vec<f64> = match variances {
        Some((va, vb)) => va
            .pixels
            .iter()
            .zip(&vb.pixels)
            // The variance of a channel mean is at most the mean of the channel variances.
            .map(|(x, y)| {
                3.0 * ((0..3).map(|c| (x[c] + y[c]).max(0.0) as f64).sum::<f64>() / 3.0).sqrt()
            })
            .collect(),
        None => {
            let max = diffs.iter().fold(0.0f64, |m, d| m.max(d.abs()));
            vec![max; diffs.len()]
        }
    };
    let pixels = diffs
        .iter()
        .zip(&scales)
        .map(|(&d, &s)| {
            let t = if s > 0.0 {
                (d / s).clamp(-1.0, 1.0) as f32
            } else {
                0.0
            };
            if t >= 0.0 {
                [t, 0.25 * t, 0.0]
            } else {
                [0.0, 0.25 * -t, -t]
            }
        })
        .collect();
    Image {
        width: a.width,
        height: a.height,
        pixels,
    }
}
