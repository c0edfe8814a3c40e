// Normal maps (mirror: src/cpu/textures/normal_map.rs): glTF's normalTexture turns the shading normal
// at a triangle hit, in the frame of the triangle's interpolated vertex tangent, its bitangent
// and the shading normal. Only the shading normal changes: the geometric normal still decides
// sides, and the result is kept on the geometric normal's side and made valid for the outgoing
// direction as interpolated normals are (shading_normal.wgsl).

// One per triangle when a material has a normal map (a placeholder otherwise).
@group(0) @binding(28) var<storage, read> triangle_tangents: array<TriangleTangents>;

// The least cosine a mapped normal keeps with the geometric normal before validation.
const NORMAL_MAP_MIN_COS: f32 = 1e-3;

// The shading normal at triangle hit `hit` (seen from wo) after the normal map `texture` (the
// material's, or its coat's) at `scale` (see normal_mapped in src/cpu/textures/normal_map.rs).
fn normal_mapped(hit: Hit, texture: u32, scale: f32, wo: vec3<f32>) -> vec3<f32> {
    let t = triangle_tangents[hit.index];
    let b = hit.barycentrics;
    let tangent4 = b.x * t.t0 + b.y * t.t1 + b.z * t.t2;
    let side = select(-1.0, 1.0, hit.front_face);
    let n = side * hit.shading_normal;
    let raw = tangent4.xyz - dot(tangent4.xyz, n) * n;
    let len = length(raw);
    if !(len > 1e-12) {
        return hit.shading_normal;
    }
    let tangent = raw / len;
    let sign = select(-1.0, 1.0, tangent4.w >= 0.0);
    let bitangent = sign * cross(n, tangent);
    let c = texture_lookup(texture, hit.uv) * 2.0 - vec3<f32>(1.0);
    let mapped = (c.x * scale) * tangent + (c.y * scale) * bitangent + c.z * n;
    let mapped_length = length(mapped);
    if !(mapped_length > 0.0) || mapped_length > F32_MAX {
        return hit.shading_normal;
    }
    var shading = side * mapped / mapped_length;
    let cos_g = dot(shading, hit.normal);
    if cos_g < NORMAL_MAP_MIN_COS {
        shading = normalize(shading + (NORMAL_MAP_MIN_COS - cos_g) * hit.normal);
    }
    return valid_shading_normal(hit.normal, wo, shading);
}
