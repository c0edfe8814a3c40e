//! A render's per-pixel running statistics (mean and M2 over a count of samples), as the
//! renderers keep them and as partial files store them, and the exact pairwise merge of two.

use crate::cpu::integrator::splat::fixed_point_value;
use crate::image::output::Image;

/// Per-pixel mean radiance and M2 (the sum of squared deviations from the mean) over `count`
/// samples per pixel, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulation {
    pub width: u32,
    pub height: u32,
    pub count: u32,
    pub mean: Vec<[f32; 3]>,
    pub m2: Vec<[f32; 3]>,
    /// Bidirectional path tracing's splat film: per pixel and channel a 64-bit fixed-point
    /// sum at `splat_scale` (`src/cpu/integrator/splat.rs`); empty for path tracing. The
    /// image adds it divided by `count`.
    pub splats: Vec<u64>,
    pub splat_scale: f32,
}

impl Accumulation {
    /// No samples yet.
    pub fn empty(width: u32, height: u32) -> Accumulation {
        let pixels = width as usize * height as usize;
        Accumulation {
            width,
            height,
            count: 0,
            mean: vec![[0.0; 3]; pixels],
            m2: vec![[0.0; 3]; pixels],
            splats: Vec::new(),
            splat_scale: 0.0,
        }
    }

    /// Adds `other`'s samples with Chan, Golub and LeVeque's pairwise update, in the kernel's
    /// f32 arithmetic and operation order (`shaders/integrator/path.wgsl`, where a batch joins the
    /// totals). So merging the statistics of consecutive sample ranges gives the same bits as
    /// a render whose batches were those ranges. Both must have the same size.
    pub fn merge(&mut self, other: &Accumulation) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "merging accumulations of different sizes"
        );
        if other.count == 0 {
            return;
        }
        let n_old = self.count as f32;
        let n_new = other.count as f32;
        let n = n_old + n_new;
        let mean_weight = n_new / n;
        let m2_weight = n_old * n_new / n;
        for i in 0..self.mean.len() {
            for c in 0..3 {
                let old_mean = self.mean[i][c];
                let delta = other.mean[i][c] - old_mean;
                self.mean[i][c] = old_mean + delta * mean_weight;
                self.m2[i][c] = self.m2[i][c] + other.m2[i][c] + delta * delta * m2_weight;
            }
        }
        self.count += other.count;
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

    /// The variance of each pixel's mean estimate (σ²/n), as `--variance` writes it.
    pub fn variance_image(&self) -> Image {
        Image {
            width: self.width,
            height: self.height,
            pixels: self
                .m2
                .iter()
                .map(|&m2| variance_of_mean(m2, self.count))
                .collect(),
        }
    }
}

/// σ²/n per channel from M2 over n samples: M2 / (n − 1) / n.
pub fn variance_of_mean(m2: [f32; 3], n: u32) -> [f32; 3] {
    if n < 2 {
        return [0.0; 3];
    }
    let scale = 1.0 / ((n as f64 - 1.0) * n as f64);
    m2.map(|v| (v.max(0.0) as f64 * scale) as f32)
}
