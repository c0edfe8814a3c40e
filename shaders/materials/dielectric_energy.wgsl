// Lookups in the rough dielectric's albedo tables (mirror: src/cpu/materials/dielectric_energy.rs; the
// tables are made by src/tables/dielectric.rs, which says what they hold): linear in
// mu = cos(theta), alpha and r = (eta - 1) / (eta + 1), in the half that etap's side picks.
// Bound with the table only where a material transmits (a placeholder otherwise).

@group(0) @binding(33) var<storage, read> dielectric_energy: array<f32>;

const DIELECTRIC_ENERGY_MU: u32 = 32u;
const DIELECTRIC_ENERGY_ALPHA: u32 = 16u;
const DIELECTRIC_ENERGY_ETA: u32 = 24u;
const DIELECTRIC_ENERGY_OFFSET_AVERAGE: u32 = 24576u;
const DIELECTRIC_ENERGY_OFFSET_TRANSMITTANCE: u32 = 25344u;
// r of MAX_IOR (100), the last point of the index axis.
const DIELECTRIC_ENERGY_MAX_R: f32 = 99.0 / 101.0;

struct DielectricBracket {
    k: u32,
    s: f32,
}

// The grid point at or below x (clamped to a grid of n points) and the weight of the next.
fn dielectric_bracket(x: f32, n: u32) -> DielectricBracket {
    let last = f32(n - 1u);
    let y = clamp(x, 0.0, last);
    let k = min(u32(y), n - 2u);
    return DielectricBracket(k, y - f32(k));
}

// The index axis' coordinate of etap: r of eta = max(etap, 1/etap), in grid steps.
fn dielectric_eta_coordinate(etap: f32) -> DielectricBracket {
    let eta = select(etap, 1.0 / etap, etap < 1.0);
    let r = (eta - 1.0) / (eta + 1.0);
    return dielectric_bracket(
        r / DIELECTRIC_ENERGY_MAX_R * f32(DIELECTRIC_ENERGY_ETA - 1u),
        DIELECTRIC_ENERGY_ETA
    );
}

// The first row (side, r, alpha) of the cell of (alpha, etap), and the weights of the next
// index and alpha rows.
struct DielectricCell {
    row: u32,
    eta_weight: f32,
    alpha_weight: f32,
}

fn dielectric_cell(alpha: f32, etap: f32) -> DielectricCell {
    let side = select(0u, 1u, etap < 1.0);
    let e = dielectric_eta_coordinate(etap);
    let a = dielectric_bracket(alpha * f32(DIELECTRIC_ENERGY_ALPHA - 1u), DIELECTRIC_ENERGY_ALPHA);
    return DielectricCell((side * DIELECTRIC_ENERGY_ETA + e.k) * DIELECTRIC_ENERGY_ALPHA + a.k, e.s, a.s);
}

// E at row `row` and mu column i + t.
fn dielectric_albedo_row(row: u32, i: u32, t: f32) -> f32 {
    let at = row * DIELECTRIC_ENERGY_MU + i;
    return dielectric_energy[at] + t * (dielectric_energy[at + 1u] - dielectric_energy[at]);
}

// E(mu, alpha, etap): the share of energy arriving at cos(theta) = mu that the
// single-scattering rough dielectric reflects or refracts.
fn dielectric_albedo(mu: f32, alpha: f32, etap: f32) -> f32 {
    let n = DIELECTRIC_ENERGY_MU;
    let b = dielectric_bracket(mu * f32(n) - 0.5, n);
    let c = dielectric_cell(alpha, etap);
    let low0 = dielectric_albedo_row(c.row, b.k, b.s);
    let low = low0 + c.alpha_weight * (dielectric_albedo_row(c.row + 1u, b.k, b.s) - low0);
    let next = c.row + DIELECTRIC_ENERGY_ALPHA;
    let high0 = dielectric_albedo_row(next, b.k, b.s);
    let high = high0 + c.alpha_weight * (dielectric_albedo_row(next + 1u, b.k, b.s) - high0);
    return low + c.eta_weight * (high - low);
}

// E_avg(alpha, etap) = 2 int E mu dmu.
fn dielectric_albedo_average(alpha: f32, etap: f32) -> f32 {
    let c = dielectric_cell(alpha, etap);
    let at = DIELECTRIC_ENERGY_OFFSET_AVERAGE + c.row;
    let next = at + DIELECTRIC_ENERGY_ALPHA;
    let low = dielectric_energy[at] + c.alpha_weight * (dielectric_energy[at + 1u] - dielectric_energy[at]);
    let high = dielectric_energy[next] + c.alpha_weight * (dielectric_energy[next + 1u] - dielectric_energy[next]);
    return low + c.eta_weight * (high - low);
}

// 1 - F_avg of a smooth interface between the two media, for light from the rarer side.
fn smooth_transmittance_average(etap: f32) -> f32 {
    let e = dielectric_eta_coordinate(etap);
    let at = DIELECTRIC_ENERGY_OFFSET_TRANSMITTANCE + e.k;
    return dielectric_energy[at] + e.s * (dielectric_energy[at + 1u] - dielectric_energy[at]);
}
