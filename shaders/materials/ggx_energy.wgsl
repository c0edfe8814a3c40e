// Lookups in the GGX albedo tables (mirror: src/cpu/materials/ggx_energy.rs; the tables are made by
// src/tables/ggx.rs, which says what they hold): bilinear in mu = cos(theta) and roughness
// sqrt(alpha), along which the rows are evenly spaced.

@group(0) @binding(25) var<storage, read> ggx_energy: array<f32>;

const GGX_ENERGY_SIZE: u32 = 32u;
const GGX_ENERGY_OFFSET_A: u32 = 0u;
const GGX_ENERGY_OFFSET_B: u32 = 1024u;
const GGX_ENERGY_OFFSET_A_AVERAGE: u32 = 2048u;
const GGX_ENERGY_OFFSET_B_AVERAGE: u32 = 2080u;
const GGX_ENERGY_OFFSET_AA_AVERAGE: u32 = 2112u;
const GGX_ENERGY_OFFSET_AB_AVERAGE: u32 = 3136u;
const GGX_ENERGY_OFFSET_BB_AVERAGE: u32 = 4160u;

struct GgxRow {
    j: u32,
    s: f32,
}

fn ggx_alpha_row(alpha: f32) -> GgxRow {
    let last = f32(GGX_ENERGY_SIZE - 1u);
    let y = clamp(sqrt(alpha) * last, 0.0, last);
    let j = min(u32(y), GGX_ENERGY_SIZE - 2u);
    return GgxRow(j, y - f32(j));
}

// The column below cos(theta) = mu and the weight of the one after: columns sit at
// (i + 1/2) / N, and read as constant beyond the first and the last.
struct GgxColumn {
    i: u32,
    t: f32,
}

fn ggx_mu_column(mu: f32) -> GgxColumn {
    let n = f32(GGX_ENERGY_SIZE);
    let x = clamp(mu * n - 0.5, 0.0, n - 1.0);
    let i = min(u32(x), GGX_ENERGY_SIZE - 2u);
    return GgxColumn(i, x - f32(i));
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
    let column = ggx_mu_column(mu);
    let row = ggx_alpha_row(alpha);
    return vec2<f32>(
        ggx_table_bilinear(GGX_ENERGY_OFFSET_A, column.i, column.t, row),
        ggx_table_bilinear(GGX_ENERGY_OFFSET_B, column.i, column.t, row)
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

// The product-average part at `offset` for rows (row1, row2), bilinear in both; `swapped`
// reads the part with the rows exchanged (B.A from A.B).
fn ggx_product_bilinear(offset: u32, row1: GgxRow, row2: GgxRow, swapped: bool) -> f32 {
    let n = GGX_ENERGY_SIZE;
    var stride1 = n;
    var stride2 = 1u;
    if swapped {
        stride1 = 1u;
        stride2 = n;
    }
    let at = offset + row1.j * stride1 + row2.j * stride2;
    let v00 = ggx_energy[at];
    let v01 = ggx_energy[at + stride2];
    let v10 = ggx_energy[at + stride1];
    let v11 = ggx_energy[at + stride1 + stride2];
    let low = v00 + row2.s * (v01 - v00);
    let high = v10 + row2.s * (v11 - v10);
    return low + row1.s * (high - low);
}

// The averages of products 2 int X(mu, alpha1) Y(mu, alpha2) mu dmu for (X, Y) = (A, A),
// (A, B), (B, A), (B, B).
fn ggx_albedo_product_average(alpha1: f32, alpha2: f32) -> vec4<f32> {
    let row1 = ggx_alpha_row(alpha1);
    let row2 = ggx_alpha_row(alpha2);
    return vec4<f32>(
        ggx_product_bilinear(GGX_ENERGY_OFFSET_AA_AVERAGE, row1, row2, false),
        ggx_product_bilinear(GGX_ENERGY_OFFSET_AB_AVERAGE, row1, row2, false),
        ggx_product_bilinear(GGX_ENERGY_OFFSET_AB_AVERAGE, row1, row2, true),
        ggx_product_bilinear(GGX_ENERGY_OFFSET_BB_AVERAGE, row1, row2, false)
    );
}
