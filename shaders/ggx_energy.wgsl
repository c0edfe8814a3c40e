// Lookups in the GGX albedo tables (mirror: src/cpu/ggx_energy.rs; the tables are made by
// src/ggx_energy.rs, which says what they hold): bilinear in mu = cos(theta) and alpha.

@group(0) @binding(25) var<storage, read> ggx_energy: array<f32>;

const GGX_ENERGY_SIZE: u32 = 32u;
const GGX_ENERGY_OFFSET_A: u32 = 0u;
const GGX_ENERGY_OFFSET_B: u32 = 1024u;
const GGX_ENERGY_OFFSET_A_AVERAGE: u32 = 2048u;
const GGX_ENERGY_OFFSET_B_AVERAGE: u32 = 2080u;

struct GgxRow {
    j: u32,
    s: f32,
}

fn ggx_alpha_row(alpha: f32) -> GgxRow {
    let last = f32(GGX_ENERGY_SIZE - 1u);
    let y = clamp(alpha * last, 0.0, last);
    let j = min(u32(y), GGX_ENERGY_SIZE - 2u);
    return GgxRow(j, y - f32(j));
}

fn ggx_table_bilinear(offset: u32, i: u32, t: f32, row: GgxRow) -> f32 {
    let row0 = offset + row.j * GGX_ENERGY_SIZE + i;
    let row1 = row0 + GGX_ENERGY_SIZE;
    let low = ggx_energy[row0] + t * (ggx_energy[row0 + 1u] - ggx_energy[row0]);
    let high = ggx_energy[row1] + t * (ggx_energy[row1 + 1u] - ggx_energy[row1]);
    return low + row.s * (high - low);
}

// (A, B) at cos(theta) = mu and alpha: the split-sum albedo f0 A + f90 B of a GGX lobe with
// Schlick's Fresnel.
fn ggx_albedo(mu: f32, alpha: f32) -> vec2<f32> {
    let n = f32(GGX_ENERGY_SIZE);
    let x = clamp(mu * n - 0.5, 0.0, n - 1.0);
    let i = min(u32(x), GGX_ENERGY_SIZE - 2u);
    let t = x - f32(i);
    let row = ggx_alpha_row(alpha);
    return vec2<f32>(
        ggx_table_bilinear(GGX_ENERGY_OFFSET_A, i, t, row),
        ggx_table_bilinear(GGX_ENERGY_OFFSET_B, i, t, row)
    );
}

// The hemispherical averages (2 int A mu dmu, 2 int B mu dmu) at alpha.
fn ggx_albedo_average(alpha: f32) -> vec2<f32> {
    let row = ggx_alpha_row(alpha);
    let a = ggx_energy[GGX_ENERGY_OFFSET_A_AVERAGE + row.j];
    let a1 = ggx_energy[GGX_ENERGY_OFFSET_A_AVERAGE + row.j + 1u];
    let b = ggx_energy[GGX_ENERGY_OFFSET_B_AVERAGE + row.j];
    let b1 = ggx_energy[GGX_ENERGY_OFFSET_B_AVERAGE + row.j + 1u];
    return vec2<f32>(a + row.s * (a1 - a), b + row.s * (b1 - b));
}
