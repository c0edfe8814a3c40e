// KHR_materials_sheen's "Charlie" sheen (mirror: src/cpu/materials/sheen.rs, which says why): Estevez
// and Kulla's distribution with the extension's visibility, f = colour D V; the layers below
// scaled by min(1 - max(colour) E(mu_o), 1 - max(colour) E(mu_i)) as the extension says.
// Sampled uniformly over the hemisphere (sheen reflects most towards grazing angles).
// Compiled in only when a material has a sheen (HAS_SHEEN, src/kernel/variant.rs).

// The smallest sheen roughness (src/tables/sheen.rs).
const SHEEN_MIN_ROUGHNESS: f32 = 0.05;
const UNIFORM_HEMISPHERE_PDF: f32 = 0.15915494309189535;

struct SheenLobe {
    // Black: no sheen.
    color: vec3<f32>,
    roughness: f32,
    alpha: f32,
    // 1 - max(colour) E(mu_o): the most the layers below keep.
    scale_o: f32,
    // The mean over the channels of colour E(mu_o), for sampling.
    albedo_o: f32,
}

// (f cos(theta_i) of the sheen, the scale of the layers below).
struct SheenEval {
    f_cos: vec3<f32>,
    below: f32,
}

fn no_sheen() -> SheenLobe {
    return SheenLobe(vec3<f32>(0.0), 1.0, 1.0, 1.0, 0.0);
}

fn sheen_lobe(color: vec3<f32>, roughness_in: f32, mu_o: f32) -> SheenLobe {
    var l: SheenLobe;
    l.color = color;
    l.roughness = max(roughness_in, SHEEN_MIN_ROUGHNESS);
    l.alpha = l.roughness * l.roughness;
    let e_o = sheen_albedo(mu_o, l.roughness);
    l.scale_o = 1.0 - max(color.x, max(color.y, color.z)) * e_o;
    l.albedo_o = (color.x + color.y + color.z) * (1.0 / 3.0) * e_o;
    return l;
}

fn sheen_transmitted_o(l: SheenLobe) -> f32 {
    return l.scale_o;
}

// The extension's fit L(x), its coefficients interpolated by (1 - alpha)^2.
fn sheen_lambda_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let a = 21.5473 + (25.3245 - 21.5473) * t;
    let b = 3.82987 + (3.32435 - 3.82987) * t;
    let c = 0.19823 + (0.16801 - 0.19823) * t;
    let d = -1.97760 + (-1.27393 + 1.97760) * t;
    let e = -4.32054 + (-4.85967 + 4.32054) * t;
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

fn charlie_lambda(cos_theta: f32, alpha: f32) -> f32 {
    if cos_theta < 0.5 {
        return exp(sheen_lambda_fit(cos_theta, alpha));
    }
    return exp(2.0 * sheen_lambda_fit(0.5, alpha) - sheen_lambda_fit(1.0 - cos_theta, alpha));
}

// wo, wi in the local frame, both above the surface.
fn sheen_eval(l: SheenLobe, wo: vec3<f32>, wi: vec3<f32>) -> SheenEval {
    let h = normalize(wo + wi);
    let inv = 1.0 / l.alpha;
    let sin2 = max(1.0 - h.z * h.z, 0.0);
    let d = (2.0 + inv) * pow(sin2, 0.5 * inv) / (2.0 * PI);
    let v = clamp(
        1.0 / ((1.0 + charlie_lambda(wo.z, l.alpha) + charlie_lambda(wi.z, l.alpha)) * (4.0 * wo.z * wi.z)),
        0.0,
        1.0
    );
    let e_i = sheen_albedo(wi.z, l.roughness);
    let below = min(l.scale_o, 1.0 - max(l.color.x, max(l.color.y, l.color.z)) * e_i);
    return SheenEval(l.color * (d * v * wi.z), below);
}

// A direction in the local frame, uniform over the upper hemisphere.
fn sample_uniform_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let z = u.x;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}
