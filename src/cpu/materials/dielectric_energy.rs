//! Lookups in the rough dielectric's albedo tables of `crate::tables::dielectric` (WGSL side:
//! `shaders/materials/dielectric_energy.wgsl`, which reads the same numbers from binding 33): linear in
//! μ = cos θ, α and r = (η − 1)/(η + 1), in the half of the table that etap's side picks, with
//! the same f32 operations on both sides.

use crate::tables::dielectric::{
    dielectric_energy_table, max_reflectance_root, DIELECTRIC_ENERGY_ALPHA, DIELECTRIC_ENERGY_ETA,
    DIELECTRIC_ENERGY_MU, OFFSET_ALBEDO, OFFSET_AVERAGE, OFFSET_TRANSMITTANCE,
};

/// Where (α, etap) falls: the first row (side, r, α) of its cell, and the weights of the next
/// index and α rows.
struct Cell {
    row: usize,
    eta_weight: f32,
    alpha_weight: f32,
}

/// The grid point at or below `x` (clamped to the grid of `n` points) and the weight of the
/// next one.
fn bracket(x: f32, n: usize) -> (usize, f32) {
    let x = x.clamp(0.0, (n - 1) as f32);
    let k = (x as usize).min(n - 2);
    (k, x - k as f32)
}

/// The index axis' coordinate of etap: r of η = max(etap, 1/etap), in grid steps.
fn eta_coordinate(etap: f32) -> (usize, f32) {
    let eta = if etap < 1.0 { 1.0 / etap } else { etap };
    let r = (eta - 1.0) / (eta + 1.0);
    bracket(
        r / max_reflectance_root() * (DIELECTRIC_ENERGY_ETA - 1) as f32,
        DIELECTRIC_ENERGY_ETA,
    )
}

fn cell(alpha: f32, etap: f32) -> Cell {
    let side = if etap < 1.0 { 1 } else { 0 };
    let (k, eta_weight) = eta_coordinate(etap);
    let (j, alpha_weight) = bracket(
        alpha * (DIELECTRIC_ENERGY_ALPHA - 1) as f32,
        DIELECTRIC_ENERGY_ALPHA,
    );
    Cell {
        row: (side * DIELECTRIC_ENERGY_ETA + k) * DIELECTRIC_ENERGY_ALPHA + j,
        eta_weight,
        alpha_weight,
    }
}

/// Bilinear in (r, α) of `value(row)` around the cell.
fn blend(c: &Cell, value: impl Fn(usize) -> f32) -> f32 {
    let next_eta = DIELECTRIC_ENERGY_ALPHA;
    let mix = |row: usize| {
        let low = value(row);
        low + c.alpha_weight * (value(row + 1) - low)
    };
    let low = mix(c.row);
    low + c.eta_weight * (mix(c.row + next_eta) - low)
}

/// E(μ, α, etap): the share of energy arriving at cos θ = `mu` that the single-scattering
/// rough dielectric reflects or refracts.
pub fn dielectric_albedo(mu: f32, alpha: f32, etap: f32) -> f32 {
    let table = dielectric_energy_table();
    let n = DIELECTRIC_ENERGY_MU;
    let (i, t) = bracket(mu * n as f32 - 0.5, n);
    blend(&cell(alpha, etap), |row| {
        let at = OFFSET_ALBEDO + row * n + i;
        table[at] + t * (table[at + 1] - table[at])
    })
}

/// E_avg(α, etap) = 2∫E μ dμ.
pub fn dielectric_albedo_average(alpha: f32, etap: f32) -> f32 {
    let table = dielectric_energy_table();
    blend(&cell(alpha, etap), |row| table[OFFSET_AVERAGE + row])
}

/// 1 − F_avg of a smooth interface between the two media, for light from the rarer side.
pub fn smooth_transmittance_average(etap: f32) -> f32 {
    let table = dielectric_energy_table();
    let (k, s) = eta_coordinate(etap);
    let low = table[OFFSET_TRANSMITTANCE + k];
    low + s * (table[OFFSET_TRANSMITTANCE + k + 1] - low)
}
