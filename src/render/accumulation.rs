//! A render's per-pixel running statistics (mean and M2 over each pixel's count of samples), as
//! the renderers keep them and as partial files store them, the exact pairwise merge of two,
//! and which pixels still take samples (adaptive sampling, `src/render/adaptive.rs`).
//!
//! Bidirectional renders (those with a splat film) keep other second moments: light tracing
//! splats into any pixel, so a pixel's own samples do not show its variance. Their M2 is the
//! sum of squares between batch means (`src/render/batch_means.rs`), over `batches` batches.

use crate::cpu::integrator::splat::fixed_point_value;
use crate::image::output::Image;

/// Per-pixel mean radiance and M2 (the sum of squared deviations from the mean) over each
/// pixel's own count of samples, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulation {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the sample range(s) covered: the most any pixel holds.
    pub count: u32,
    /// Each pixel's own sample count, at most `count`: all equal to it unless adaptive sampling
    /// stopped some pixels early. A pixel stopped in a range holds that range's first samples.
    pub counts: Vec<u32>,
    pub mean: Vec<[f32; 3]>,
    pub m2: Vec<[f32; 3]>,
    /// Bidirectional path tracing's splat film: per pixel and channel a 64-bit fixed-point
    /// sum at `splat_scale` (`src/cpu/integrator/splat.rs`); empty for path tracing. The
    /// image adds it divided by `count`.
    pub splats: Vec<u64>,
    pub splat_scale: f32,
    /// Bidirectional renders: how many batches `m2` is the between-batch sum of squares of
    /// (`src/render/batch_means.rs`); 0 for path tracing, whose `m2` is the samples' own.
    pub batches: u32,
}

impl Accumulation {
    /// No samples yet.
    pub fn empty(width: u32, height: u32) -> Accumulation {
        let pixels = width as usize * height as usize;
        Accumulation {
            width,
            height,
            count: 0,
            counts: vec![0; pixels],
            mean: vec![[0.0; 3]; pixels],
            m2: vec![[0.0; 3]; pixels],
            splats: Vec::new(),
            splat_scale: 0.0,
            batches: 0,
        }
    }

    /// Whether this is a bidirectional render's: a splat film, and batch means in `m2`.
    pub fn is_bidirectional(&self) -> bool {
        !self.splats.is_empty()
    }

    /// Each pixel's full mean in f64: the camera strategies' mean plus, for a bidirectional
    /// render, its splat sum over the samples per pixel ([`Accumulation::mean_image`] before
    /// its rounding to f32).
    pub fn full_means(&self) -> Vec<[f64; 3]> {
        let n = self.count.max(1) as f64;
        self.mean
            .iter()
            .enumerate()
            .map(|(pixel, rgb)| {
                std::array::from_fn(|c| {
                    let splat = match self.splats.get(3 * pixel + c) {
                        Some(&w) => fixed_point_value(w, self.splat_scale) / n,
                        None => 0.0,
                    };
                    rgb[c] as f64 + splat
                })
            })
            .collect()
    }

    /// Whether every pixel holds `count` samples (no pixel was stopped early).
    pub fn is_uniform(&self) -> bool {
        self.counts.iter().all(|&n| n == self.count)
    }

    /// Samples held by all pixels together.
    pub fn total_samples(&self) -> u64 {
        self.counts.iter().map(|&n| n as u64).sum()
    }

    /// Adds `other`'s samples with Chan, Golub and LeVeque's pairwise update, pixel by pixel
    /// with each pixel's own counts, in the kernel's f32 arithmetic and operation order
    /// (`shaders/integrator/accumulate.wgsl`, where a block joins the totals). So merging the
    /// statistics of consecutive sample ranges gives the same bits as a render whose batches
    /// were those ranges, and adaptive parts weigh each pixel by its own samples. Both must
    /// have the same size.
    ///
    /// Bidirectional accumulations' M2 are between-batch sums of squares about their full
    /// means (splats included): they add as Chan's update says, SSB₁ + SSB₂ + n₁n₂/n (Ȳ₁ − Ȳ₂)²,
    /// with those means, in f64, and their batches add. That is the sum of squares a single
    /// render of the same batches accumulates (`src/render/batch_means.rs`), up to rounding.
    pub fn merge(&mut self, other: &Accumulation) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "merging accumulations of different sizes"
        );
        // Of bidirectional parts, the sum of squares between batch means (before the means
        // change below).
        let between_batches = (self.is_bidirectional() && other.is_bidirectional())
            .then(|| between_batch_merge(self, other));
        for i in 0..self.mean.len() {
            if other.counts[i] == 0 {
                continue;
            }
            let n_old = self.counts[i] as f32;
            let n_new = other.counts[i] as f32;
            let n = n_old + n_new;
            let mean_weight = n_new / n;
            let m2_weight = n_old * n_new / n;
            for c in 0..3 {
                let old_mean = self.mean[i][c];
                let delta = other.mean[i][c] - old_mean;
                self.mean[i][c] = old_mean + delta * mean_weight;
                self.m2[i][c] = self.m2[i][c] + other.m2[i][c] + delta * delta * m2_weight;
            }
            self.counts[i] += other.counts[i];
        }
        self.count += other.count;
        self.batches += other.batches;
        if let Some(m2) = between_batches {
            self.m2 = m2;
        }
        // Splat sums are integers: they add exactly, in any order (wrapping as the kernel's do).
        if self.splats.is_empty() {
            self.splats = other.splats.clone();
            self.splat_scale = other.splat_scale;
        } else {
            for (a, b) in self.splats.iter_mut().zip(&other.splats) {
                *a = a.wrapping_add(*b);
            }
        }
    }

    pub fn mean_image(&self) -> Image {
        let mut pixels = self.mean.clone();
        if !self.splats.is_empty() && self.count > 0 {
            let n = self.count as f64;
            for (pixel, rgb) in pixels.iter_mut().enumerate() {
                for (c, v) in rgb.iter_mut().enumerate() {
                    let splat = fixed_point_value(self.splats[3 * pixel + c], self.splat_scale);
                    *v = (*v as f64 + splat / n) as f32;
                }
            }
        }
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// The variance of each pixel's mean estimate (σ²/n, n the pixel's own count), as
    /// `--variance` writes it. A bidirectional render's is from its batch means instead:
    /// SSB / ((K − 1) n) (`src/render/batch_means.rs`).
    pub fn variance_image(&self) -> Image {
        if self.is_bidirectional() {
            return Image {
                width: self.width,
                height: self.height,
                pixels: self
                    .m2
                    .iter()
                    .map(|&ssb| batch_variance_of_mean(ssb, self.batches, self.count))
                    .collect(),
            };
        }
        Image {
            width: self.width,
            height: self.height,
            pixels: self
                .m2
                .iter()
                .zip(&self.counts)
                .map(|(&m2, &n)| variance_of_mean(m2, n))
                .collect(),
        }
    }
}

