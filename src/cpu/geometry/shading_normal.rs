//! The shading normal a BSDF sees (WGSL side: `shaders/geometry/shading_normal.wgsl`).
//!
//! An interpolated (or, later, normal-mapped) normal can tilt so far from the geometric one
//! that the direction the light leaves by, wo, lies below it while above the surface itself.
//! Every BSDF is defined for wo above its normal: below it, a microfacet lobe's 1/cos θo
//! explodes while its sampling pdf is 0, so next-event estimation gets light with the full MIS
//! weight and a smooth-shaded metal mesh under an environment map made pixels of 10¹⁰.
//! So, as Cycles does (`ensure_valid_specular_reflection`), the shading normal is rotated
//! towards the geometric normal, in the plane of the two, just far enough that the mirror
//! reflection of wo leaves the surface at an angle t = min(0.9 cos θ_g, 0.01) above it. That
//! also puts wo above the new normal. Only directions near the silhouette change, and all of
//! the BSDF's evaluation, sampling and pdf use the same normal, so they stay consistent.

use glam::Vec3;

/// The shading normal for light leaving towards `wo` (unit, with `wo · geometric` ≥ 0), from
/// `shading` (unit, on the side of the unit `geometric` normal).
pub fn valid_shading_normal(geometric: Vec3, wo: Vec3, shading: Vec3) -> Vec3 {
    let wo_z = wo.dot(geometric);
    let threshold = (0.9 * wo_z).min(0.01);
    let reflected = 2.0 * shading.dot(wo) * shading - wo;
    if reflected.dot(geometric) >= threshold {
        return shading;
    }
    // A frame with the geometric normal as z and the shading normal in the x-z plane; the new
    // normal stays in that plane. Solving 2 (n · wo) n_z − wo_z = t for a unit n gives
    // 4a n_z⁴ − 2b n_z² + c = 0, of whose roots one solves the equation before squaring.
    let tangent = shading - shading.dot(geometric) * geometric;
    let tangent_length = tangent.length();
    if tangent_length <= 0.0 {
        return geometric;
    }
    let x = tangent / tangent_length;
    let wo_x = wo.dot(x);
    let a = wo_x * wo_x + wo_z * wo_z;
    let b = 2.0 * (a + wo_z * threshold);
    let c = (threshold + wo_z) * (threshold + wo_z);
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let n_z2 = if wo_x < 0.0 {
        0.25 * (b + root) / a
    } else {
        0.25 * (b - root) / a
    };
    let n_x = (1.0 - n_z2).max(0.0).sqrt();
    let n_z = n_z2.max(0.0).sqrt();
    (n_x * x + n_z * geometric).normalize()
}
