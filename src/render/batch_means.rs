//! The variance of a bidirectional render's pixels, from batch means.
//!
//! Light tracing (the t = 1 strategy) splats a light subpath's contributions into whichever
//! pixels they land in, so a pixel's own camera samples do not show the variance of its
//! estimate: its M2 misses the splats, and the splats of one sample index land in many pixels.
//! What is independent is the sample index: Yᵢ(p), pixel p's camera estimate of sample i plus
//! every splat the light subpath of sample i put into p, are i.i.d. over i, and the pixel's
//! estimate is their mean Ȳ over the N samples.
//!
//! So the samples are grouped into batches, the merge schedule's blocks (`src/kernel/
//! schedule.rs`: 1, 1, 2, 4, …, 32, then 64 at a time, by global sample index, the same for
//! every pixel), cut where a call to [`Renderer::add_samples`] ends (a sample range's end). With
//! K batches of nₖ samples whose means are bₖ, the sum of squares between them,
//! SSB = Σ nₖ (bₖ − Ȳ)², has expectation (K − 1) σ² for unequal sizes too (one-way ANOVA:
//! E[nₖ (bₖ − Ȳ)²] = σ² − nₖσ²/N), so SSB / ((K − 1) N) is an unbiased estimate of the variance
//! of Ȳ, σ²/N. It has about K − 1 degrees of freedom per pixel: few at first (3 at 8 spp, 6 at
//! 64), one more per 64 samples after; the image's mean variance, which `--target-error` uses,
//! averages it over many pixels.
//!
//! SSB is what Chan's pairwise update accumulates when each batch joins with an M2 of zero:
//! after a batch of nₖ samples, SSB += (N_prev nₖ / N) (bₖ − Ȳ_prev)² = N_prev N / nₖ (Ȳ − Ȳ_prev)²,
//! with Ȳ_prev and Ȳ the pixel's full mean (camera strategies plus splats) before and after the
//! batch. [`BatchMeans`] wraps either device's renderer and does that on the host after every
//! batch, in f64 from the renderer's accumulation (the splat sums are exact integers), keeping
//! SSB in f32 as a partial file's M2 channels hold it: a render resumed from a file then goes on
//! with the very numbers a render made at once has, and its variance is the same bytes. Its
//! accumulations carry SSB in their M2 and K in `batches` (`glint.batches` in a partial file);
//! [`Accumulation::merge`] joins two as Chan's update does, which gives a single render's SSB up
//! to rounding when the parts split the samples at batch ends.
//!
//! The cost is one readback of the mean and the splat film per batch: a few per render, then
//! one per 64 samples per pixel.

use crate::image::aov::Aovs;
use crate::image::output::Image;
use crate::kernel::schedule::next_block_end;
use crate::kernel::types::{Params, INTEGRATOR_BDPT};
use crate::render::accumulation::{batch_variance_of_mean, Accumulation};
use crate::render::Renderer;
use anyhow::{anyhow, bail, Result};
use std::ops::DerefMut;
use std::time::Duration;

/// A renderer whose variance comes from batch means (see the module's documentation).
pub struct BatchMeans<R> {
    inner: R,
    /// Per pixel and channel, the sum of squares between the batch means.
    ssb: Vec<[f32; 3]>,
    /// Batches so far (K).
    batches: u32,
    /// Each pixel's full mean after the last batch.
    means: Vec<[f64; 3]>,
    /// The image's width and height, once an accumulation has shown them.
    size: (u32, u32),
}

/// `renderer` with batch-means variance where `params` renders bidirectionally; as it is
/// otherwise.
pub fn for_params<'a>(renderer: Box<dyn Renderer + 'a>, params: &Params) -> Box<dyn Renderer + 'a> {
    if params.integrator == INTEGRATOR_BDPT {
        Box::new(BatchMeans::new(renderer))
    } else {
        renderer
    }
}

