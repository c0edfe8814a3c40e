//! The directional albedo E(μ, r) of KHR_materials_sheen's "Charlie" sheen lobe with a white
//! colour, tabulated for the extension's albedo scaling of the layers below the sheen
//! (`src/cpu/materials/sheen.rs`, `shaders/materials/sheen.wgsl`): the lobe reflects colour · E(μo), and the
//! layers below are scaled by 1 − max(colour) · E.
//!
//! Computed here, at first use, by a midpoint rule over the hemisphere of incoming directions
//! in f64, from the extension's own formulas (Estevez and Kulla 2017's distribution, the
//! extension's fitted visibility): deterministic, well under a second, never hand-typed. The
//! same numbers feed the GPU (binding 32) and the CPU reference.

use std::f64::consts::PI;
use std::sync::OnceLock;

/// Grid points per axis: μ at (i + ½)/N, sheen roughness at j/(N − 1).
pub const SHEEN_ENERGY_SIZE: usize = 32;
/// The smallest sheen roughness the lobe uses (α = 0.0025): below it the distribution is so
/// narrow that neither the table's quadrature nor f32 powers resolve it, and its albedo is
/// already negligible away from grazing angles.
pub const SHEEN_MIN_ROUGHNESS: f64 = 0.05;
pub const SHEEN_ENERGY_LEN: usize = SHEEN_ENERGY_SIZE * SHEEN_ENERGY_SIZE;

/// Quadrature points in cos θi and in φi over [0, π] (the lobe is symmetric in φ).
const STEPS_MU: usize = 128;
const STEPS_PHI: usize = 128;

/// The table (N × N, roughness-major), computed once per process. The extension's lobe is
/// not energy-conserving everywhere: at the most grazing μ and the smallest roughness its
/// albedo exceeds 1 (1.46 at μ 1/64, roughness 0.05), so the table holds at most 1, and the
/// layers below are never scaled by less than 0.
pub fn sheen_energy_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = SHEEN_ENERGY_SIZE;
        (0..n * n)
            .map(|k| {
                let e = sheen_albedo_exact(grid_mu(k % n), grid_roughness(k / n), STEPS_MU);
                e.min(1.0) as f32
            })
            .collect()
    })
}

/// μ of grid column i and sheen roughness of grid row j.
pub fn grid_mu(i: usize) -> f64 {
    (i as f64 + 0.5) / SHEEN_ENERGY_SIZE as f64
}

pub fn grid_roughness(j: usize) -> f64 {
    (j as f64 / (SHEEN_ENERGY_SIZE - 1) as f64).max(SHEEN_MIN_ROUGHNESS)
}

/// The Charlie distribution at cos θh with α = roughness²: (2 + 1/α) sin^(1/α) θh / (2π).
pub fn charlie_d(cos_h: f64, alpha: f64) -> f64 {
    let inv = 1.0 / alpha;
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI)
}

/// The extension's fit L(x), its coefficients interpolated by (1 − α)².
fn lambda_fit(x: f64, alpha: f64) -> f64 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |a: f64, b: f64| a + (b - a) * t;
    let a = mix(21.5473, 25.3245);
    let b = mix(3.82987, 3.32435);
    let c = mix(0.19823, 0.16801);
    let d = mix(-1.97760, -1.27393);
    let e = mix(-4.32054, -4.85967);
    a / (1.0 + b * x.powf(c)) + d * x + e
}

/// The extension's Λ(cos θ).
pub fn charlie_lambda(cos: f64, alpha: f64) -> f64 {
    if cos < 0.5 {
        lambda_fit(cos, alpha).exp()
    } else {
        (2.0 * lambda_fit(0.5, alpha) - lambda_fit(1.0 - cos, alpha)).exp()
    }
}

/// The extension's visibility V = 1 / ((1 + Λ(μo) + Λ(μi)) 4 μo μi), clamped to [0, 1] as
/// Khronos' sample viewer does.
pub fn charlie_v(mu_o: f64, mu_i: f64, alpha: f64) -> f64 {
    let v = 1.0
        / ((1.0 + charlie_lambda(mu_o, alpha) + charlie_lambda(mu_i, alpha)) * 4.0 * mu_o * mu_i);
    v.clamp(0.0, 1.0)
}

/// ∫ D V cos θi dωi at cos θo = μ and `roughness`, by the midpoint rule with `steps` points
/// in cos θi and as many in φi.
pub fn sheen_albedo_exact(mu: f64, roughness: f64, steps: usize) -> f64 {
    let alpha = roughness.max(SHEEN_MIN_ROUGHNESS).powi(2);
    let wo = [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu];
    let steps_phi = steps * STEPS_PHI / STEPS_MU;
    let mut sum = 0.0;
    for a in 0..steps {
        let cos_i = (a as f64 + 0.5) / steps as f64;
        let sin_i = (1.0 - cos_i * cos_i).sqrt();
        let v = charlie_v(mu, cos_i, alpha);
        for b in 0..steps_phi {
            let phi = PI * (b as f64 + 0.5) / steps_phi as f64;
            let h = [
                wo[0] + sin_i * phi.cos(),
                wo[1] + sin_i * phi.sin(),
                wo[2] + cos_i,
            ];
            let length = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            sum += charlie_d(h[2] / length, alpha) * v * cos_i;
        }
    }
    // dω = d(cos θ) dφ, and φ over [0, π] counts half the hemisphere.
    sum * 2.0 * (1.0 / steps as f64) * (PI / steps_phi as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table against the same integral at twice the resolution (the quadrature has
    /// converged), and every entry in [0, 1] (clamped where the lobe itself exceeds 1).
    #[test]
    fn the_table_has_converged_and_creates_no_energy() {
        let table = sheen_energy_table();
        let n = SHEEN_ENERGY_SIZE;
        for (i, j) in [
            (0, 31),
            (5, 10),
            (16, 16),
            (31, 31),
            (20, 1),
            (2, 25),
            (31, 1),
        ] {
            let fine = sheen_albedo_exact(grid_mu(i), grid_roughness(j), 2 * STEPS_MU).min(1.0);
            let value = table[j * n + i] as f64;
            assert!(
                (value - fine).abs() < 2e-3,
                "μ {} r {}: table {value}, finer {fine}",
                grid_mu(i),
                grid_roughness(j)
            );
        }
        assert!(table.iter().all(|v| (0.0..=1.0).contains(v)));
    }
}
