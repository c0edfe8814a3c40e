// The shading normal a BSDF sees (mirror: src/cpu/geometry/shading_normal.rs, which says why). An
// interpolated normal tilted so far that wo lies below it is rotated towards the geometric
// normal, in the plane of the two, until the mirror reflection of wo leaves the surface at
// t = min(0.9 cos(theta_g), 0.01) above it (Cycles' ensure_valid_specular_reflection).

// wo: unit, dot(wo, geometric) >= 0; shading: unit, on the geometric normal's side.
fn valid_shading_normal(geometric: vec3<f32>, wo: vec3<f32>, shading: vec3<f32>) -> vec3<f32> {
    let wo_z = dot(wo, geometric);
    let threshold = min(0.9 * wo_z, 0.01);
    let reflected = 2.0 * dot(shading, wo) * shading - wo;
    if dot(reflected, geometric) >= threshold {
        return shading;
    }
    let tangent = shading - dot(shading, geometric) * geometric;
    let tangent_length = length(tangent);
    if tangent_length <= 0.0 {
        return geometric;
    }
    let x = tangent / tangent_length;
    let wo_x = dot(wo, x);
    let a = wo_x * wo_x + wo_z * wo_z;
    let b = 2.0 * (a + wo_z * threshold);
    let c = (threshold + wo_z) * (threshold + wo_z);
    let root = sqrt(max(b * b - 4.0 * a * c, 0.0));
    let n_z2 = select(0.25 * (b - root) / a, 0.25 * (b + root) / a, wo_x < 0.0);
    let n_x = sqrt(max(1.0 - n_z2, 0.0));
    let n_z = sqrt(max(n_z2, 0.0));
    return normalize(n_x * x + n_z * geometric);
}