impl<R> BatchMeans<R>
where
    R: DerefMut,
    R::Target: Renderer,
{
    /// Wraps `inner`, which must hold no samples yet (or be loaded through the wrapper).
    pub fn new(inner: R) -> BatchMeans<R> {
        BatchMeans {
            inner,
            ssb: Vec::new(),
            batches: 0,
            means: Vec::new(),
            size: (0, 0),
        }
    }

    pub fn inner(&mut self) -> &mut R::Target {
        &mut self.inner
    }

    /// Closes a batch that ended `samples_before` samples after the first: adds its term to
    /// SSB.
    fn close_batch(&mut self, samples_before: u32) -> Result<()> {
        let accumulation = self.inner.read_accumulation()?;
        let means = accumulation.full_means();
        let (n_prev, n) = (samples_before as f64, accumulation.count as f64);
        if self.ssb.len() != means.len() {
            self.ssb = vec![[0.0; 3]; means.len()];
        }
        if samples_before > 0 && !self.means.is_empty() {
            let weight = n_prev * n / (n - n_prev);
            for ((ssb, new), old) in self.ssb.iter_mut().zip(&means).zip(&self.means) {
                for c in 0..3 {
                    let delta = new[c] - old[c];
                    ssb[c] = (ssb[c] as f64 + weight * delta * delta) as f32;
                }
            }
        }
        self.means = means;
        self.batches += 1;
        self.size = (accumulation.width, accumulation.height);
        Ok(())
    }
}

