// glTF 2.0's metallic-roughness material, energy-compensated (mirror: src/cpu/materials/pbr.rs, which
// says how): a GGX specular lobe with Schlick's Fresnel mixed between the dielectric layer's
// and the metal's, Kulla and Conty's multiple-scattering lobe, and the diffuse base under the
// dielectric layer by reciprocal albedo scaling; with transmission T, (1 - T) of that stack and T
// of rough_dielectric.wgsl's rough glass, its refraction tinted by the base colour. Refracted
// samples are delta only where the refraction is (roughness 0, or ior 1); elsewhere light
// sampling evaluates the rough BTDF through the surface and MIS weighs the two. Over that stack the sheen (sheen.wgsl) and over it the coat (clearcoat.wgsl), each
// scaling what lies below: f = coat + below_coat (sheen + below_sheen base).

// The smallest GGX alpha of the material (roughness 0.032).
const PBR_MIN_ALPHA: f32 = 1e-3;
// Bounds of the probability of sampling the specular lobe, so neither strategy starves.
const MIN_LOBE_PROBABILITY: f32 = 0.1;
// The most the coat's and the sheen's lobes are each sampled with.
const MAX_LAYER_PROBABILITY: f32 = 0.45;

// Whether the material's refraction is a delta, which light sampling cannot evaluate:
// roughness 0 (alpha clamped to PBR_MIN_ALPHA, a needle no light sample would meet), or ior 1,
// where every microfacet refracts straight through.
fn pbr_refraction_is_delta(m: Material) -> bool {
    return m.alpha <= 0.0 || m.ior == 1.0;
}

struct PbrLobes {
    base: vec3<f32>,
    metallic: f32,
    alpha: f32,
    dielectric_f0: vec3<f32>,
    dielectric_f90: f32,
    e_o: f32,
    e_average: f32,
    ms_dielectric: vec3<f32>,
    ms_metal: vec3<f32>,
    layer_o: vec3<f32>,
    layer_average: vec3<f32>,
    // The transmissive share of the dielectric part, and eta(other side) / eta(wo's side).
    transmission: f32,
    etap: f32,
    // Refracted samples are delta (pbr_refraction_is_delta).
    refraction_is_delta: bool,
    specular_probability: f32,
    transmission_probability: f32,
    // The coat and the sheen (none where the material has none or they are compiled out),
    // their sampling probabilities, and the share of light from wo that passes both.
    coat: ClearcoatLobe,
    sheen: SheenLobe,
    coat_probability: f32,
    sheen_probability: f32,
    layers_o: f32,
    // The factors of the diffuse base and of the multiple-scattering lobe that normalise the
    // coat's scaling and their own together (clearcoat_coupling; 1 without a coat).
    coat_diffuse_coupling: vec3<f32>,
    coat_ms_coupling: f32,
}

fn channel_average(v: vec3<f32>) -> f32 {
    return (v.x + v.y + v.z) * (1.0 / 3.0);
}

// Kulla and Conty's F_ms for a lobe whose average Fresnel is f_average.
fn multiple_scattering_fresnel(f_average: vec3<f32>, e_average: f32) -> vec3<f32> {
    return f_average * f_average * e_average / (vec3<f32>(1.0) - f_average * (1.0 - e_average));
}

