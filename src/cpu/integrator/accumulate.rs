//! Per-pixel statistics (WGSL side: `shaders/integrator/accumulate.wgsl`): each sample is checked, then
//! added to a running mean and M2 (the sum of squared deviations from the mean) on a fixed
//! schedule.
//!
//! Samples are grouped into blocks by their global index: a block ends after sample counts 1,
//! 2, 4, …, [`MERGE_BLOCK`], and then after every multiple of it. Within a block the samples
//! are added by Welford's update; at the block's end the block is merged into the totals by
//! Chan, Golub and LeVeque's pairwise update, which keeps the mean accurate in f32 at millions
//! of samples. Since batches are split only at block ends (`kernel::schedule`), the floats
//! depend on the sample indices alone: any batching gives the same bytes.

use crate::cpu::integrator::path::PixelStats;
use crate::kernel::schedule::is_block_end;
use glam::Vec3;

/// Largest sample value (per channel) taken. With at most 2³⁰ samples, M2 stays below
/// 2³⁰ · (2·10¹⁴)² < 4.3·10³⁷, so it cannot overflow f32.
pub const MAX_SAMPLE: f32 = 1e14;
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Accumulator {
    /// Totals over the merged blocks.
    pub count: u32,
    pub mean: Vec3,
    pub m2: Vec3,
    /// The block in progress.
    pub block_count: u32,
    pub block_mean: Vec3,
    pub block_m2: Vec3,
    /// Samples dropped since the accumulator started.
    pub nonfinite: u32,
}

/// Whether adaptive sampling has stopped the pixel (the kernel reads a flag the host sets in
/// the pixel's M2; here it is [`PixelStats::stopped`]).
pub fn pixel_stopped(stats: &PixelStats) -> bool {
    stats.stopped
}

pub fn accumulator_start(count: u32, mean: Vec3, m2: Vec3) -> Accumulator {
    Accumulator {
        count,
        mean,
        m2,
        ..Default::default()
    }
}

/// Whether every channel is finite and at most [`MAX_SAMPLE`] in magnitude (compared as bit
/// patterns, as the kernel does).
pub fn is_accepted_sample(x: Vec3) -> bool {
    let max = MAX_SAMPLE.to_bits();
    x.to_array()
        .iter()
        .all(|c| c.to_bits() & 0x7fff_ffff <= max)
}

/// Adds the radiance of the sample with global index `sample`; a rejected one counts as black
/// (and in `nonfinite`), so nothing non-finite ever reaches the accumulators.
pub fn add_sample(acc: &mut Accumulator, radiance: Vec3, sample: u32) {
    let mut x = radiance;
    if !is_accepted_sample(x) {
        x = Vec3::ZERO;
        acc.nonfinite += 1;
    }
    acc.block_count += 1;
    let delta = x - acc.block_mean;
    acc.block_mean += delta / acc.block_count as f32;
    acc.block_m2 += delta * (x - acc.block_mean);
    if is_block_end(sample + 1) {
        merge_block(acc);
    }
}

/// Merges the block in progress into the totals (Chan, Golub and LeVeque's pairwise update).
pub fn merge_block(acc: &mut Accumulator) {
    if acc.block_count == 0 {
        return;
    }
    let n_old = acc.count as f32;
    let n_new = acc.block_count as f32;
    let n = n_old + n_new;
    let delta = acc.block_mean - acc.mean;
    acc.mean += delta * (n_new / n);
    acc.m2 = acc.m2 + acc.block_m2 + delta * delta * (n_old * n_new / n);
    acc.count += acc.block_count;
    acc.block_count = 0;
    acc.block_mean = Vec3::ZERO;
    acc.block_m2 = Vec3::ZERO;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::schedule::{next_block_end, MERGE_BLOCK};

    #[test]
    fn the_kernel_bound_is_the_bit_pattern_of_max_sample() {
        let wgsl = include_str!("../../../shaders/integrator/accumulate.wgsl");
        let bits = format!("const MAX_SAMPLE_BITS: u32 = {:#x}u;", MAX_SAMPLE.to_bits());
        assert!(wgsl.contains(&bits), "{bits}");
        assert!(wgsl.contains(&format!("const MERGE_BLOCK: u32 = {MERGE_BLOCK}u;")));
    }

    #[test]
    fn blocks_end_at_powers_of_two_then_multiples_of_the_block() {
        let ends: Vec<u32> = (1..=200).filter(|&n| is_block_end(n)).collect();
        assert_eq!(ends, [1, 2, 4, 8, 16, 32, 64, 128, 192]);
        assert_eq!(next_block_end(0, 1, 100), 1);
        assert_eq!(next_block_end(4, 1, 100), 8);
        assert_eq!(next_block_end(64, 10, 1000), 128);
        assert_eq!(next_block_end(64, 10, 70), 70);
    }

    #[test]
    fn non_finite_and_huge_samples_are_dropped_and_counted() {
        let mut acc = Accumulator::default();
        for (i, x) in [1.0, f32::NAN, f32::INFINITY, -2e14, 1e14, 3.0]
            .into_iter()
            .enumerate()
        {
            add_sample(&mut acc, Vec3::splat(x), i as u32);
        }
        merge_block(&mut acc);
        assert_eq!(acc.nonfinite, 3);
        assert_eq!(acc.count, 6);
        assert!(acc.mean.is_finite() && acc.m2.is_finite());
    }
}
