// Lookups in the coat's table (mirror: src/cpu/materials/clearcoat_energy.rs; the table is made by
// src/tables/clearcoat.rs, which says what it holds): trilinear in mu = cos(theta), the
// base's roughness sqrt(alpha) and the coat's, on the GGX tables' grid.

@group(0) @binding(36) var<storage, read> clearcoat_energy: array<f32>;

const CLEARCOAT_ENERGY_SIZE: u32 = 32u;
// Values per part (h_A, then h_B).
const CLEARCOAT_ENERGY_PART: u32 = 32768u;

fn clearcoat_energy_part(offset: u32, column: GgxColumn, base: GgxRow, coat: GgxRow) -> f32 {
    let n = CLEARCOAT_ENERGY_SIZE;
    let t = column.t;
    let at00 = offset + (coat.j * n + base.j) * n + column.i;
    let at01 = at00 + n;
    let at10 = at00 + n * n;
    let at11 = at10 + n;
    let r00 = clearcoat_energy[at00] + t * (clearcoat_energy[at00 + 1u] - clearcoat_energy[at00]);
    let r01 = clearcoat_energy[at01] + t * (clearcoat_energy[at01 + 1u] - clearcoat_energy[at01]);
    let r10 = clearcoat_energy[at10] + t * (clearcoat_energy[at10 + 1u] - clearcoat_energy[at10]);
    let r11 = clearcoat_energy[at11] + t * (clearcoat_energy[at11 + 1u] - clearcoat_energy[at11]);
    let low = r00 + base.s * (r01 - r00);
    let high = r10 + base.s * (r11 - r10);
    return low + coat.s * (high - low);
}

// (h_A, h_B)(mu, alpha_base, alpha_coat): the factors of the coat's scaling of the two parts
// of a specular lobe below it at one end.
fn clearcoat_narrow_scale(mu: f32, alpha_base: f32, alpha_coat: f32) -> vec2<f32> {
    let column = ggx_mu_column(mu);
    let base = ggx_alpha_row(alpha_base);
    let coat = ggx_alpha_row(alpha_coat);
    return vec2<f32>(
        clearcoat_energy_part(0u, column, base, coat),
        clearcoat_energy_part(CLEARCOAT_ENERGY_PART, column, base, coat)
    );
}
