//! The clear coat's scaling of the specular lobes below it, tabulated (`src/cpu/materials/clearcoat.rs`,
//! `shaders/materials/clearcoat.wgsl`, which read it from binding 36).
//!
//! A coat of weight c reflects c L(μ) of the light (L its whole directional albedo, from the
//! GGX tables of `crate::tables::ggx`), so a specular lobe below it may keep 1 − c L(μo) of
//! its energy, and its scaling must be symmetric in wo and wi to keep the BRDF reciprocal.
//! 1 − c max(L(μo), L(μi)) is symmetric and exact for a mirror, but a glossy lobe spreads wi
//! over angles where L is larger than at μo (towards grazing, where a smooth coat's L climbs
//! from 0.04 to 1), and lost up to 4.3% of white metal's energy under a smooth coat
//! (tests/suite/pbr.rs's coat furnace). So the lobe is scaled by
//!
//! 1 − c · min(1, max(L(μo), L(μi)) · h(μo) h(μi)),
//!
//! with h(μ, α_base, α_coat) chosen so that, for GGX reflection of roughness α_base with
//! F = 1, the average of that min over the lobe is exactly L(μo): then the lobe keeps
//! 1 − c L(μo) of its energy at every μo, for every c. That is a symmetric matrix scaling
//! problem (a Sinkhorn–Knopp iteration), solved here per pair of roughnesses; h does not
//! depend on c, so one table serves every coat weight. The clamp to 1 (no lobe is scaled
//! below 0) is part of the problem solved, not applied after: a smooth coat's L is near 1 at
//! grazing μo, where h must exceed 1 to make up for the smaller h of the directions the lobe
//! spreads to, and unclamped products reached 1.7.
//!
//! The lobe's Schlick Fresnel f0 (1 − s⁵) + f90 s⁵ (s = 1 − cos θh) has two parts that spread
//! differently (the f90 part goes towards grazing angles), so each has its own h, solved for
//! GGX reflection weighted by 1 − s⁵ and by s⁵: one h for the whole lobe, from F = 1, kept
//! white metal to 0.3% but lost 1.9% over a white dielectric base at cos θo 0.05.
//!
//! Computed at first use: the lobe's transfer from each grid μo to 64 bins of μi by the GGX
//! tables' own stratified sampler of visible normals, then the fixed point
//! h(μo) ← h(μo) √(L(μo) E(μo) / Σ_k W(μo, k) min(1, max(L(μo), L(μk)) h(μo) h(μk))) (E the
//! part's albedo), in f64:
//! deterministic, never hand-typed, a fraction of a second. The same numbers feed the GPU
//! and the CPU reference.

use crate::tables::ggx::{
    for_each_reflection, ggx_energy_table, grid_alpha, grid_mu, interpolate_row, row_position,
    GGX_ENERGY_SIZE, OFFSET_A, OFFSET_A_AVERAGE, OFFSET_B, OFFSET_B_AVERAGE,
};
use crate::tables::threads::rows_in_parallel;
use std::sync::OnceLock;

/// The coat's Fresnel at normal incidence (ior 1.5), which `src/cpu/materials/clearcoat.rs` uses too.
pub const CLEARCOAT_F0: f32 = 0.04;
const COAT_F0: f64 = CLEARCOAT_F0 as f64;
/// Bins of μi the base lobe's transfer is gathered into (each keeps its weighted mean μi).
const MU_BINS: usize = 64;
/// Strata of the base lobe's sampler at each grid μo: radial and azimuthal.
const RADIAL_STRATA: usize = 64;
const AZIMUTHAL_STRATA: usize = 32;
/// The fixed point stops when every grid μo keeps its share to within this (the table's test
/// checks 10⁻⁴ after rounding to f32), or after so many iterations.
const TOLERANCE: f64 = 1e-5;
const MAX_ITERATIONS: usize = 20_000;

/// Grid points per axis: μ, base roughness √α_base and coat roughness √α_coat, on the GGX
/// tables' grid.
pub const CLEARCOAT_ENERGY_SIZE: usize = GGX_ENERGY_SIZE;
/// Values per part: h at (μ index i, base row jb, coat row jc) is at (jc · N + jb) · N + i.
pub const CLEARCOAT_ENERGY_PART: usize =
    CLEARCOAT_ENERGY_SIZE * CLEARCOAT_ENERGY_SIZE * CLEARCOAT_ENERGY_SIZE;
