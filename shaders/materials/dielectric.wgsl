// Smooth glass: Fresnel reflection or Snell refraction (mirror: src/cpu/materials/dielectric.rs).

// Unpolarised Fresnel reflectance of a dielectric interface; eta = eta_incident / eta_transmitted,
// cos_i > 0. Total internal reflection gives 1.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

// `front_face` says whether wo is on the outside; n faces wo.
fn dielectric_sample(tint: vec3<f32>, ior: f32, wo: vec3<f32>, n: vec3<f32>, front_face: bool, rng: ptr<function, Rng>) -> BsdfSample {
    var out: BsdfSample;
    out.pdf = 0.0;
    out.is_delta = true;
    let cos_o = dot(wo, n);
    // Reflect with the Fresnel probability, else refract: the weights F / F and
    // (1 - F) / (1 - F) cancel, leaving the tint and the radiance scaling eta^2.
    let eta = select(ior, 1.0 / ior, front_face);
    let reflectance = fresnel_dielectric(cos_o, eta);
    if rng_next(rng) < reflectance {
        out.dir = normalize(reflect(-wo, n));
        out.weight = vec3<f32>(1.0);
        return out;
    }
    let sin2_t = eta * eta * max(0.0, 1.0 - cos_o * cos_o);
    let cos_t = sqrt(max(0.0, 1.0 - sin2_t));
    out.dir = normalize(-eta * wo + (eta * cos_o - cos_t) * n);
    out.weight = tint * (eta * eta);
    return out;
}