// front_face says whether wo is on the outside (which decides eta for transmission); mu_o is
// cos(theta_o) about the base's shading normal, coat_mu_o about the coat's (clearcoat.wgsl).
fn pbr_lobes(m: Material, mu_o: f32, coat_mu_o: f32, front_face: bool) -> PbrLobes {
    var l: PbrLobes;
    l.base = m.albedo;
    l.alpha = max(m.alpha, PBR_MIN_ALPHA);
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    l.dielectric_f0 = min(r * r * m.specular_color, vec3<f32>(1.0)) * m.specular;
    l.dielectric_f90 = m.specular;
    let ab_o = ggx_albedo(mu_o, l.alpha);
    let ab_average = ggx_albedo_average(l.alpha);
    l.e_o = ab_o.x + ab_o.y;
    l.e_average = ab_average.x + ab_average.y;
    l.ms_dielectric = multiple_scattering_fresnel(
        l.dielectric_f0 + (l.dielectric_f90 - l.dielectric_f0) * (1.0 / 21.0),
        l.e_average
    );
    l.ms_metal = multiple_scattering_fresnel(l.base + (vec3<f32>(1.0) - l.base) * (1.0 / 21.0), l.e_average);
    l.layer_o = l.dielectric_f0 * ab_o.x + vec3<f32>(l.dielectric_f90 * ab_o.y) + l.ms_dielectric * (1.0 - l.e_o);
    l.layer_average = l.dielectric_f0 * ab_average.x
        + vec3<f32>(l.dielectric_f90 * ab_average.y)
        + l.ms_dielectric * (1.0 - l.e_average);
    l.metallic = m.metallic;
    l.transmission = select(0.0, m.transmission, HAS_TRANSMISSION);
    l.etap = select(1.0 / m.ior, m.ior, front_face);
    l.refraction_is_delta = pbr_refraction_is_delta(m);
    // The opaque dielectric stack's share.
    let opaque = (1.0 - l.metallic) * (1.0 - l.transmission);
    let specular = opaque * (l.dielectric_f0 * ab_o.x + vec3<f32>(l.dielectric_f90 * ab_o.y))
        + l.metallic * (l.base * ab_o.x + vec3<f32>(ab_o.y));
    let ms = (opaque * l.ms_dielectric + l.metallic * l.ms_metal) * (1.0 - l.e_o);
    let diffuse = opaque * l.base * (vec3<f32>(1.0) - l.layer_o);
    let specular_weight = channel_average(specular);
    let other_weight = channel_average(ms + diffuse);
    let transmission_weight = (1.0 - l.metallic) * l.transmission;
    let opaque_total = specular_weight + other_weight;
    let total = opaque_total + transmission_weight;
    l.transmission_probability = 0.0;
    if total > 0.0 {
        l.transmission_probability = transmission_weight / total;
    }
    var specular_share = 0.5;
    if opaque_total > 0.0 {
        specular_share = clamp(specular_weight / opaque_total, MIN_LOBE_PROBABILITY, 1.0 - MIN_LOBE_PROBABILITY);
    }
    l.specular_probability = (1.0 - l.transmission_probability) * specular_share;
    // The layers on top: their lobes take shares of the samples by their albedos at mu_o
    // against the stack's (which they dim), each within [0.1, 0.45] when present.
    l.coat = no_clearcoat();
    if HAS_CLEARCOAT && m.clearcoat > 0.0 {
        l.coat = clearcoat_lobe(m.clearcoat, m.clearcoat_alpha, coat_mu_o, l.alpha);
    }
    l.sheen = no_sheen();
    if HAS_SHEEN && max(m.sheen_color.x, max(m.sheen_color.y, m.sheen_color.z)) > 0.0 {
        l.sheen = sheen_lobe(m.sheen_color, m.sheen_roughness, mu_o);
    }
    l.coat_diffuse_coupling = vec3<f32>(1.0);
    l.coat_ms_coupling = 1.0;
    if HAS_CLEARCOAT && l.coat.weight > 0.0 {
        // What passes the dielectric layer, 1 - Es = (1 - F_ms) - (f0 - F_ms) A - (f90 - F_ms) B,
        // and what the multiple scattering leaves, 1 - E = 1 - A - B.
        l.coat_diffuse_coupling = clearcoat_coupling(
            l.coat,
            l.alpha,
            vec3<f32>(1.0) - l.ms_dielectric,
            l.ms_dielectric - l.dielectric_f0,
            l.ms_dielectric - vec3<f32>(l.dielectric_f90)
        );
        l.coat_ms_coupling = clearcoat_coupling(l.coat, l.alpha, vec3<f32>(1.0), vec3<f32>(-1.0), vec3<f32>(-1.0)).x;
    }
    let below_coat = clearcoat_transmitted_o(l.coat);
    l.layers_o = below_coat * sheen_transmitted_o(l.sheen);
    l.coat_probability = 0.0;
    l.sheen_probability = 0.0;
    let has_sheen = max(l.sheen.color.x, max(l.sheen.color.y, l.sheen.color.z)) > 0.0;
    if (HAS_CLEARCOAT || HAS_SHEEN) && (l.coat.weight > 0.0 || has_sheen) {
        let coat_weight = l.coat.specular_albedo_o;
        let sheen_weight = below_coat * l.sheen.albedo_o;
        let all = coat_weight + sheen_weight + l.coat.ms_albedo_o + l.layers_o * total;
        if all > 0.0 {
            // A coat whose normal wo does not see cannot be sampled (its lobe is black there).
            if l.coat.weight > 0.0 && coat_mu_o > 0.0 {
                l.coat_probability = clamp(coat_weight / all, MIN_LOBE_PROBABILITY, MAX_LAYER_PROBABILITY);
            }
            if has_sheen {
                l.sheen_probability = clamp(sheen_weight / all, MIN_LOBE_PROBABILITY, MAX_LAYER_PROBABILITY);
            }
        }
        let rest = 1.0 - l.coat_probability - l.sheen_probability;
        l.specular_probability *= rest;
        l.transmission_probability *= rest;
    }
    return l;
}

