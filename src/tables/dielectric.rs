//! The directional albedo of the single-scattering rough dielectric (Walter et al. 2007, the
//! lobe of `src/cpu/materials/rough_dielectric.rs`), tabulated for its energy compensation (Kulla and
//! Conty 2017).
//!
//! E(μ, α, etap) is the share of the energy arriving at cos θo = μ that the lobe reflects or
//! refracts in one scattering event (refraction's radiance scaling taken out), on a grid of
//! μ, α and the index ratio. The index axis runs over r = (η − 1)/(η + 1) for η ≥ 1, with η
//! the larger of etap and 1/etap, in two halves: light entering the denser medium (etap ≥ 1)
//! and light leaving it (etap < 1, where total internal reflection sends energy back). r
//! spans [0, (MAX_IOR − 1)/(MAX_IOR + 1)], every index glint accepts (and ior < 1 too, which
//! is just the other half). Next to E: its hemispherical averages E_avg = 2∫E μ dμ of the
//! same interpolant the kernel reads (so the compensation lobe's albedo is exactly 1 − E),
//! and per η the smooth interface's average transmittance 1 − F_avg from the rarer side,
//! which decides how the compensation lobe splits between reflection and refraction.
//!
//! Computed here at first use by integrating with the lobe's own sampler (visible normals,
//! both the reflected and the refracted branch weighted by Fresnel) on a stratified grid:
//! deterministic (the parallel rows are gathered in order), about 0.8 s of CPU time split over
//! the cores. The same numbers feed the GPU (binding 33) and the CPU reference.

use crate::cpu::materials::dielectric::fresnel_dielectric;
use crate::cpu::materials::rough_dielectric_single::single_scattering_albedo_sample;
use crate::scene::limits::MAX_IOR;
use crate::tables::threads::rows_in_parallel;
use glam::Vec3;
use std::sync::OnceLock;

/// Grid points along μ (at (i + ½)/N), α (at j/(N − 1)) and r (at k/(N − 1) · R_MAX).
pub const DIELECTRIC_ENERGY_MU: usize = 32;
pub const DIELECTRIC_ENERGY_ALPHA: usize = 16;
pub const DIELECTRIC_ENERGY_ETA: usize = 24;
/// The smallest α the table is integrated at (the PBR material's own minimum).
pub const DIELECTRIC_ENERGY_MIN_ALPHA: f32 = 1e-3;
/// Strata per axis of the integration grid at each table point.
const STRATA: usize = 20;

/// Sizes of the parts: E over (side, r, α, μ), E_avg over (side, r, α), 1 − F_avg over r.
const ALBEDO_LEN: usize =
    2 * DIELECTRIC_ENERGY_ETA * DIELECTRIC_ENERGY_ALPHA * DIELECTRIC_ENERGY_MU;
const AVERAGE_LEN: usize = 2 * DIELECTRIC_ENERGY_ETA * DIELECTRIC_ENERGY_ALPHA;
pub const OFFSET_ALBEDO: usize = 0;
pub const OFFSET_AVERAGE: usize = ALBEDO_LEN;
pub const OFFSET_TRANSMITTANCE: usize = ALBEDO_LEN + AVERAGE_LEN;
pub const DIELECTRIC_ENERGY_LEN: usize = OFFSET_TRANSMITTANCE + DIELECTRIC_ENERGY_ETA;

/// r of the largest index glint accepts; the last grid point of the index axis.
pub fn max_reflectance_root() -> f32 {
    (MAX_IOR - 1.0) / (MAX_IOR + 1.0)
}

/// The table, computed once per process.
pub fn dielectric_energy_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(compute_table)
}

pub fn grid_mu(i: usize) -> f32 {
    (i as f32 + 0.5) / DIELECTRIC_ENERGY_MU as f32
}

pub fn grid_alpha(j: usize) -> f32 {
    (j as f32 / (DIELECTRIC_ENERGY_ALPHA - 1) as f32).max(DIELECTRIC_ENERGY_MIN_ALPHA)
}

/// η ≥ 1 of index grid point k.
pub fn grid_eta(k: usize) -> f32 {
    let r = k as f32 / (DIELECTRIC_ENERGY_ETA - 1) as f32 * max_reflectance_root();
    (1.0 + r) / (1.0 - r)
}

