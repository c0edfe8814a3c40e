//! The directional albedo of single-scattering GGX reflection, tabulated for the glTF PBR
//! material's energy compensation (`src/cpu/materials/pbr.rs`, `shaders/materials/pbr.wgsl`).
//!
//! Schlick's Fresnel f0 + (f90 − f0)(1 − cos θh)⁵ is linear in f0 and f90, so the albedo of a
//! GGX lobe with it is f0·A(μ, α) + f90·B(μ, α) (the "split sum"), A and B being the albedos
//! with the weights 1 − (1 − cos θh)⁵ and (1 − cos θh)⁵; with F = 1 it is E = A + B. The
//! tables hold A and B on a grid of μ = cos θo and roughness √α, and their hemispherical
//! averages 2∫A(μ)μ dμ, 2∫B(μ)μ dμ of the same bilinear interpolant the kernel reads, so that
//! the energy-compensated lobes conserve energy to the tables' own accuracy.
//!
//! A third part holds the averages of products of two rows, 2∫X(μ, α1) Y(μ, α2) μ dμ for X, Y
//! in {A, B}: a clear coat (`src/cpu/materials/clearcoat.rs`) and a layer below it each scale what
//! passes them by a factor that is linear in A and B, and the average of the factors' product
//! normalises both together (they rise towards grazing angles together, so the product of
//! their averages is too small).
//!
//! The α axis is spaced evenly in roughness, not in α: the albedo changes fastest at small α
//! (a smooth lobe's grazing shadowing), where rows evenly spaced in α put nothing between
//! α = 0.001 and 0.032, and reading a roughness-0.1 coat between them was off by 2% of its
//! albedo at cos θ 0.05 (tests/suite/pbr.rs's table test).
//!
//! They are computed here, at first use, by integrating with the kernel's own sampler (the
//! distribution of visible normals) on a stratified grid in f64: deterministic, about 0.15 s,
//! and never hand-typed. The same numbers feed the GPU (binding 25) and the CPU reference.

use std::sync::OnceLock;

/// Grid points per axis: μ at (i + ½)/N, roughness √α at j/(N − 1).
pub const GGX_ENERGY_SIZE: usize = 32;
/// The smallest α the tables are integrated at (the PBR material's own minimum).
pub const GGX_ENERGY_MIN_ALPHA: f64 = 1e-3;
/// Strata of the integration grid at each table point: radial (the visible normal's
/// distance from the lobe's centre) and azimuthal.
const RADIAL_STRATA: usize = 128;
const AZIMUTHAL_STRATA: usize = 32;

/// Offsets of the parts of the table: A and B (N × N, α-major), their averages (N), and the
/// averages of the products A·A, A·B, B·B of rows j1 and j2 (N × N, at j1 · N + j2; B·A is
/// A·B with the rows swapped).
pub const OFFSET_A: usize = 0;
pub const OFFSET_B: usize = GGX_ENERGY_SIZE * GGX_ENERGY_SIZE;
pub const OFFSET_A_AVERAGE: usize = 2 * GGX_ENERGY_SIZE * GGX_ENERGY_SIZE;
pub const OFFSET_B_AVERAGE: usize = OFFSET_A_AVERAGE + GGX_ENERGY_SIZE;
pub const OFFSET_AA_AVERAGE: usize = OFFSET_B_AVERAGE + GGX_ENERGY_SIZE;
pub const OFFSET_AB_AVERAGE: usize = OFFSET_AA_AVERAGE + GGX_ENERGY_SIZE * GGX_ENERGY_SIZE;
pub const OFFSET_BB_AVERAGE: usize = OFFSET_AB_AVERAGE + GGX_ENERGY_SIZE * GGX_ENERGY_SIZE;
pub const GGX_ENERGY_LEN: usize = OFFSET_BB_AVERAGE + GGX_ENERGY_SIZE * GGX_ENERGY_SIZE;

/// The table, computed once per process.
pub fn ggx_energy_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(compute_table)
}

/// μ of grid column i and α of grid row j.
pub fn grid_mu(i: usize) -> f64 {
    (i as f64 + 0.5) / GGX_ENERGY_SIZE as f64
}

pub fn grid_alpha(j: usize) -> f64 {
    let roughness = j as f64 / (GGX_ENERGY_SIZE - 1) as f64;
    (roughness * roughness).max(GGX_ENERGY_MIN_ALPHA)
}