impl<R> Renderer for BatchMeans<R>
where
    R: DerefMut,
    R::Target: Renderer,
{
    /// Adds the samples a batch at a time: one per block of the merge schedule, and the last
    /// one ending where `count` does.
    fn add_samples(&mut self, count: u32) -> Result<()> {
        let end = self.inner.samples() + count;
        while self.inner.samples() < end {
            let before = self.inner.samples();
            let first = self.inner.first_sample();
            let next = next_block_end(first + before, 1, first + end) - first;
            self.inner.add_samples(next - before)?;
            self.close_batch(before)?;
        }
        Ok(())
    }

    fn samples(&self) -> u32 {
        self.inner.samples()
    }

    fn first_sample(&self) -> u32 {
        self.inner.first_sample()
    }

    /// The renderer's accumulation with the sum of squares between batch means in its M2.
    fn read_accumulation(&mut self) -> Result<Accumulation> {
        let mut accumulation = self.inner.read_accumulation()?;
        accumulation.m2 = if self.ssb.is_empty() {
            vec![[0.0; 3]; accumulation.mean.len()]
        } else {
            self.ssb.clone()
        };
        accumulation.batches = self.batches;
        Ok(accumulation)
    }

    fn load_accumulation(&mut self, first_sample: u32, state: Option<&Accumulation>) -> Result<()> {
        // The renderer's own M2 then holds SSB, and goes on as its camera strategies' M2 from
        // there: never read, as this wrapper's M2 replaces it.
        self.inner.load_accumulation(first_sample, state)?;
        match state {
            Some(state) if state.count > 0 => {
                if !state.is_bidirectional() || state.batches == 0 {
                    bail!("the accumulation holds no batch means of a bidirectional render");
                }
                self.ssb = state.m2.clone();
                self.batches = state.batches;
                self.means = state.full_means();
                self.size = (state.width, state.height);
            }
            _ => {
                self.ssb.clear();
                self.batches = 0;
                self.means.clear();
            }
        }
        Ok(())
    }

    fn read_mean(&mut self) -> Result<Image> {
        self.inner.read_mean()
    }

    /// SSB / ((K − 1) N): zero before two batches.
    fn read_variance(&mut self) -> Result<Image> {
        if self.ssb.is_empty() {
            // No batch yet: zero, in the renderer's image shape.
            let mut variance = self.inner.read_variance()?;
            variance.pixels.fill([0.0; 3]);
            return Ok(variance);
        }
        let n = self.inner.samples();
        Ok(Image {
            width: self.size.0,
            height: self.size.1,
            pixels: self
                .ssb
                .iter()
                .map(|&ssb| batch_variance_of_mean(ssb, self.batches, n))
                .collect(),
        })
    }

    fn read_aovs(&mut self) -> Result<Aovs> {
        self.inner.read_aovs()
    }

    fn reset(&mut self) -> Result<()> {
        self.ssb.clear();
        self.batches = 0;
        self.means.clear();
        self.inner.reset()
    }

    /// Batch means need every pixel to take every sample: stopping a pixel is an error.
    fn stop_pixels(&mut self, stop: &[bool]) -> Result<()> {
        if stop.iter().any(|&s| s) {
            return Err(anyhow!(
                "adaptive sampling cannot stop pixels of a bidirectional render (its variance \
                 comes from batch means of every pixel's samples)"
            ));
        }
        self.inner.stop_pixels(stop)
    }

    fn pixel_counts(&self) -> Vec<u32> {
        self.inner.pixel_counts()
    }

    fn active_pixels(&self) -> usize {
        self.inner.active_pixels()
    }

    fn segments_traced(&self) -> Option<u64> {
        self.inner.segments_traced()
    }

    fn last_kernel_time(&self) -> Option<Duration> {
        self.inner.last_kernel_time()
    }

    fn nonfinite_samples(&self) -> u64 {
        self.inner.nonfinite_samples()
    }

    fn device_name(&self) -> String {
        self.inner.device_name()
    }

    fn backend_name(&self) -> String {
        self.inner.backend_name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A renderer of two pixels whose sample i is known: a camera value and a splat (a whole
    /// number, at scale 1) per pixel and channel, so the batch means can be worked out here.
    struct Fake {
        first: u32,
        samples: u32,
        /// The camera values' mean (updated per call in f32, as a kernel's is per batch),
        /// and the splat film.
        mean: Vec<[f32; 3]>,
        splats: Vec<u64>,
    }

    const PIXELS: usize = 2;

    /// Sample `i`'s camera value and splat for `pixel`, channel `c`: skewed, as light is.
    fn sample(i: u32, pixel: usize, c: usize) -> (f64, u64) {
        let h = (i as u64 + 1)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(((3 * pixel + c) as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9));
        let h = h ^ (h >> 29);
        let camera = (h % 1000) as f64 / 250.0;
        let splat = if h.is_multiple_of(7) {
            (h >> 40) % 50
        } else {
            0
        };
        (camera, splat)
    }

    fn y(i: u32, pixel: usize, c: usize) -> f64 {
        let (camera, splat) = sample(i, pixel, c);
        camera + splat as f64
    }

    impl Fake {
        fn new() -> Fake {
            Fake {
                first: 0,
                samples: 0,
                mean: vec![[0.0; 3]; PIXELS],
                splats: vec![0; 3 * PIXELS],
            }
        }
    }

    impl Renderer for Fake {
        fn add_samples(&mut self, count: u32) -> Result<()> {
            let start = self.first + self.samples;
            let n = (self.samples + count) as f32;
            for p in 0..PIXELS {
                for c in 0..3 {
                    let mut sum = 0.0;
                    for i in start..start + count {
                        let (camera, splat) = sample(i, p, c);
                        sum += camera;
                        self.splats[3 * p + c] += splat;
                    }
                    let batch = (sum / count as f64) as f32;
                    let old = self.mean[p][c];
                    self.mean[p][c] = old + (batch - old) * (count as f32 / n);
                }
            }
            self.samples += count;
            Ok(())
        }
        fn samples(&self) -> u32 {
            self.samples
        }
        fn first_sample(&self) -> u32 {
            self.first
        }
        fn read_accumulation(&mut self) -> Result<Accumulation> {
            Ok(Accumulation {
                width: PIXELS as u32,
                height: 1,
                count: self.samples,
                counts: vec![self.samples; PIXELS],
                mean: self.mean.clone(),
                // The camera values' own M2, which batch means replace: nonsense here.
                m2: vec![[-1.0; 3]; PIXELS],
                splats: self.splats.clone(),
                splat_scale: 1.0,
                batches: 0,
            })
        }
        fn load_accumulation(&mut self, first: u32, state: Option<&Accumulation>) -> Result<()> {
            self.reset()?;
            self.first = first;
            if let Some(state) = state {
                self.samples = state.count;
                self.mean = state.mean.clone();
                self.splats = state.splats.clone();
            }
            Ok(())
        }
        fn read_mean(&mut self) -> Result<Image> {
            Ok(self.read_accumulation()?.mean_image())
        }
        fn read_variance(&mut self) -> Result<Image> {
            Ok(Image {
                width: PIXELS as u32,
                height: 1,
                pixels: vec![[-1.0; 3]; PIXELS],
            })
        }
        fn reset(&mut self) -> Result<()> {
            *self = Fake {
                first: self.first,
                ..Fake::new()
            };
            Ok(())
        }
        fn stop_pixels(&mut self, _stop: &[bool]) -> Result<()> {
            Ok(())
        }
        fn pixel_counts(&self) -> Vec<u32> {
            vec![self.samples; PIXELS]
        }
        fn active_pixels(&self) -> usize {
            PIXELS
        }
        fn nonfinite_samples(&self) -> u64 {
            0
        }
        fn device_name(&self) -> String {
            "fake".into()
        }
        fn backend_name(&self) -> String {
            "fake".into()
        }
    }

    /// The variance of the mean from the batches between `ends` (0 first), worked out from
    /// the samples: Σ nₖ (bₖ − Ȳ)² / ((K − 1) N).
    fn expected(ends: &[u32], pixel: usize, c: usize) -> f64 {
        let (start, end) = (ends[0], *ends.last().unwrap());
        let n = (end - start) as f64;
        let mean = (start..end).map(|i| y(i, pixel, c)).sum::<f64>() / n;
        let ssb: f64 = ends
            .windows(2)
            .map(|w| {
                let size = (w[1] - w[0]) as f64;
                let b = (w[0]..w[1]).map(|i| y(i, pixel, c)).sum::<f64>() / size;
                size * (b - mean) * (b - mean)
            })
            .sum();
        ssb / ((ends.len() - 2) as f64 * n)
    }

    fn assert_close(variance: &Image, ends: &[u32]) {
        for p in 0..PIXELS {
            for c in 0..3 {
                let (got, want) = (variance.pixels[p][c] as f64, expected(ends, p, c));
                // f32 means and sums of squares: a few ulps of the terms.
                assert!(
                    (got - want).abs() <= 1e-5 * want,
                    "pixel {p} channel {c}: {got} vs {want} of the batches {ends:?}"
                );
            }
        }
    }

    #[test]
    fn variance_is_the_spread_of_the_batch_means_splats_included() {
        let mut r = BatchMeans::new(Box::new(Fake::new()));
        assert_eq!(r.read_variance().unwrap().pixels, [[0.0; 3]; PIXELS]);
        // Batches end at the blocks 1, 2, 4, …, 64, 128 and where a call ends (3, 53).
        for count in [3, 50, 47, 28] {
            r.add_samples(count).unwrap();
        }
        let ends = [0, 1, 2, 3, 4, 8, 16, 32, 53, 64, 100, 128];
        assert_eq!(r.read_accumulation().unwrap().batches, 11);
        assert_close(&r.read_variance().unwrap(), &ends);
        assert_close(&r.read_accumulation().unwrap().variance_image(), &ends);
        // One batch: no estimate yet.
        let mut one = BatchMeans::new(Box::new(Fake::new()));
        one.add_samples(1).unwrap();
        assert_eq!(one.read_variance().unwrap().pixels, [[0.0; 3]; PIXELS]);
    }

    #[test]
    fn resumed_and_merged_batch_means_are_a_single_renders() {
        let mut once = BatchMeans::new(Box::new(Fake::new()));
        once.add_samples(128).unwrap();
        let once = once.read_accumulation().unwrap();
        // Resumed at 64: the same numbers.
        let mut first = BatchMeans::new(Box::new(Fake::new()));
        first.add_samples(64).unwrap();
        let half = first.read_accumulation().unwrap();
        let mut resumed = BatchMeans::new(Box::new(Fake::new()));
        resumed.load_accumulation(0, Some(&half)).unwrap();
        resumed.add_samples(64).unwrap();
        assert_eq!(resumed.read_accumulation().unwrap(), once);
        // Merged from 0..64 and 64..128 rendered apart: the same batches, to rounding.
        let mut second = BatchMeans::new(Box::new(Fake::new()));
        second.load_accumulation(64, None).unwrap();
        second.add_samples(64).unwrap();
        let mut merged = half;
        merged.merge(&second.read_accumulation().unwrap());
        assert_eq!(merged.batches, once.batches);
        assert_close(&merged.variance_image(), &[0, 1, 2, 4, 8, 16, 32, 64, 128]);
        // A merge at 40, inside the block 32..64, splits it in two.
        let mut a = BatchMeans::new(Box::new(Fake::new()));
        a.add_samples(40).unwrap();
        let mut b = BatchMeans::new(Box::new(Fake::new()));
        b.load_accumulation(40, None).unwrap();
        b.add_samples(88).unwrap();
        let mut split = a.read_accumulation().unwrap();
        split.merge(&b.read_accumulation().unwrap());
        assert_close(
            &split.variance_image(),
            &[0, 1, 2, 4, 8, 16, 32, 40, 64, 128],
        );
    }

    #[test]
    fn pixels_cannot_stop_and_path_accumulations_do_not_load() {
        let mut r = BatchMeans::new(Box::new(Fake::new()));
        r.add_samples(4).unwrap();
        assert!(r.stop_pixels(&[false, true]).is_err());
        r.stop_pixels(&[false, false]).unwrap();
        let mut path = r.read_accumulation().unwrap();
        path.splats.clear();
        path.batches = 0;
        assert!(r.load_accumulation(0, Some(&path)).is_err());
    }
}