fn compute_table() -> Vec<f32> {
    let (nm, na, ne) = (
        DIELECTRIC_ENERGY_MU,
        DIELECTRIC_ENERGY_ALPHA,
        DIELECTRIC_ENERGY_ETA,
    );
    // One row of E over μ per (side, r, α), in table order.
    let rows: Vec<Vec<f64>> = rows_in_parallel(2 * ne * na, |row| {
        let (side, k, j) = (row / (ne * na), (row / na) % ne, row % na);
        let eta = grid_eta(k);
        let etap = if side == 0 { eta } else { 1.0 / eta };
        (0..nm)
            .map(|i| albedo(grid_mu(i), grid_alpha(j), etap))
            .collect()
    });
    let mut table = vec![0.0f32; DIELECTRIC_ENERGY_LEN];
    for (row, values) in rows.iter().enumerate() {
        for (i, v) in values.iter().enumerate() {
            table[OFFSET_ALBEDO + row * nm + i] = *v as f32;
        }
        table[OFFSET_AVERAGE + row] = hemispherical_average(values) as f32;
    }
    for k in 0..ne {
        table[OFFSET_TRANSMITTANCE + k] = 1.0 - fresnel_average(grid_eta(k)) as f32;
    }
    table
}

/// E at cos θo = μ, α and etap: the mean over a stratified grid of visible normals of the
/// lobe's expected energy weight (its reflection and refraction weighted by Fresnel).
pub fn albedo(mu: f32, alpha: f32, etap: f32) -> f64 {
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0f64;
    for sy in 0..STRATA {
        for sx in 0..STRATA {
            let u = (
                (sx as f32 + 0.5) / STRATA as f32,
                (sy as f32 + 0.5) / STRATA as f32,
            );
            sum += single_scattering_albedo_sample(alpha, etap, wo, u) as f64;
        }
    }
    sum / (STRATA * STRATA) as f64
}

