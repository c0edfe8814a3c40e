//! The environment map: its radiance for escaping rays, and importance sampling of it for
//! next-event estimation (WGSL side: `shaders/lights/environment.wgsl`). The conventions and the
//! exact pdf are in `src/scene/environment.rs`, where the tables are built.

use crate::cpu::core::frame::PI;
use crate::cpu::core::rng::Rng;
use crate::cpu::scene_refs::SceneRefs;
use crate::cpu::textures::texture::polynomial_atan2;
use crate::kernel::types::Params;
use glam::Vec3;

/// A scene direction in the map's frame: turned by −rotate about +y.
pub fn to_map_frame(params: &Params, d: Vec3) -> Vec3 {
    let (c, s) = (params.environment_cos, params.environment_sin);
    Vec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
}

/// A direction in the map's frame in the scene: turned by +rotate about +y.
pub fn from_map_frame(params: &Params, d: Vec3) -> Vec3 {
    let (c, s) = (params.environment_cos, params.environment_sin);
    Vec3::new(c * d.x + s * d.z, d.y, c * d.z - s * d.x)
}

/// Index of the texel a unit direction (in the scene) looks at. The angles come from the
/// polynomial atan2 the textures use (not atan2 and acos, which Vulkan lets be 4096 ulps
/// off), so the GPU picks the CPU's texel; θ = atan2(√(x² + z²), y) keeps its precision at
/// the poles, where acos(y) loses it.
pub fn environment_texel_index(params: &Params, dir: Vec3) -> u32 {
    let d = to_map_frame(params, dir);
    let mut u = polynomial_atan2(d.x, -d.z) * (0.5 / PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = polynomial_atan2((d.x * d.x + d.z * d.z).sqrt(), d.y) * (1.0 / PI);
    let (w, h) = (params.environment_width, params.environment_height);
    let x = ((u * w as f32) as u32).min(w - 1);
    let y = ((v * h as f32) as u32).min(h - 1);
    y * w + x
}

/// Radiance arriving from the map along -`dir` (seen looking along `dir`).
pub fn environment_radiance(scene: &SceneRefs, dir: Vec3) -> Vec3 {
    let texel = environment_texel_index(scene.params, dir);
    Vec3::from(scene.environment_texels[texel as usize].radiance)
}

/// Solid-angle pdf with which [`sample_environment`] picks `dir` (selection excluded).
pub fn environment_pdf(scene: &SceneRefs, dir: Vec3) -> f32 {
    let texel = environment_texel_index(scene.params, dir);
    scene.environment_texels[texel as usize].pdf
}

#[derive(Clone, Copy, Debug)]
pub struct EnvironmentSample {
    pub dir: Vec3,
    /// Solid-angle pdf (selection among emitters excluded).
    pub pdf: f32,
    pub radiance: Vec3,
}

/// A direction towards the map, drawn in proportion to luminance: a texel by the alias table
/// (`u.0` picks the entry, `u.1` decides between it and its alias), then uniformly in solid
/// angle within it (`rng`'s next two numbers: φ, then cos θ).
pub fn sample_environment(scene: &SceneRefs, u: (f32, f32), rng: &mut Rng) -> EnvironmentSample {
    let params = scene.params;
    let (w, h) = (params.environment_width, params.environment_height);
    let n = w * h;
    let k = ((u.0 * n as f32) as u32).min(n - 1);
    let entry = scene.environment_alias[k as usize];
    let texel = if u.1 < entry.threshold {
        k
    } else {
        entry.alias_texel
    };
    let (x, y) = (texel % w, texel / w);
    let within = (rng.next_f32(), rng.next_f32());
    let phi = 2.0 * PI * (x as f32 + within.0) / w as f32;
    // cos θ from the texel's top edge down by a uniform share of the row's cos θ extent,
    // 2 sin θ_c sin(π/2H), which keeps its precision near the poles.
    let cos_top = (PI * y as f32 / h as f32).cos();
    let extent = 2.0 * (PI * (y as f32 + 0.5) / h as f32).sin() * (0.5 * PI / h as f32).sin();
    let cos_theta = (cos_top - within.1 * extent).clamp(-1.0, 1.0);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let local = Vec3::new(sin_theta * phi.sin(), cos_theta, -sin_theta * phi.cos());
    let t = scene.environment_texels[texel as usize];
    EnvironmentSample {
        dir: from_map_frame(params, local),
        pdf: t.pdf,
        radiance: Vec3::from(t.radiance),
    }
}
