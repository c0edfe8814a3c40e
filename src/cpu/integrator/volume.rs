//! Beer–Lambert attenuation inside closed meshes (KHR_materials_volume; WGSL side:
//! `shaders/integrator/volume.wgsl`).
//!
//! A ray that hits a surface from inside (its back face) has travelled its whole segment
//! through the volume that surface bounds, so the segment's transmittance is
//! attenuation_color^(t / attenuation_distance). This needs no per-path record of the medium,
//! on the assumption that volumes are closed and neither nest nor overlap: the surface a ray
//! inside one hits first is that volume's own boundary. (A ray that leaves through an open
//! mesh's hole, or a light inside a volume reached by a shadow ray, is not attenuated.)

use crate::kernel::types::Material;
use glam::Vec3;

/// The fraction of radiance that crosses `t` inside the volume whose boundary material is `m`;
/// 1 where the material has no attenuation (`attenuation_distance` 0, glTF's +∞).
pub fn volume_transmittance(m: &Material, t: f32) -> Vec3 {
    if m.attenuation_distance <= 0.0 {
        return Vec3::ONE;
    }
    let color = Vec3::from(m.attenuation_color);
    // Bounded, so a tiny distance gives 0 · 1e30 = 0 (not NaN) in a colour channel of 1.
    let exponent = (t / m.attenuation_distance).min(1e30);
    // exp2(log2(c) e), with c = 0 (which absorbs everything) apart: log2(0) is −∞.
    let channel = |c: f32| {
        if c <= 0.0 {
            0.0
        } else {
            (c.max(1e-30).log2() * exponent).exp2()
        }
    };
    Vec3::new(channel(color.x), channel(color.y), channel(color.z))
}