fn compute_table() -> Vec<f32> {
    let n = GGX_ENERGY_SIZE;
    let mut table = vec![0.0f32; GGX_ENERGY_LEN];
    let mut a = vec![0.0f64; n * n];
    let mut b = vec![0.0f64; n * n];
    for j in 0..n {
        for i in 0..n {
            let (ai, bi) = albedo_split(grid_mu(i), grid_alpha(j));
            a[j * n + i] = ai;
            b[j * n + i] = bi;
        }
    }
    let row = |t: &[f64], j: usize| t[j * n..(j + 1) * n].to_vec();
    let one = vec![1.0; n];
    for j in 0..n {
        table[OFFSET_A_AVERAGE + j] = hemispherical_average(&row(&a, j), &one) as f32;
        table[OFFSET_B_AVERAGE + j] = hemispherical_average(&row(&b, j), &one) as f32;
        for k in 0..n {
            let at = j * n + k;
            table[OFFSET_AA_AVERAGE + at] = hemispherical_average(&row(&a, j), &row(&a, k)) as f32;
            table[OFFSET_AB_AVERAGE + at] = hemispherical_average(&row(&a, j), &row(&b, k)) as f32;
            table[OFFSET_BB_AVERAGE + at] = hemispherical_average(&row(&b, j), &row(&b, k)) as f32;
        }
    }
    for k in 0..n * n {
        table[OFFSET_A + k] = a[k] as f32;
        table[OFFSET_B + k] = b[k] as f32;
    }
    table
}

/// Where `mu` falls on a row of `n` values at the grid's μ, as the kernel reads it: the point
/// below and the weight of the one above (constant beyond the first and the last point).
pub(crate) fn row_position(n: usize, mu: f64) -> (usize, f64) {
    let x = (mu * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
    let i = (x.floor() as usize).min(n - 2);
    (i, x - i as f64)
}

/// A row of values at the grid's μ read at `mu`, linear between its points ([`row_position`]).
pub(crate) fn interpolate_row(row: &[f64], mu: f64) -> f64 {
    let (i, t) = row_position(row.len(), mu);
    row[i] * (1.0 - t) + row[i + 1] * t
}

/// 2∫f(μ)g(μ)μ dμ of the piecewise-linear interpolants of two rows (values at the grid's μ,
/// constant beyond its first and last points), as the kernel interpolates them. Between
/// neighbouring grid points (and beyond the ends) the integrand is a cubic in μ, which
/// Simpson's rule integrates exactly.
fn hemispherical_average(f: &[f64], g: &[f64]) -> f64 {
    let n = f.len();
    let integrand = |mu: f64| 2.0 * interpolate_row(f, mu) * interpolate_row(g, mu) * mu;
    let mut breaks = vec![0.0];
    breaks.extend((0..n).map(grid_mu));
    breaks.push(1.0);
    breaks
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            (b - a) / 6.0 * (integrand(a) + 4.0 * integrand(0.5 * (a + b)) + integrand(b))
        })
        .sum()
}

/// (A, B) at cos θo = μ and α: the albedo of GGX reflection with the Fresnel weights
/// 1 − (1 − cos θh)⁵ and (1 − cos θh)⁵, by sampling visible normals: each sample's weight is
/// G2/G1 where the reflected direction is above the surface. At the table's resolution.
pub fn albedo_split(mu: f64, alpha: f64) -> (f64, f64) {
    albedo_split_at_resolution(mu, alpha, RADIAL_STRATA, AZIMUTHAL_STRATA)
}

/// [`albedo_split`] on a grid of `radial` × `azimuthal` strata (tests integrate finer).
///
/// The radial coordinate u of the sampler is stratified through u = 1 − (1 − v)³, v evenly
/// spaced, weighted by du/dv = 3(1 − v)²: the lobe's tail (u near 1) gets fine strata. With u
/// itself evenly spaced, the last stratum stands for the outermost 1/64 of the visible normals
/// at one point, and as α grew that point's reflection crossed the horizon all at once: steps
/// of 1.6% in the albedo head-on near roughness 0.3 (0.66% off at roughness 0.3, measured
/// against 2048 × 512 strata; now within 0.01%).
pub fn albedo_split_at_resolution(
    mu: f64,
    alpha: f64,
    radial: usize,
    azimuthal: usize,
) -> (f64, f64) {
    let (mut a, mut b) = (0.0, 0.0);
    for_each_reflection(mu, alpha, radial, azimuthal, |_, s5, weight| {
        a += weight * (1.0 - s5);
        b += weight * s5;
    });
    let count = (radial * azimuthal) as f64;
    (a / count, b / count)
}