// f * cos(theta_i); wo and wi in the base's local frame, coat_wo and coat_wi in the coat's.
fn pbr_eval(l: PbrLobes, wo: vec3<f32>, wi: vec3<f32>, coat_wo: vec3<f32>, coat_wi: vec3<f32>) -> vec3<f32> {
    // The transmission lobe's share of the whole.
    let transmissive = (1.0 - l.metallic) * l.transmission;
    if wo.z <= 0.0 || wi.z == 0.0 {
        return vec3<f32>(0.0);
    }
    if wi.z < 0.0 {
        if !HAS_TRANSMISSION || transmissive <= 0.0 {
            return vec3<f32>(0.0);
        }
        return l.base * (transmissive * l.layers_o * rough_dielectric_eval(l.alpha, l.etap, wo, wi));
    }
    let opaque = (1.0 - l.metallic) * (1.0 - l.transmission);
    let h = normalize(wo + wi);
    let c = clamp(1.0 - dot(wo, h), 0.0, 1.0);
    let s5 = c * c * c * c * c;
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, l.alpha) + ggx_lambda(wi, l.alpha));
    let dg = ggx_d(h.z, l.alpha) * g2 / (4.0 * wo.z);
    // The specular lobes apart from the broad ones: the coat scales them as narrow lobes, the
    // two parts of Schlick's Fresnel f0 (1 - s^5) + f90 s^5 each by its own factor.
    var narrow_f0 = (opaque * l.dielectric_f0 + l.metallic * l.base) * ((1.0 - s5) * dg);
    var narrow_f90 = vec3<f32>((opaque * l.dielectric_f90 + l.metallic) * s5 * dg);
    let ab_i = ggx_albedo(wi.z, l.alpha);
    let e_i = ab_i.x + ab_i.y;
    var out = vec3<f32>(0.0);
    if l.e_average < 1.0 {
        let ms = opaque * l.ms_dielectric + l.metallic * l.ms_metal;
        out += ms * ((1.0 - l.e_o) * (1.0 - e_i) / (PI * (1.0 - l.e_average)) * wi.z * l.coat_ms_coupling);
    }
    let layer_i = l.dielectric_f0 * ab_i.x + vec3<f32>(l.dielectric_f90 * ab_i.y) + l.ms_dielectric * (1.0 - e_i);
    let transmitted = (vec3<f32>(1.0) - l.layer_o) * (vec3<f32>(1.0) - layer_i);
    let room = vec3<f32>(1.0) - l.layer_average;
    let base_weight = select(vec3<f32>(0.0), transmitted / room, room > vec3<f32>(0.0));
    out += opaque * l.base * base_weight * l.coat_diffuse_coupling * (wi.z / PI);
    if HAS_TRANSMISSION && transmissive > 0.0 {
        // Its exact Fresnel is f90-like: small head-on, all of the reflection at grazing.
        narrow_f90 += vec3<f32>(transmissive * rough_dielectric_eval(l.alpha, l.etap, wo, wi));
    }
    if HAS_SHEEN && max(l.sheen.color.x, max(l.sheen.color.y, l.sheen.color.z)) > 0.0 {
        let sheen = sheen_eval(l.sheen, wo, wi);
        out = sheen.f_cos + sheen.below * out;
        narrow_f0 *= sheen.below;
        narrow_f90 *= sheen.below;
    }
    if HAS_CLEARCOAT && l.coat.weight > 0.0 {
        let coat = clearcoat_eval(l.coat, coat_wo, coat_wi);
        return vec3<f32>(coat.f_cos) + coat.below_broad * out + coat.below_narrow.x * narrow_f0
            + coat.below_narrow.y * narrow_f90;
    }
    return out + narrow_f0 + narrow_f90;
}

