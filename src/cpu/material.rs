//! BSDF sampling (WGSL side: `shaders/material.wgsl`).

use super::rng::Rng;
use crate::shader_types::{Material, MATERIAL_SPECULAR};
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

/// Cosine-weighted direction about `n`: pdf = cos θ / π. With the Lambertian BRDF albedo / π
/// the path weight brdf · cos / pdf is exactly the albedo.
pub fn sample_cosine_hemisphere(n: Vec3, u: (f32, f32)) -> Vec3 {
    let r = u.0.sqrt();
    let phi = 2.0 * PI * u.1;
    let x = r * phi.cos();
    let y = r * phi.sin();
    let z = (1.0 - u.0).max(0.0).sqrt();
    let (t, b) = basis(n);
    (x * t + y * b + z * n).normalize()
}

/// WGSL's `reflect`.
pub fn reflect(wi: Vec3, n: Vec3) -> Vec3 {
    wi - 2.0 * n.dot(wi) * n
}

pub struct Scatter {
    pub dir: Vec3,
    pub weight: Vec3,
}

/// Samples the next direction at a hit. `n` faces the incoming direction `wi`.
pub fn scatter(m: &Material, wi: Vec3, n: Vec3, rng: &mut Rng) -> Scatter {
    if m.kind == MATERIAL_SPECULAR {
        return Scatter {
            dir: reflect(wi, n),
            weight: Vec3::from(m.albedo),
        };
    }
    let u = (rng.next_f32(), rng.next_f32());
    Scatter {
        dir: sample_cosine_hemisphere(n, u),
        weight: Vec3::from(m.albedo),
    }
}
