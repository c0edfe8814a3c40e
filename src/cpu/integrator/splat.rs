//! The splat film (WGSL side: `shaders/integrator/splat.wgsl`): light tracing's contributions,
//! added into whichever pixel they land in, by every pixel's samples at once. WGSL has only
//! integer atomics, and a float sum would depend on the order of the adds; so each channel is
//! a 64-bit fixed-point sum, two u32 words, to which every splat adds an integer: the sum is
//! exact and the same in any order, on the GPU and here, and a render is reproducible byte for
//! byte.
//!
//! A splat of value v adds ⌊v · scale + ½⌋ (`Params::splat_scale`, chosen from the scene's
//! brightest emitter, `src/kernel/scene/params.rs`): rounding costs at most ½ / scale per
//! splat. A sum wraps modulo 2⁶⁴, which needs some 2⁴⁰ times the brightest emitter's radiance
//! in one pixel and channel; each splat is clamped to 2⁶² so that none wraps alone.

use glam::Vec3;
use std::sync::atomic::{AtomicU64, Ordering};

/// The largest integer one splat adds (per channel).
pub const MAX_SPLAT: f32 = 4.611_686e18; // 2^62

/// The fixed-point words (low, high) of a splat of value `v` at `scale`. In f32 throughout, as
/// the kernel computes them: x < 2³² converts directly; above, x is a multiple of 2⁸, and its
/// high and low words split exactly.
pub fn fixed_point_words(v: f32, scale: f32) -> (u32, u32) {
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(v > 0.0) {
        return (0, 0);
    }
    let x = (v * scale + 0.5).floor().min(MAX_SPLAT);
    if x < 4_294_967_296.0 {
        return (x as u32, 0);
    }
    let high = (x * (1.0 / 4_294_967_296.0)).floor();
    let low = (x * (1.0 / 4_294_967_296.0) - high) * 4_294_967_296.0;
    (low as u32, high as u32)
}

/// The value of a fixed-point sum.
pub fn fixed_point_value(sum: u64, scale: f32) -> f64 {
    sum as f64 / scale as f64
}

/// Per pixel, per channel: the 64-bit sum.
#[derive(Debug, Default)]
pub struct SplatFilm {
    pub sums: Vec<AtomicU64>,
}

impl SplatFilm {
    pub fn new(pixels: usize) -> SplatFilm {
        SplatFilm {
            sums: (0..3 * pixels).map(|_| AtomicU64::new(0)).collect(),
        }
    }

    /// Adds `radiance` to `pixel` (wrapping, as the kernel's two-word add does).
    pub fn add(&self, pixel: u32, radiance: Vec3, scale: f32) {
        for (c, v) in radiance.to_array().into_iter().enumerate() {
            let (low, high) = fixed_point_words(v, scale);
            let word = ((high as u64) << 32) | low as u64;
            if word != 0 {
                self.sums[3 * pixel as usize + c].fetch_add(word, Ordering::Relaxed);
            }
        }
    }

    /// The sums as they stand.
    pub fn words(&self) -> Vec<u64> {
        self.sums
            .iter()
            .map(|s| s.load(Ordering::Relaxed))
            .collect()
    }

    pub fn load(&mut self, words: &[u64]) {
        for (s, w) in self.sums.iter_mut().zip(words) {
            *s.get_mut() = *w;
        }
    }

    pub fn clear(&mut self) {
        for s in &mut self.sums {
            *s.get_mut() = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_split_exactly_above_two_to_the_32() {
        let scale = 1.0;
        for v in [
            0.0f32, 0.4, 0.6, 1.0, 12345.5, 4.0e9, 4.3e9, 1.0e15, 3.0e18, 1.0e30,
        ] {
            let (low, high) = fixed_point_words(v, scale);
            let word = ((high as u64) << 32) | low as u64;
            let expected = ((v as f64 * scale as f64 + 0.5).floor()).min(MAX_SPLAT as f64);
            // f32 rounding of v·scale + ½ is the only difference from the exact value.
            assert!(
                (word as f64 - expected).abs() <= expected * 1.2e-7 + 1.0,
                "{v}: {word} vs {expected}"
            );
        }
        assert_eq!(fixed_point_words(-1.0, 1.0), (0, 0));
        assert_eq!(fixed_point_words(f32::NAN, 1.0), (0, 0));
    }
}