/// GGX reflection of roughness α from cos θo = μ (wo in the xz plane), one reflection per
/// stratum of the sampler of visible normals (stratified as [`albedo_split_at_resolution`]
/// says): `reflection(wi, s5, weight)` for each wi above the surface, with s5 = (1 − cos θh)⁵
/// and weight = du/dv · G2/G1, whose sum divided by radial × azimuthal is the albedo with
/// F = 1. The coat's table (`crate::tables::clearcoat`) gathers the same reflections by wi.
pub(crate) fn for_each_reflection(
    mu: f64,
    alpha: f64,
    radial: usize,
    azimuthal: usize,
    mut reflection: impl FnMut([f64; 3], f64, f64),
) {
    let wo = [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu];
    let lambda_o = lambda(wo, alpha);
    for sr in 0..radial {
        let v = (sr as f64 + 0.5) / radial as f64;
        let u_radial = 1.0 - (1.0 - v).powi(3);
        let jacobian = 3.0 * (1.0 - v).powi(2);
        for sa in 0..azimuthal {
            let u_azimuthal = (sa as f64 + 0.5) / azimuthal as f64;
            let h = visible_normal(wo, alpha, (u_radial, u_azimuthal));
            let c = dot(wo, h);
            let wi = [
                2.0 * c * h[0] - wo[0],
                2.0 * c * h[1] - wo[1],
                2.0 * c * h[2] - wo[2],
            ];
            if wi[2] <= 0.0 {
                continue;
            }
            let weight = jacobian * (1.0 + lambda_o) / (1.0 + lambda_o + lambda(wi, alpha));
            let s5 = (1.0 - c).clamp(0.0, 1.0).powi(5);
            reflection(wi, s5, weight);
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = dot(v, v).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// Smith's Λ for GGX.
fn lambda(w: [f64; 3], alpha: f64) -> f64 {
    let x = alpha * alpha * (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2]).max(1e-300);
    x / (2.0 * (1.0 + (1.0 + x).sqrt()))
}

/// Heitz's sampling of visible normals (JCGT 2018), as in `src/cpu/materials/microfacet.rs`.
fn visible_normal(wo: [f64; 3], alpha: f64, u: (f64, f64)) -> [f64; 3] {
    let vh = normalize([alpha * wo[0], alpha * wo[1], wo[2]]);
    let len2 = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if len2 > 0.0 {
        let l = len2.sqrt();
        [-vh[1] / l, vh[0] / l, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t2 = [
        vh[1] * t1[2] - vh[2] * t1[1],
        vh[2] * t1[0] - vh[0] * t1[2],
        vh[0] * t1[1] - vh[1] * t1[0],
    ];
    let r = u.0.sqrt();
    let phi = 2.0 * std::f64::consts::PI * u.1;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh[2]);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * (r * phi.sin());
    let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh = [
        p1 * t1[0] + p2 * t2[0] + p3 * vh[0],
        p1 * t1[1] + p2 * t2[1] + p3 * vh[1],
        p1 * t1[2] + p2 * t2[2] + p3 * vh[2],
    ];
    normalize([alpha * nh[0], alpha * nh[1], nh[2].max(0.0)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// E(μ, α) = ∫ D G2 / (4 μo) dωi over the upper hemisphere (F = 1), by a midpoint rule in
    /// (cos θi, φi), from the textbook formulas: independent of the sampler the table uses.
    fn albedo_by_quadrature(mu: f64, alpha: f64) -> f64 {
        let wo = [(1.0 - mu * mu).sqrt(), 0.0, mu];
        let (nc, np) = (800, 400);
        let mut sum = 0.0;
        for a in 0..nc {
            let cos_i = (a as f64 + 0.5) / nc as f64;
            let sin_i = (1.0 - cos_i * cos_i).sqrt();
            for b in 0..np {
                let phi = 2.0 * PI * (b as f64 + 0.5) / np as f64;
                let wi = [sin_i * phi.cos(), sin_i * phi.sin(), cos_i];
                let h = normalize([wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]]);
                let a2 = alpha * alpha;
                let d = a2 / (PI * (h[2] * h[2] * (a2 - 1.0) + 1.0).powi(2));
                let g2 = 1.0 / (1.0 + lambda(wo, alpha) + lambda(wi, alpha));
                sum += d * g2 / (4.0 * mu);
            }
        }
        sum * (1.0 / nc as f64) * (2.0 * PI / np as f64)
    }

    #[test]
    fn the_table_matches_an_independent_quadrature() {
        let table = ggx_energy_table();
        let n = GGX_ENERGY_SIZE;
        for (i, j) in [(0, 31), (5, 10), (16, 16), (31, 31), (20, 5), (2, 25)] {
            let table_e = (table[OFFSET_A + j * n + i] + table[OFFSET_B + j * n + i]) as f64;
            let exact = albedo_by_quadrature(grid_mu(i), grid_alpha(j));
            assert!(
                (table_e - exact).abs() < 2e-3,
                "μ {} α {}: table {table_e}, quadrature {exact}",
                grid_mu(i),
                grid_alpha(j)
            );
        }
        // With F = 1 nothing is created: every albedo is at most 1, and a smooth lobe keeps
        // everything head-on.
        assert!(table[..OFFSET_A_AVERAGE]
            .iter()
            .all(|v| (0.0..=1.0 + 1e-6).contains(v)));
        let smooth_head_on = table[OFFSET_A + n - 1] + table[OFFSET_B + n - 1];
        assert!((smooth_head_on - 1.0).abs() < 1e-3, "{smooth_head_on}");
    }
}
