// KHR_materials_clearcoat's coat (mirror: src/cpu/materials/clearcoat.rs, which says why): a GGX
// dielectric layer (f0 = 0.04, f90 = 1) with Kulla and Conty's multiple scattering, weighted
// by the clearcoat factor c, over the whole pbr stack; the stack is scaled by the coat's whole
// albedo L, reciprocally: its broad lobes by (1 - c L(mu_o)) (1 - c L(mu_i)) / (1 - c L_avg),
// its specular lobes by 1 - c min(1, max(L(mu_o), L(mu_i)) h(mu_o) h(mu_i)), h from
// src/tables/clearcoat.rs for each part of their Schlick Fresnel.
// Compiled in only when a material has a coat (HAS_CLEARCOAT, src/kernel/variant.rs).

// The coat's Fresnel at normal incidence: ior 1.5.
const CLEARCOAT_F0: f32 = 0.04;
// The smallest alpha of the coat (roughness 0.032).
const CLEARCOAT_MIN_ALPHA: f32 = 1e-3;

struct ClearcoatLobe {
    // The clearcoat factor c (0: no coat).
    weight: f32,
    alpha: f32,
    e_o: f32,
    e_average: f32,
    ms: f32,
    albedo_o: f32,
    albedo_average: f32,
    // c times the single- and the multiple-scattering albedo at mu_o, for sampling.
    specular_albedo_o: f32,
    ms_albedo_o: f32,
    // The alpha of the specular lobes below, and the factors (h_A, h_B)(mu_o) of their
    // scaling (src/tables/clearcoat.rs).
    base_alpha: f32,
    narrow_scale_o: vec2<f32>,
}

// The coat's own f cos(theta_i), and the scales of the broad and the specular lobes below.
struct ClearcoatEval {
    f_cos: f32,
    below_broad: f32,
    // For the two parts of a specular lobe, weighted by 1 - (1 - cos(theta_h))^5 and by
    // (1 - cos(theta_h))^5 (Schlick's f0 and f90 terms).
    below_narrow: vec2<f32>,
}

fn no_clearcoat() -> ClearcoatLobe {
    return ClearcoatLobe(0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, vec2<f32>(1.0));
}

// The coat's whole albedo L from its split-sum parts.
fn clearcoat_layer_albedo(a: f32, b: f32, e: f32, ms: f32) -> f32 {
    return CLEARCOAT_F0 * a + b + ms * (1.0 - e);
}

// The coat of weight c and alpha over specular lobes of alpha base_alpha, seen from mu_o.
fn clearcoat_lobe(weight: f32, alpha_in: f32, mu_o: f32, base_alpha: f32) -> ClearcoatLobe {
    var l: ClearcoatLobe;
    l.weight = weight;
    l.alpha = max(alpha_in, CLEARCOAT_MIN_ALPHA);
    let ab_o = ggx_albedo(mu_o, l.alpha);
    let ab_average = ggx_albedo_average(l.alpha);
    l.e_o = ab_o.x + ab_o.y;
    l.e_average = ab_average.x + ab_average.y;
    let f_average = CLEARCOAT_F0 + (1.0 - CLEARCOAT_F0) * (1.0 / 21.0);
    l.ms = f_average * f_average * l.e_average / (1.0 - f_average * (1.0 - l.e_average));
    l.albedo_o = clearcoat_layer_albedo(ab_o.x, ab_o.y, l.e_o, l.ms);
    l.albedo_average = clearcoat_layer_albedo(ab_average.x, ab_average.y, l.e_average, l.ms);
    l.specular_albedo_o = weight * (CLEARCOAT_F0 * ab_o.x + ab_o.y);
    l.ms_albedo_o = weight * l.ms * (1.0 - l.e_o);
    l.base_alpha = base_alpha;
    l.narrow_scale_o = clearcoat_narrow_scale(mu_o, base_alpha, l.alpha);
    return l;
}

// The factor of a broad lobe below the coat that normalises the coat's scaling and the
// lobe's own, 1 - L' = q0 + qa A + qb B, together (see clearcoat_coupling in the mirror):
// (1 - c L_avg)(1 - L'_avg) / 2 int (1 - c L(mu))(1 - L'(mu)) mu dmu.
fn clearcoat_coupling(l: ClearcoatLobe, alpha: f32, q0: vec3<f32>, qa: vec3<f32>, qb: vec3<f32>) -> vec3<f32> {
    let p0 = 1.0 - l.weight * l.ms;
    let pa = -l.weight * (CLEARCOAT_F0 - l.ms);
    let pb = -l.weight * (1.0 - l.ms);
    let coat_ab = ggx_albedo_average(l.alpha);
    let layer_ab = ggx_albedo_average(alpha);
    let m = ggx_albedo_product_average(l.alpha, alpha);
    let coat_room = 1.0 - l.weight * l.albedo_average;
    let layer_room = q0 + qa * layer_ab.x + qb * layer_ab.y;
    let joint = p0 * layer_room
        + q0 * (pa * coat_ab.x + pb * coat_ab.y)
        + qa * (pa * m.x + pb * m.z)
        + qb * (pa * m.y + pb * m.w);
    let ratio = coat_room * layer_room / joint;
    return select(vec3<f32>(1.0), ratio, joint > vec3<f32>(0.0));
}

// The share of light from wo that passes the coat (what refraction keeps).
fn clearcoat_transmitted_o(l: ClearcoatLobe) -> f32 {
    return 1.0 - l.weight * l.albedo_o;
}

// wo, wi in the coat's local frame (about its own normal); with either below it the coat's
// lobe is black, and below it wi dims the layers under the coat as its mirror image above
// does (|cos|; see clearcoat_eval in the mirror for why).
fn clearcoat_eval(l: ClearcoatLobe, wo: vec3<f32>, wi: vec3<f32>) -> ClearcoatEval {
    let ab_i = ggx_albedo(abs(wi.z), l.alpha);
    let e_i = ab_i.x + ab_i.y;
    let albedo_i = clearcoat_layer_albedo(ab_i.x, ab_i.y, e_i, l.ms);
    let passed = (1.0 - l.weight * l.albedo_o) * (1.0 - l.weight * albedo_i);
    let room = 1.0 - l.weight * l.albedo_average;
    var below_broad = 0.0;
    if room > 0.0 {
        below_broad = passed / room;
    }
    let narrow_scale_i = clearcoat_narrow_scale(abs(wi.z), l.base_alpha, l.alpha);
    let larger = max(l.albedo_o, albedo_i) * l.narrow_scale_o * narrow_scale_i;
    let below_narrow = vec2<f32>(1.0) - l.weight * min(larger, vec2<f32>(1.0));
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return ClearcoatEval(0.0, below_broad, below_narrow);
    }
    let h = normalize(wo + wi);
    let c = clamp(1.0 - dot(wo, h), 0.0, 1.0);
    let s5 = c * c * c * c * c;
    let fresnel = CLEARCOAT_F0 + (1.0 - CLEARCOAT_F0) * s5;
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, l.alpha) + ggx_lambda(wi, l.alpha));
    var f_cos = fresnel * ggx_d(h.z, l.alpha) * g2 / (4.0 * wo.z);
    if l.e_average < 1.0 {
        f_cos += l.ms * (1.0 - l.e_o) * (1.0 - e_i) / (PI * (1.0 - l.e_average)) * wi.z;
    }
    return ClearcoatEval(l.weight * f_cos, below_broad, below_narrow);
}
