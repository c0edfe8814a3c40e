//! Lookups in the GGX albedo tables of `crate::tables::ggx` (WGSL side:
//! `shaders/materials/ggx_energy.wgsl`, which reads the same numbers from binding 25): bilinear in
//! μ = cos θ and roughness √α, the same f32 operations on both sides.

use crate::tables::ggx::{
    ggx_energy_table, GGX_ENERGY_SIZE, OFFSET_A, OFFSET_AA_AVERAGE, OFFSET_AB_AVERAGE,
    OFFSET_A_AVERAGE, OFFSET_B, OFFSET_BB_AVERAGE, OFFSET_B_AVERAGE,
};

/// The row below `alpha` and the weight of the one above: rows are evenly spaced in √α.
pub(super) fn alpha_row(alpha: f32) -> (usize, f32) {
    let y = (alpha.sqrt() * (GGX_ENERGY_SIZE - 1) as f32).clamp(0.0, (GGX_ENERGY_SIZE - 1) as f32);
    let j = (y as usize).min(GGX_ENERGY_SIZE - 2);
    (j, y - j as f32)
}

/// The column below cos θ = `mu` and the weight of the one after: columns sit at (i + ½)/N,
/// and read as constant beyond the first and the last.
pub(super) fn mu_column(mu: f32) -> (usize, f32) {
    let n = GGX_ENERGY_SIZE;
    let x = (mu * n as f32 - 0.5).clamp(0.0, (n - 1) as f32);
    let i = (x as usize).min(n - 2);
    (i, x - i as f32)
}

/// (A, B) at cos θ = `mu` and `alpha`: the split-sum albedo f0·A + f90·B of a GGX lobe with
/// Schlick's Fresnel.
pub fn ggx_albedo(mu: f32, alpha: f32) -> (f32, f32) {
    let table = ggx_energy_table();
    let n = GGX_ENERGY_SIZE;
    let (i, t) = mu_column(mu);
    let (j, s) = alpha_row(alpha);
    let at = |offset: usize| {
        let row0 = offset + j * n + i;
        let row1 = row0 + n;
        let low = table[row0] + t * (table[row0 + 1] - table[row0]);
        let high = table[row1] + t * (table[row1 + 1] - table[row1]);
        low + s * (high - low)
    };
    (at(OFFSET_A), at(OFFSET_B))
}

/// The hemispherical averages (2∫A μ dμ, 2∫B μ dμ) at `alpha`.
pub fn ggx_albedo_average(alpha: f32) -> (f32, f32) {
    let table = ggx_energy_table();
    let (j, s) = alpha_row(alpha);
    let at = |offset: usize| {
        let low = table[offset + j];
        low + s * (table[offset + j + 1] - low)
    };
    (at(OFFSET_A_AVERAGE), at(OFFSET_B_AVERAGE))
}

/// The averages of products of the split-sum parts at two α, 2∫X(μ, α1) Y(μ, α2) μ dμ, for
/// (X, Y) = (A, A), (A, B), (B, A), (B, B): bilinear in the two rows, which is exactly the
/// average of the product of the interpolated rows.
pub fn ggx_albedo_product_average(alpha1: f32, alpha2: f32) -> [f32; 4] {
    let table = ggx_energy_table();
    let n = GGX_ENERGY_SIZE;
    let (j1, s1) = alpha_row(alpha1);
    let (j2, s2) = alpha_row(alpha2);
    // The part at `offset` with rows (k1, k2) = (j1, j2) + corner, bilinear in (s1, s2).
    let at = |offset: usize, swapped: bool| {
        let value = |k1: usize, k2: usize| {
            if swapped {
                table[offset + k2 * n + k1]
            } else {
                table[offset + k1 * n + k2]
            }
        };
        let low = value(j1, j2) + s2 * (value(j1, j2 + 1) - value(j1, j2));
        let high = value(j1 + 1, j2) + s2 * (value(j1 + 1, j2 + 1) - value(j1 + 1, j2));
        low + s1 * (high - low)
    };
    [
        at(OFFSET_AA_AVERAGE, false),
        at(OFFSET_AB_AVERAGE, false),
        at(OFFSET_AB_AVERAGE, true),
        at(OFFSET_BB_AVERAGE, false),
    ]
}
