//! Adaptive sampling: which pixels stop taking samples. The decision is made on the host, from
//! the accumulated statistics alone, at fixed checkpoints of the sample count (the merge
//! schedule's block ends from `min_spp` on: 16, 32, 64, 128, 192, … by default), so it does not
//! depend on how batches were sized, and a resumed render makes the same decisions as an
//! uninterrupted one. A stopped pixel keeps the first samples of the range, so it holds exactly
//! what a render with its count as `--spp` would hold there.
//!
//! The estimate of a pixel's error is its expected contribution to `glint compare`'s relative
//! MSE (`src/image/compare.rs`): e² = mean over the channels of σ²_c / (μ_c² + 0.01), σ²_c the
//! variance of the pixel's mean (M2 / (n(n − 1))) and μ_c its mean. The 0.01 is the metric's
//! own floor ([`REL_MSE_EPSILON`]): below a radiance of 0.1 (display white is 1) the error is
//! taken relative to 0.1, so black and near-black pixels are not chased for a relative error
//! no one sees.
//!
//! A pixel stops once e ≤ the target for each of the 8 pixels around it that still take
//! samples, its own left out.
//! Deciding from a pixel's own samples biases its mean: with skewed samples (rare bright
//! paths), a low variance estimate goes with a low mean, so pixels that stop early stop low.
//! On the 64² Cornell box at a target of 0.05 that made the image 0.9% dark (z of the image
//! means −5.7 against an independent reference); the neighbours' samples are independent of
//! the pixel's, and the same renders came out within 2σ. (Not strictly independent: a
//! neighbour's own stop depends on this pixel's samples, which moves what the neighbour holds
//! at later checkpoints; tests/suite/adaptive.rs measures what is left.) The neighbours are
//! also a larger sample of the error where the image is smooth; an isolated noisy pixel
//! among converged ones can stop noisy. Neighbours already stopped are left out (their error
//! no longer falls), so a pixel whose neighbours have all stopped stops too.

use crate::image::compare::REL_MSE_EPSILON;
use crate::kernel::schedule::is_block_end;
use crate::render::accumulation::Accumulation;

/// Default of `--adaptive-min-spp`: samples every pixel takes before any may stop. The
/// variance estimate of n samples has a relative standard deviation of about √(2/(n − 1))
/// (37% at 16) for normal samples, far more for the skewed ones of rare light paths; fewer
/// samples let too many pixels stop on a lucky start.
pub const DEFAULT_MIN_SPP: u32 = 16;

/// The settings of adaptive sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// The largest estimated relative error (see the module doc) a pixel may stop at.
    pub target_error: f64,
    /// Samples every pixel takes first (of the render's range).
    pub min_spp: u32,
}

impl Adaptive {
    /// Whether a render whose range starts at the global sample `first` decides which pixels
    /// stop once it holds `samples` of it.
    pub fn is_checkpoint(&self, first: u32, samples: u32) -> bool {
        samples >= self.min_spp.max(2) && is_block_end(first + samples)
    }

    /// Samples to add after `done` of the range starting at `first` to reach the next
    /// checkpoint.
    pub fn until_checkpoint(&self, first: u32, done: u32) -> u32 {
        let wanted = (first + self.min_spp.max(2))
            .saturating_sub(first + done)
            .max(1);
        crate::kernel::schedule::next_block_end(first + done, wanted, u32::MAX) - (first + done)
    }

    /// `header` text for partial files: `target-error=E min-spp=N`.
    pub fn to_header(&self) -> String {
        format!(
            "target-error={} min-spp={}",
            self.target_error, self.min_spp
        )
    }

    /// Reads [`Adaptive::to_header`]'s text.
    pub fn from_header(text: &str) -> Result<Adaptive, String> {
        let mut target_error = None;
        let mut min_spp = None;
        for word in text.split_whitespace() {
            match word.split_once('=') {
                Some(("target-error", v)) => target_error = v.parse::<f64>().ok(),
                Some(("min-spp", v)) => min_spp = v.parse::<u32>().ok(),
                _ => return Err(format!("unknown setting {word:?}")),
            }
        }
        match (target_error, min_spp) {
            (Some(e), Some(n)) if e.is_finite() && e > 0.0 => Ok(Adaptive {
                target_error: e,
                min_spp: n,
            }),
            _ => Err(format!(
                "expected \"target-error=E min-spp=N\", got {text:?}"
            )),
        }
    }
}

