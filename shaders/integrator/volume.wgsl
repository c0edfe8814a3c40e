// Beer-Lambert attenuation inside closed meshes (KHR_materials_volume; mirror:
// src/cpu/integrator/volume.rs, which says why a back-face hit is all it takes: volumes are assumed closed,
// neither nested nor overlapping).

// The fraction of radiance that crosses t inside the volume whose boundary material is m; 1
// where the material has no attenuation (attenuation_distance 0, glTF's +infinity).
fn volume_transmittance(m: Material, t: f32) -> vec3<f32> {
    if m.attenuation_distance <= 0.0 {
        return vec3<f32>(1.0);
    }
    // Bounded, so a tiny distance gives 0 * 1e30 = 0 (not NaN) in a colour channel of 1.
    let exponent = min(t / m.attenuation_distance, 1e30);
    // exp2(log2(c) e), with c = 0 (which absorbs everything) apart: log2(0) is -infinity.
    let c = m.attenuation_color;
    let through = exp2(log2(max(c, vec3<f32>(1e-30))) * exponent);
    return select(through, vec3<f32>(0.0), c <= vec3<f32>(0.0));
}