/// Two parts: h_A for the part of a Schlick-Fresnel lobe weighted by 1 − (1 − cos θh)⁵ (the
/// A of the split sum), then h_B for the part weighted by (1 − cos θh)⁵.
pub const CLEARCOAT_ENERGY_LEN: usize = 2 * CLEARCOAT_ENERGY_PART;

/// The table of h, computed once per process.
pub fn clearcoat_energy_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(compute_table)
}

/// One part of the base lobe's transfer at one roughness: for each grid μo, the weight that
/// lands in each bin of μi, and the weighted mean μi there.
struct Transfer {
    weight: Vec<f64>,
    mean_mu: Vec<f64>,
}

fn compute_table() -> Vec<f32> {
    let n = CLEARCOAT_ENERGY_SIZE;
    let coat_albedos: Vec<Vec<f64>> = (0..n).map(coat_albedo_row).collect();
    // Per base row: h for each part and coat row, (part, jc, i).
    let base_row = |jb: usize| {
        let mut rows = vec![0.0; 2 * n * n];
        for (part, transfer) in base_transfer(grid_alpha(jb)).iter().enumerate() {
            // From the roughest coat to the smoothest, each starting from the solution of the
            // one before (the smooth coats' fixed points are the slow ones).
            let mut h = vec![1.0; n];
            for jc in (0..n).rev() {
                h = narrow_scale(transfer, &coat_albedos[jc], h);
                rows[(part * n + jc) * n..][..n].copy_from_slice(&h);
            }
        }
        rows
    };
    let per_base = rows_in_parallel(n, base_row);
    let mut table = vec![0.0f32; CLEARCOAT_ENERGY_LEN];
    for (jb, rows) in per_base.iter().enumerate() {
        for part in 0..2 {
            for jc in 0..n {
                for i in 0..n {
                    table[part * CLEARCOAT_ENERGY_PART + (jc * n + jb) * n + i] =
                        rows[(part * n + jc) * n + i] as f32;
                }
            }
        }
    }
    table
}

/// The coat's whole albedo L = f0 A + B + F_ms (1 − E) at the grid's μ for coat row jc, from
/// the f32 GGX tables as the kernel reads them.
fn coat_albedo_row(jc: usize) -> Vec<f64> {
    let table = ggx_energy_table();
    let n = GGX_ENERGY_SIZE;
    let e_average = (table[OFFSET_A_AVERAGE + jc] + table[OFFSET_B_AVERAGE + jc]) as f64;
    let f_average = COAT_F0 + (1.0 - COAT_F0) / 21.0;
    let ms = f_average * f_average * e_average / (1.0 - f_average * (1.0 - e_average));
    (0..n)
        .map(|i| {
            let a = table[OFFSET_A + jc * n + i] as f64;
            let b = table[OFFSET_B + jc * n + i] as f64;
            COAT_F0 * a + b + ms * (1.0 - a - b)
        })
        .collect()
}

/// The two parts of GGX reflection of roughness α from each grid μo, with the weights
/// 1 − (1 − cos θh)⁵ and (1 − cos θh)⁵, gathered by μi: the reflections the GGX tables sum
/// (`crate::tables::ggx::for_each_reflection`).
fn base_transfer(alpha: f64) -> [Transfer; 2] {
    let n = CLEARCOAT_ENERGY_SIZE;
    let mut parts = [0, 1].map(|_| Transfer {
        weight: vec![0.0; n * MU_BINS],
        mean_mu: vec![0.0; n * MU_BINS],
    });
    let count = (RADIAL_STRATA * AZIMUTHAL_STRATA) as f64;
    for i in 0..n {
        let reflect = |wi: [f64; 3], s5: f64, weight: f64| {
            let at = i * MU_BINS + ((wi[2] * MU_BINS as f64) as usize).min(MU_BINS - 1);
            for (part, share) in parts.iter_mut().zip([1.0 - s5, s5]) {
                part.weight[at] += weight / count * share;
                part.mean_mu[at] += weight / count * share * wi[2];
            }
        };
        for_each_reflection(grid_mu(i), alpha, RADIAL_STRATA, AZIMUTHAL_STRATA, reflect);
    }
    for part in &mut parts {
        for (m, w) in part.mean_mu.iter_mut().zip(&part.weight) {
            if *w > 0.0 {
                *m /= w;
            }
        }
    }
    parts
}