/// 2∫f(μ)μ dμ of the piecewise-linear interpolant of `row` (values at the grid's μ, constant
/// beyond its first and last points), as the kernel interpolates it.
fn hemispherical_average(row: &[f64]) -> f64 {
    let steps = 4096;
    let n = row.len();
    (0..steps)
        .map(|k| {
            let mu = (k as f64 + 0.5) / steps as f64;
            let x = (mu * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
            let i = (x.floor() as usize).min(n - 2);
            let t = x - i as f64;
            2.0 * (row[i] * (1.0 - t) + row[i + 1] * t) * mu / steps as f64
        })
        .sum()
}

/// F_avg = 2∫F(μ)μ dμ of a smooth interface for light arriving from the rarer side (index
/// ratio η ≥ 1), by the midpoint rule.
fn fresnel_average(eta: f32) -> f64 {
    let steps = 4096;
    (0..steps)
        .map(|k| {
            let mu = (k as f64 + 0.5) / steps as f64;
            2.0 * fresnel_dielectric(mu as f32, 1.0 / eta) as f64 * mu / steps as f64
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// E by a midpoint rule over the sphere of wi, from Walter et al.'s formulas in f64 with
    /// the exact Fresnel term: independent of the sampler the table uses.
    fn albedo_by_quadrature(mu: f64, alpha: f64, etap: f64) -> f64 {
        let lambda = |z: f64| {
            let x = alpha * alpha * (1.0 - z * z) / (z * z);
            x / (2.0 * (1.0 + (1.0 + x).sqrt()))
        };
        let fresnel = |c: f64, eta: f64| {
            let s2 = eta * eta * (1.0 - c * c);
            if s2 >= 1.0 {
                return 1.0;
            }
            let t = (1.0 - s2).sqrt();
            let a = (c - eta * t) / (c + eta * t);
            let b = (eta * c - t) / (eta * c + t);
            0.5 * (a * a + b * b)
        };
        let wo = glam::DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let (nc, np) = (1600, 400);
        let mut sum = 0.0;
        for a in 0..nc {
            let z = -1.0 + 2.0 * (a as f64 + 0.5) / nc as f64;
            let s = (1.0 - z * z).sqrt();
            for b in 0..np {
                let phi = 2.0 * PI * (b as f64 + 0.5) / np as f64;
                let wi = glam::DVec3::new(s * phi.cos(), s * phi.sin(), z);
                let reflected = z > 0.0;
                let h = if reflected { wo + wi } else { wo + etap * wi };
                let mut m = h.normalize();
                if m.z < 0.0 {
                    m = -m;
                }
                if wo.dot(m) <= 0.0 || wi.dot(m) * z <= 0.0 {
                    continue;
                }
                let a2 = alpha * alpha;
                let d = a2 / (PI * (m.z * m.z * (a2 - 1.0) + 1.0).powi(2));
                let g2 = 1.0 / (1.0 + lambda(mu) + lambda(z.abs()));
                let f = fresnel(wo.dot(m), 1.0 / etap);
                let value = if reflected {
                    f * d * g2 / (4.0 * mu)
                } else {
                    let den = wi.dot(m) + wo.dot(m) / etap;
                    (1.0 - f) * d * g2 * (wi.dot(m) * wo.dot(m)).abs() / (mu * den * den)
                };
                sum += value;
            }
        }
        sum * (2.0 / nc as f64) * (2.0 * PI / np as f64)
    }

    /// The WGSL lookups spell the layout out as constants: they must be these.
    #[test]
    fn the_wgsl_lookups_use_this_layout() {
        let wgsl = include_str!("../../shaders/materials/dielectric_energy.wgsl");
        for line in [
            format!("DIELECTRIC_ENERGY_MU: u32 = {DIELECTRIC_ENERGY_MU}u;"),
            format!("DIELECTRIC_ENERGY_ALPHA: u32 = {DIELECTRIC_ENERGY_ALPHA}u;"),
            format!("DIELECTRIC_ENERGY_ETA: u32 = {DIELECTRIC_ENERGY_ETA}u;"),
            format!("DIELECTRIC_ENERGY_OFFSET_AVERAGE: u32 = {OFFSET_AVERAGE}u;"),
            format!("DIELECTRIC_ENERGY_OFFSET_TRANSMITTANCE: u32 = {OFFSET_TRANSMITTANCE}u;"),
            format!(
                "DIELECTRIC_ENERGY_MAX_R: f32 = {0:.1} / {1:.1};",
                MAX_IOR - 1.0,
                MAX_IOR + 1.0
            ),
        ] {
            assert!(
                wgsl.contains(&line),
                "shaders/materials/dielectric_energy.wgsl lacks {line:?}"
            );
        }
    }

    #[test]
    fn the_table_matches_an_independent_quadrature() {
        let t = dielectric_energy_table();
        for (mu, alpha, etap) in [
            (0.5f32, 0.5f32, 1.5f32),
            (0.9, 1.0, 1.5),
            (0.3, 1.0, 1.0 / 1.5),
            (0.8, 0.5, 1.0 / 1.5),
            (0.6, 0.75, 2.0),
        ] {
            let table = albedo(mu, alpha, etap);
            let exact = albedo_by_quadrature(mu as f64, alpha as f64, etap as f64);
            assert!(
                (table - exact).abs() < 3e-3,
                "μ {mu} α {alpha} etap {etap}: sampled {table}, quadrature {exact}"
            );
        }
        // Nothing is created, and the smooth interface keeps everything.
        assert!(t[..OFFSET_TRANSMITTANCE]
            .iter()
            .all(|v| (0.0..=1.0 + 1e-4).contains(v)));
        assert!((albedo(0.7, 1e-3, 1.5) - 1.0).abs() < 1e-3);
        // 1 − F_avg of glass (η 1.5) is about 0.908 (d'Eon's fit gives 0.909).
        let k = (1..DIELECTRIC_ENERGY_ETA)
            .find(|&k| grid_eta(k) > 1.4)
            .unwrap();
        let (index_matched, glass) = (t[OFFSET_TRANSMITTANCE], t[OFFSET_TRANSMITTANCE + k]);
        assert!(
            (index_matched - 1.0).abs() < 1e-6 && (0.85..0.95).contains(&glass),
            "1 − F_avg: {index_matched} at η 1, {glass} at η {}",
            grid_eta(k)
        );
    }
}
