// The BSDF of each material kind, dispatched to its lobes (mirror: src/cpu/materials/material.rs):
// diffuse.wgsl, conductor.wgsl, dielectric.wgsl, pbr.wgsl (with rough_dielectric.wgsl), on
// microfacet.wgsl and frame.wgsl.

// Material kinds a scene lacks are compiled out (HAS_*, see src/kernel/variant.rs).
fn is_metal(m: Material) -> bool {
    return HAS_METAL && m.kind == MATERIAL_METAL;
}

fn is_dielectric(m: Material) -> bool {
    return HAS_DIELECTRIC && m.kind == MATERIAL_DIELECTRIC;
}

fn is_pbr(m: Material) -> bool {
    return HAS_PBR && m.kind == MATERIAL_PBR;
}

// Mirrors, glass and very smooth metal scatter into single directions: light sampling cannot
// help there, and emitters they see count in full.
fn is_delta(m: Material) -> bool {
    return m.kind == MATERIAL_SPECULAR || is_dielectric(m)
        || (is_metal(m) && m.alpha < MIN_METAL_ALPHA);
}

// Whether light sampling may evaluate the material below its surface: a pbr material with a
// rough transmission lobe (pbr.wgsl's pbr_refraction_is_delta says when it is not rough).
fn transmits_roughly(m: Material) -> bool {
    return HAS_TRANSMISSION && is_pbr(m) && m.transmission > 0.0 && m.metallic < 1.0
        && !pbr_refraction_is_delta(m);
}

// f * cos(theta_i) for light arriving from wi and leaving towards wo (n faces wo; front_face says
// whether that is the outside). Zero for delta lobes, and for wi below the surface except
// through a rough transmission lobe (transmits_roughly), whose light samples' shadow rays leave
// through the surface. coat_n, facing wo too, is the pbr coat's own shading normal
// (KHR_materials_clearcoat's: n itself where nothing tilts it).
fn bsdf_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>, n: vec3<f32>, coat_n: vec3<f32>, front_face: bool) -> vec3<f32> {
    let cos_i = dot(wi, n);
    if cos_i == 0.0 || (cos_i < 0.0 && !transmits_roughly(m)) || is_delta(m) {
        return vec3<f32>(0.0);
    }
    if is_pbr(m) {
        let lobes = pbr_lobes(m, dot(wo, n), dot(wo, coat_n), front_face);
        return pbr_eval(lobes, to_local(wo, n), to_local(wi, n), to_local(wo, coat_n), to_local(wi, coat_n));
    }
    if is_metal(m) {
        return conductor_eval(m.albedo, m.alpha, to_local(wo, n), to_local(wi, n));
    }
    return diffuse_eval(m.albedo, cos_i);
}

// The solid-angle pdf with which bsdf_sample returns wi.
fn bsdf_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>, n: vec3<f32>, coat_n: vec3<f32>, front_face: bool) -> f32 {
    if is_delta(m) {
        return 0.0;
    }
    if is_pbr(m) {
        let lobes = pbr_lobes(m, dot(wo, n), dot(wo, coat_n), front_face);
        return pbr_pdf(lobes, to_local(wo, n), to_local(wi, n), to_local(wo, coat_n), to_local(wi, coat_n));
    }
    if is_metal(m) {
        return ggx_reflection_pdf(to_local(wo, n), to_local(wi, n), m.alpha);
    }
    return max(dot(wi, n), 0.0) / PI;
}

// Samples the direction light arrives from, for light leaving towards wo. `n` and `coat_n`
// face wo (as for bsdf_eval); `front_face` says whether that is the outside (for glass and
// transmission).
fn bsdf_sample(m: Material, wo: vec3<f32>, n: vec3<f32>, coat_n: vec3<f32>, front_face: bool, rng: ptr<function, Rng>) -> BsdfSample {
    if m.kind == MATERIAL_SPECULAR {
        var out: BsdfSample;
        out.pdf = 0.0;
        out.is_delta = true;
        out.dir = normalize(reflect(-wo, n));
        out.weight = m.albedo;
        return out;
    }
    if is_dielectric(m) {
        return dielectric_sample(m.albedo, m.ior, wo, n, front_face, rng);
    }
    let u = vec2<f32>(rng_next(rng), rng_next(rng));
    if is_pbr(m) {
        return pbr_sample(pbr_lobes(m, dot(wo, n), dot(wo, coat_n), front_face), wo, n, coat_n, rng_next(rng), u);
    }
    if is_metal(m) {
        return conductor_sample(m.albedo, m.alpha, wo, n, u);
    }
    return diffuse_sample(m.albedo, n, u);
}
