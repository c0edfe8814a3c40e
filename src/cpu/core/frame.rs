//! Local shading frames (WGSL side: `shaders/core/frame.wgsl`).

use glam::Vec3;

/// The same f32 as the WGSL literal `3.14159265358979`.
pub use std::f32::consts::PI;

/// Orthonormal basis around a unit `n` (Duff et al., "Building an Orthonormal Basis, Revisited").
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// WGSL's `reflect`.
pub fn reflect(wi: Vec3, n: Vec3) -> Vec3 {
    wi - 2.0 * n.dot(wi) * n
}

pub fn to_local(v: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    Vec3::new(v.dot(t), v.dot(b), v.dot(n))
}

pub fn from_local(v: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    v.x * t + v.y * b + v.z * n
}
