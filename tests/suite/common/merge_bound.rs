//! How far two accumulations of the same samples may differ: float rounding only.

use glint::render::accumulation::Accumulation;

/// The largest |a − b| over every pixel channel of two accumulations of the same samples
/// (merged shards against a single render, or a resumed render against an uninterrupted one),
/// as a fraction of the bound they must stay under, so ≤ 1 passes.
///
/// Why this bound: both are f32 evaluations of the exact mean μ of the same n sample values
/// per pixel (same seed and device, so the same values), differing only in how Welford steps
/// and pairwise merges group them. Each of those at most 2n operations computes m' = m + δ·w
/// (w ≤ 1) with a rounding error ≤ u·(|m'| + 3|δ|), u = 2⁻²⁴, and every error reaches the
/// result scaled by at most 1. A merge of blocks of n_a and n_b samples has δ²·n_a·n_b/n ≤ M2,
/// so |δ| ≤ √(2·M2), and every running mean lies within that of μ. So each is within
/// 2n·u·(|μ| + 4√(2·M2)) of μ, and the two within twice that. A sharding bug (a shard drawing
/// another shard's samples, a wrong weight) moves a pixel by about its standard error
/// √(2·M2)/n: thousands of times the bound at the sample counts of these tests.
pub fn worst_vs_bound(a: &Accumulation, b: &Accumulation) -> f64 {
    assert_eq!(a.count, b.count, "not the same number of samples");
    let n = b.count as f64;
    let u = f32::EPSILON as f64 / 2.0;
    let mut worst: f64 = 0.0;
    for i in 0..b.mean.len() {
        for c in 0..3 {
            let mu = b.mean[i][c] as f64;
            let m2 = b.m2[i][c].max(0.0) as f64;
            let bound = 4.0 * n * u * (mu.abs() + 4.0 * (2.0 * m2).sqrt()) + 1e-30;
            worst = worst.max((a.mean[i][c] as f64 - mu).abs() / bound);
        }
    }
    worst
}