/// The between-batch sum of squares of `a` and `b` together, from each's own and their full
/// means: SSB₁ + SSB₂ + n₁n₂/n (Ȳ₁ − Ȳ₂)², in f64, rounded to f32 as the M2 channels hold it.
fn between_batch_merge(a: &Accumulation, b: &Accumulation) -> Vec<[f32; 3]> {
    let (mean_a, mean_b) = (a.full_means(), b.full_means());
    let (n1, n2) = (a.count as f64, b.count as f64);
    let weight = if n1 + n2 > 0.0 {
        n1 * n2 / (n1 + n2)
    } else {
        0.0
    };
    (0..a.m2.len())
        .map(|i| {
            std::array::from_fn(|c| {
                let delta = mean_b[i][c] - mean_a[i][c];
                (a.m2[i][c] as f64 + b.m2[i][c] as f64 + weight * delta * delta) as f32
            })
        })
        .collect()
}

/// σ²/n per channel from M2 over n samples: M2 / (n − 1) / n.
pub fn variance_of_mean(m2: [f32; 3], n: u32) -> [f32; 3] {
    if n < 2 {
        return [0.0; 3];
    }
    let scale = 1.0 / ((n as f64 - 1.0) * n as f64);
    m2.map(|v| (v.max(0.0) as f64 * scale) as f32)
}

/// The variance of a mean of n samples from the sum of squares between its K batch means
/// (`src/render/batch_means.rs`): SSB / ((K − 1) n); zero before two batches.
pub fn batch_variance_of_mean(ssb: [f32; 3], batches: u32, n: u32) -> [f32; 3] {
    if batches < 2 || n == 0 {
        return [0.0; 3];
    }
    let scale = 1.0 / ((batches as f64 - 1.0) * n as f64);
    ssb.map(|v| (v.max(0.0) as f64 * scale) as f32)
}

/// Which pixels still take samples and how many each holds: the renderers' side of adaptive
/// sampling. A pixel stopped at n samples keeps them and takes no more until a reset; the
/// others hold all the renderer's samples.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelCounts {
    /// The count each pixel stopped at; `u32::MAX` while it takes samples.
    stopped_at: Vec<u32>,
}

impl PixelCounts {
    /// Every pixel taking samples.
    pub fn new(pixels: usize) -> PixelCounts {
        PixelCounts {
            stopped_at: vec![u32::MAX; pixels],
        }
    }

    /// Every pixel taking samples again.
    pub fn reset(&mut self) {
        self.stopped_at.fill(u32::MAX);
    }

    pub fn is_stopped(&self, pixel: usize) -> bool {
        self.stopped_at[pixel] != u32::MAX
    }

    /// Pixels still taking samples.
    pub fn active(&self) -> usize {
        self.stopped_at.iter().filter(|&&n| n == u32::MAX).count()
    }

    /// Each pixel's count when the renderer holds `samples` per pixel.
    pub fn counts(&self, samples: u32) -> Vec<u32> {
        self.stopped_at.iter().map(|&n| n.min(samples)).collect()
    }

    /// Takes the counts of a loaded accumulation: the pixels below `count` were stopped.
    pub fn load(&mut self, counts: &[u32], count: u32) {
        for (stopped_at, &n) in self.stopped_at.iter_mut().zip(counts) {
            *stopped_at = if n < count { n } else { u32::MAX };
        }
    }

    /// Stops the pixels where `stop` is true at `samples`; returns those newly stopped.
    pub fn stop(&mut self, stop: &[bool], samples: u32) -> Vec<usize> {
        assert_eq!(stop.len(), self.stopped_at.len(), "one flag per pixel");
        let mut stopped = Vec::new();
        for (i, (stopped_at, &s)) in self.stopped_at.iter_mut().zip(stop).enumerate() {
            if s && *stopped_at == u32::MAX {
                *stopped_at = samples;
                stopped.push(i);
            }
        }
        stopped
    }
}
