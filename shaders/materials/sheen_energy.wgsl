// Lookups in the sheen albedo table (mirror: src/cpu/materials/sheen_energy.rs; the table is made by
// src/tables/sheen.rs, which says what it holds): bilinear in mu = cos(theta) and roughness.

@group(0) @binding(32) var<storage, read> sheen_energy: array<f32>;

const SHEEN_ENERGY_SIZE: u32 = 32u;

// E(mu, roughness): the directional albedo of a white Charlie sheen lobe.
fn sheen_albedo(mu: f32, roughness: f32) -> f32 {
    let n = f32(SHEEN_ENERGY_SIZE);
    let last = n - 1.0;
    let x = clamp(mu * n - 0.5, 0.0, last);
    let i = min(u32(x), SHEEN_ENERGY_SIZE - 2u);
    let t = x - f32(i);
    let y = clamp(roughness * last, 0.0, last);
    let j = min(u32(y), SHEEN_ENERGY_SIZE - 2u);
    let s = y - f32(j);
    let row0 = j * SHEEN_ENERGY_SIZE + i;
    let row1 = row0 + SHEEN_ENERGY_SIZE;
    let low = sheen_energy[row0] + t * (sheen_energy[row0 + 1u] - sheen_energy[row0]);
    let high = sheen_energy[row1] + t * (sheen_energy[row1 + 1u] - sheen_energy[row1]);
    return low + s * (high - low);
}
