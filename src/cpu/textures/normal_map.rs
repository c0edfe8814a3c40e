//! Normal maps (WGSL side: `shaders/textures/normal_map.wgsl`): glTF's normalTexture turns the shading
//! normal at a triangle hit, in the frame of the triangle's interpolated vertex tangent, its
//! bitangent and the shading normal. Only the shading normal changes: the geometric normal
//! still decides sides, and the result is kept on the geometric normal's side and made valid
//! for the outgoing direction as interpolated normals are (`shading_normal.rs`).

use crate::cpu::geometry::hit::Hit;
use crate::cpu::geometry::shading_normal::valid_shading_normal;
use crate::cpu::textures::texture::{texture_lookup, Textures};
use crate::kernel::types::TriangleTangents;
use glam::{Vec3, Vec4};

/// The least cosine a mapped normal keeps with the geometric normal before validation.
const MIN_COS: f32 = 1e-3;

/// The shading normal at triangle hit `hit` (seen from `wo`) after the normal map `texture`
/// (the material's normalTexture, or its coat's clearcoatNormalTexture) at `scale`, with the
/// triangle's vertex tangents `t`. glTF's rule: the texel, mapped from [0, 1] to
/// [−1, 1], x and y scaled by the map's scale, is a direction in (tangent, bitangent,
/// normal), the bitangent being sign · normal × tangent. The frame is built on the outward
/// side (the side the tangents were made for) and the result turned to the side seen.
pub fn normal_mapped(
    textures: &Textures,
    hit: &Hit,
    texture: u32,
    scale: f32,
    t: &TriangleTangents,
    wo: Vec3,
) -> Vec3 {
    let b = hit.barycentrics;
    let tangent4 = b.x * Vec4::from(t.t0) + b.y * Vec4::from(t.t1) + b.z * Vec4::from(t.t2);
    let side = if hit.front_face { 1.0 } else { -1.0 };
    let n = side * hit.shading_normal;
    let raw = tangent4.truncate() - tangent4.truncate().dot(n) * n;
    let length = raw.length();
    // NaN too, as the WGSL's comparison.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(length > 1e-12) {
        return hit.shading_normal;
    }
    let tangent = raw / length;
    let sign = if tangent4.w >= 0.0 { 1.0 } else { -1.0 };
    let bitangent = sign * n.cross(tangent);
    let c = texture_lookup(textures, texture, hit.uv) * 2.0 - Vec3::ONE;
    let mapped = (c.x * scale) * tangent + (c.y * scale) * bitangent + c.z * n;
    let mapped_length = mapped.length();
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(mapped_length > 0.0) || !mapped_length.is_finite() {
        return hit.shading_normal;
    }
    let mut shading = side * mapped / mapped_length;
    let cos_g = shading.dot(hit.normal);
    if cos_g < MIN_COS {
        shading = (shading + (MIN_COS - cos_g) * hit.normal).normalize();
    }
    valid_shading_normal(hit.normal, wo, shading)
}
