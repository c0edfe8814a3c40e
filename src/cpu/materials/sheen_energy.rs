//! Lookups in the sheen albedo table of `crate::tables::sheen` (WGSL side:
//! `shaders/materials/sheen_energy.wgsl`, which reads the same numbers from binding 32): bilinear in
//! μ = cos θ and the sheen roughness, the same f32 operations on both sides.

use crate::tables::sheen::{sheen_energy_table, SHEEN_ENERGY_SIZE};

/// E(μ, roughness): the directional albedo of a white Charlie sheen lobe.
pub fn sheen_albedo(mu: f32, roughness: f32) -> f32 {
    let table = sheen_energy_table();
    let n = SHEEN_ENERGY_SIZE;
    let last = (n - 1) as f32;
    let x = (mu * n as f32 - 0.5).clamp(0.0, last);
    let i = (x as usize).min(n - 2);
    let t = x - i as f32;
    let y = (roughness * last).clamp(0.0, last);
    let j = (y as usize).min(n - 2);
    let s = y - j as f32;
    let row0 = j * n + i;
    let row1 = row0 + n;
    let low = table[row0] + t * (table[row0 + 1] - table[row0]);
    let high = table[row1] + t * (table[row1 + 1] - table[row1]);
    low + s * (high - low)
}