/// h at the grid's μ for one part of a base transfer and one coat albedo row: the fixed point of the
/// symmetric scaling (module comment).
fn narrow_scale(transfer: &Transfer, coat_albedo: &[f64], start: Vec<f64>) -> Vec<f64> {
    let n = CLEARCOAT_ENERGY_SIZE;
    // The bins each grid μo reaches: the weight, max(L(μo), L(μi)), and where the mean μi
    // falls between the grid's μ (as `interpolate_row` reads h there); and the target L(μo) E(μo).
    struct Reached {
        weight: f64,
        larger: f64,
        below: usize,
        t: f64,
    }
    let mut reached: Vec<Vec<Reached>> = Vec::with_capacity(n);
    let mut target = vec![0.0; n];
    for i in 0..n {
        let l_o = coat_albedo[i];
        let mut bins = Vec::new();
        for k in 0..MU_BINS {
            let at = i * MU_BINS + k;
            let (weight, mu) = (transfer.weight[at], transfer.mean_mu[at]);
            if weight <= 0.0 {
                continue;
            }
            let (below, t) = row_position(n, mu);
            bins.push(Reached {
                weight,
                larger: l_o.max(interpolate_row(coat_albedo, mu)),
                below,
                t,
            });
            target[i] += weight * l_o;
        }
        reached.push(bins);
    }
    let kept = |h: &[f64], i: usize| -> f64 {
        reached[i]
            .iter()
            .map(|r| {
                let h_i = h[r.below] * (1.0 - r.t) + h[r.below + 1] * r.t;
                r.weight * (r.larger * h[i] * h_i).min(1.0)
            })
            .sum()
    };
    // Gauss–Seidel: each h(μo) is updated in place, the later ones seeing it.
    let mut h = start;
    for _ in 0..MAX_ITERATIONS {
        let mut worst = 0.0f64;
        for i in 0..n {
            let sum = kept(&h, i);
            if sum > 0.0 && target[i] > 0.0 {
                let ratio = target[i] / sum;
                worst = worst.max((ratio - 1.0).abs());
                h[i] *= ratio.sqrt();
            }
        }
        if worst < TOLERANCE {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At every grid μo (for a spread of both roughnesses), the lobe's average of
    /// min(1, max(L(μo), L(μi)) h(μo) h(μi)), as the kernel reads h, is L(μo) to 10⁻⁴: the
    /// fixed point is reached, the clamp included. It fails if the iteration stops early or
    /// the table is laid out other than the kernel reads it.
    #[test]
    fn the_scaling_keeps_the_coats_share_at_every_grid_point() {
        let n = CLEARCOAT_ENERGY_SIZE;
        let table = clearcoat_energy_table();
        let mut worst = 0.0f64;
        for jb in [0, 5, 10, 16, 24, 31] {
            for (part, transfer) in base_transfer(grid_alpha(jb)).iter().enumerate() {
                for jc in [0, 3, 10, 20, 31] {
                    let l = coat_albedo_row(jc);
                    let h: Vec<f64> = (0..n)
                        .map(|i| table[part * CLEARCOAT_ENERGY_PART + (jc * n + jb) * n + i] as f64)
                        .collect();
                    for i in 0..n {
                        let (mut kept, mut e) = (0.0, 0.0);
                        for k in 0..MU_BINS {
                            let at = i * MU_BINS + k;
                            let mu_i = transfer.mean_mu[at];
                            let scaled = l[i].max(interpolate_row(&l, mu_i))
                                * h[i]
                                * interpolate_row(&h, mu_i);
                            kept += transfer.weight[at] * scaled.min(1.0);
                            e += transfer.weight[at];
                        }
                        // Where the lobe has next to no energy left (grazing, rough) nothing is
                        // kept or lost.
                        if e > 1e-3 {
                            worst = worst.max((kept / (e * l[i]) - 1.0).abs());
                        }
                    }
                }
            }
        }
        assert!(worst < 1e-4, "worst relative error {worst}");
    }
}