// The mixture pdf of pbr_sample; wo and wi in the base's local frame, coat_wo and coat_wi in
// the coat's.
fn pbr_pdf(l: PbrLobes, wo: vec3<f32>, wi: vec3<f32>, coat_wo: vec3<f32>, coat_wi: vec3<f32>) -> f32 {
    if wo.z <= 0.0 {
        return 0.0;
    }
    let p_specular = l.specular_probability;
    let p_transmission = l.transmission_probability;
    var pdf = 0.0;
    if HAS_TRANSMISSION && p_transmission > 0.0 {
        pdf = p_transmission * rough_dielectric_pdf(l.alpha, l.etap, wo, wi);
    }
    if wi.z > 0.0 {
        let p_coat = l.coat_probability;
        let p_sheen = l.sheen_probability;
        pdf += p_specular * ggx_reflection_pdf(wo, wi, l.alpha)
            + (1.0 - p_specular - p_transmission - p_coat - p_sheen) * (wi.z / PI);
        if HAS_CLEARCOAT && p_coat > 0.0 {
            pdf += p_coat * ggx_reflection_pdf(coat_wo, coat_wi, l.coat.alpha);
        }
        if HAS_SHEEN {
            pdf += p_sheen * UNIFORM_HEMISPHERE_PDF;
        }
    }
    return pdf;
}

// `choice` picks the lobe, u the direction; n (the base's shading normal) and coat_n (the
// coat's) face wo.
fn pbr_sample(l: PbrLobes, wo: vec3<f32>, n: vec3<f32>, coat_n: vec3<f32>, choice: f32, u: vec2<f32>) -> BsdfSample {
    var out: BsdfSample;
    out.is_delta = false;
    let wo_l = to_local(wo, n);
    let coat_wo = to_local(wo, coat_n);
    var wi_l: vec3<f32>;
    let p_transmission = l.transmission_probability;
    if HAS_TRANSMISSION && choice < p_transmission {
        let s = rough_dielectric_sample(l.alpha, l.etap, wo_l, u, choice / p_transmission);
        out.dir = normalize(from_local(s.wi, n));
        wi_l = s.wi;
        if s.refracted {
            // Only the transmission lobe reaches below: the mixture's f cos / pdf is the lobe's
            // own weight times its share over its probability (finite at ior 1 too).
            let share = (1.0 - l.metallic) * l.transmission * l.layers_o / p_transmission;
            out.weight = l.base * (s.weight * share);
            out.pdf = p_transmission * rough_dielectric_pdf(l.alpha, l.etap, wo_l, s.wi);
            out.is_delta = l.refraction_is_delta;
            return out;
        }
    } else if choice < p_transmission + l.specular_probability {
        let h = sample_ggx_visible_normal(wo_l, l.alpha, u);
        wi_l = 2.0 * dot(wo_l, h) * h - wo_l;
        out.dir = normalize(from_local(wi_l, n));
    } else if HAS_CLEARCOAT && choice < p_transmission + l.specular_probability + l.coat_probability {
        // The coat's lobe about its own normal.
        let h = sample_ggx_visible_normal(coat_wo, l.coat.alpha, u);
        let coat_wi = 2.0 * dot(coat_wo, h) * h - coat_wo;
        out.dir = normalize(from_local(coat_wi, coat_n));
        wi_l = to_local(out.dir, n);
    } else if HAS_SHEEN
        && choice < p_transmission + l.specular_probability + l.coat_probability + l.sheen_probability {
        wi_l = sample_uniform_hemisphere(u);
        out.dir = normalize(from_local(wi_l, n));
    } else {
        out.dir = sample_cosine_hemisphere(n, u);
        wi_l = to_local(out.dir, n);
    }
    let coat_wi = to_local(out.dir, coat_n);
    out.pdf = pbr_pdf(l, wo_l, wi_l, coat_wo, coat_wi);
    out.weight = vec3<f32>(0.0);
    // A reflection below the surface is absorbed: below, f / pdf counts only the transmission
    // lobe's refractions, whose density alone pbr_pdf gives there.
    if out.pdf > 0.0 && wi_l.z > 0.0 {
        out.weight = pbr_eval(l, wo_l, wi_l, coat_wo, coat_wi) / out.pdf;
    }
    return out;
}
