//! Lookups in the coat's table of `crate::tables::clearcoat` (WGSL side:
//! `shaders/materials/clearcoat_energy.wgsl`, which reads the same numbers from binding 36): trilinear
//! in μ = cos θ, the base's roughness √α and the coat's, on the GGX tables' grid, the same f32
//! operations on both sides.

use crate::cpu::materials::ggx_energy::{alpha_row, mu_column};
use crate::tables::clearcoat::{
    clearcoat_energy_table, CLEARCOAT_ENERGY_PART, CLEARCOAT_ENERGY_SIZE,
};
use glam::Vec2;

/// (h_A, h_B)(μ, α_base, α_coat): the factors of the coat's scaling of the two parts of a
/// specular lobe below it at one end (`crate::tables::clearcoat` says what they keep).
pub fn clearcoat_narrow_scale(mu: f32, alpha_base: f32, alpha_coat: f32) -> Vec2 {
    let table = clearcoat_energy_table();
    let n = CLEARCOAT_ENERGY_SIZE;
    let (i, t) = mu_column(mu);
    let (jb, sb) = alpha_row(alpha_base);
    let (jc, sc) = alpha_row(alpha_coat);
    let part = |offset: usize| {
        let row = |jc: usize, jb: usize| {
            let at = offset + (jc * n + jb) * n + i;
            table[at] + t * (table[at + 1] - table[at])
        };
        let along_base = |jc: usize| {
            let low = row(jc, jb);
            low + sb * (row(jc, jb + 1) - low)
        };
        let low = along_base(jc);
        low + sc * (along_base(jc + 1) - low)
    };
    Vec2::new(part(0), part(CLEARCOAT_ENERGY_PART))
}