/// Each pixel's estimated error squared (see the module doc), in f64 from the stored f32
/// statistics, so it is the same on every machine for the same statistics. Pixels below two
/// samples have no variance estimate: infinite.
pub fn pixel_errors_squared(acc: &Accumulation) -> Vec<f64> {
    acc.mean
        .iter()
        .zip(&acc.m2)
        .zip(&acc.counts)
        .map(|((mean, m2), &n)| {
            if n < 2 {
                return f64::INFINITY;
            }
            let n = n as f64;
            let mut sum = 0.0;
            for c in 0..3 {
                let variance = m2[c].max(0.0) as f64 / ((n - 1.0) * n);
                let mu = mean[c] as f64;
                sum += variance / (mu * mu + REL_MSE_EPSILON);
            }
            sum / 3.0
        })
        .collect()
}

/// The pixels whose neighbours that still take samples (the 8 around it, within the image, the
/// pixel itself left out; those holding all `acc.count` samples) all have estimated errors at
/// most `target`: those that may stop. A stopped neighbour no longer counts: its error is
/// frozen, and would otherwise keep its neighbours sampling forever. A pixel with no such
/// neighbour stops too, except in a 1×1 image, which decides by its own pixel.
pub fn converged(acc: &Accumulation, target: f64) -> Vec<bool> {
    let errors = pixel_errors_squared(acc);
    let limit = target * target;
    let (w, h) = (acc.width as usize, acc.height as usize);
    if w * h == 1 {
        return vec![errors[0] <= limit];
    }
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let mut worst = 0.0f64;
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    let q = yy * w + xx;
                    if q != i && acc.counts[q] == acc.count {
                        worst = worst.max(errors[q]);
                    }
                }
            }
            worst <= limit
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn accumulation(width: u32, height: u32, count: u32) -> Accumulation {
        let mut a = Accumulation::empty(width, height);
        a.count = count;
        a.counts.fill(count);
        a
    }

    #[test]
    fn checkpoints_are_block_ends_from_the_minimum_on() {
        let a = Adaptive {
            target_error: 0.1,
            min_spp: 16,
        };
        let ends: Vec<u32> = (1..=300).filter(|&n| a.is_checkpoint(0, n)).collect();
        assert_eq!(ends, [16, 32, 64, 128, 192, 256]);
        assert_eq!(a.until_checkpoint(0, 0), 16);
        assert_eq!(a.until_checkpoint(0, 16), 16);
        assert_eq!(a.until_checkpoint(0, 64), 64);
        // A range starting at 100: at least 16 of its own, ending at a global block end.
        assert_eq!(a.until_checkpoint(100, 0), 28);
        assert!(a.is_checkpoint(100, 28) && !a.is_checkpoint(100, 12));
    }

    #[test]
    fn the_header_text_reads_back() {
        let a = Adaptive {
            target_error: 0.05,
            min_spp: 32,
        };
        assert_eq!(Adaptive::from_header(&a.to_header()), Ok(a));
        assert!(Adaptive::from_header("target-error=0 min-spp=3").is_err());
        assert!(Adaptive::from_header("colour=red").is_err());
    }

    #[test]
    fn a_noisy_pixel_keeps_its_neighbours_sampling_not_itself() {
        // 5×4, all flat except pixel (1, 1), whose error is about 0.3.
        let mut a = accumulation(5, 4, 16);
        for p in &mut a.mean {
            *p = [0.5; 3];
        }
        a.m2[6] = [0.25 * 0.3 * 0.3 * 240.0; 3];
        let e = pixel_errors_squared(&a)[6].sqrt();
        assert!((e - 0.3).abs() < 0.01, "{e}");
        let stop = converged(&a, 0.1);
        for y in 0..4 {
            for x in 0..5 {
                let expected = x > 2 || y > 2 || (x, y) == (1, 1);
                assert_eq!(stop[y * 5 + x], expected, "({x}, {y})");
            }
        }
        assert!(converged(&a, 0.31).iter().all(|&s| s));
        // Once the noisy pixel has stopped (fewer samples than the rest), it holds no one back.
        a.counts[6] = 8;
        assert!(converged(&a, 0.1).iter().all(|&s| s));
    }

    #[test]
    fn dark_pixels_are_measured_against_the_floor() {
        let mut a = accumulation(1, 1, 16);
        // σ of the mean 0.01 at a mean of 0.001: 10 relative, 0.1 against the floor of 0.1.
        a.mean[0] = [0.001; 3];
        a.m2[0] = [1e-4 * 240.0; 3];
        let e = pixel_errors_squared(&a)[0].sqrt();
        assert!((e - 0.0995).abs() < 1e-3, "{e}");
    }
}
