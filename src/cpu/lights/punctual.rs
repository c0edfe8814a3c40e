//! Point, spot and directional (sun) lights (WGSL side: `shaders/lights/punctual.wgsl`; built in
//! `src/scene/light.rs`). Point and spot lights, and suns without a disk, are delta lights:
//! only next-event estimation reaches them (a BSDF-sampled ray never hits them), so their
//! samples carry an MIS weight of 1. A sun with a disk is a cone of directions at infinity,
//! sampled uniformly in its solid angle and seen by rays that escape into it, with MIS like the
//! environment map's.

use crate::cpu::core::frame::{basis, PI};
use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::intersect::{escapes, unoccluded_before};
use crate::cpu::lights::light_sample::{power_heuristic, LightSample};
use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::{Light, LIGHT_SUN, PRIMITIVE_LIGHT};
use glam::Vec3;

/// glTF's spot falloff towards the unit direction `from_light` (light → point):
/// clamp(cos·scale + offset, 0, 1)². Point lights have scale 0 and offset 1: no falloff.
pub fn spot_falloff(l: &Light, from_light: Vec3) -> f32 {
    let cd = Vec3::from(l.direction).dot(from_light);
    let a = (cd * l.spot_scale + l.spot_offset).clamp(0.0, 1.0);
    a * a
}

/// 1 − cos of the angle between two unit vectors, as |a − b|² / 2: accurate for the small
/// angles of a sun's disk, where 1 − a·b cancels.
pub fn one_minus_cos_between(a: Vec3, b: Vec3) -> f32 {
    let d = a - b;
    0.5 * d.dot(d)
}

/// A direction towards light `index` from `p`, picked with `probability`. A sample with no
/// light (outside a spot's cone, or at its very position) has pdf 0.
pub fn sample_punctual(
    scene: &SceneRefs,
    index: u32,
    probability: f32,
    p: Vec3,
    u: (f32, f32),
) -> LightSample {
    let l = &scene.lights[index as usize];
    let mut out = LightSample {
        dir: Vec3::ZERO,
        pdf: 0.0,
        radiance: Vec3::ZERO,
        primitive: PRIMITIVE_LIGHT,
        index,
        is_delta: true,
    };
    if l.kind == LIGHT_SUN {
        let axis = -Vec3::from(l.direction);
        out.radiance = Vec3::from(l.emitted);
        if l.sun_one_minus_cos == 0.0 {
            out.dir = axis;
            out.pdf = probability;
            return out;
        }
        // Uniform in the disk's cone of directions.
        let one_minus_cos = u.0 * l.sun_one_minus_cos;
        let cos_theta = 1.0 - one_minus_cos;
        let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
        let phi = 2.0 * PI * u.1;
        let (t, b) = basis(axis);
        out.dir =
            (sin_theta * phi.cos() * t + sin_theta * phi.sin() * b + cos_theta * axis).normalize();
        out.pdf = probability / (2.0 * PI * l.sun_one_minus_cos);
        out.is_delta = false;
        return out;
    }
    let to_light = Vec3::from(l.position) - p;
    let distance2 = to_light.dot(to_light);
    if distance2 <= 0.0 {
        return out;
    }
    out.dir = to_light / distance2.sqrt();
    let falloff = spot_falloff(l, -out.dir);
    if falloff <= 0.0 {
        return out;
    }
    out.radiance = Vec3::from(l.emitted) * (falloff / distance2);
    out.pdf = probability;
    out
}

/// Whether nothing blocks `shadow` (leaving the shading point along `light.dir`) before light
/// `light.index`: the light's position for a point or spot, the sky for a sun.
pub fn punctual_visible(scene: &SceneRefs, shadow: &Ray, light: &LightSample) -> bool {
    let l = &scene.lights[light.index as usize];
    let geometry = &scene.geometry;
    if l.kind == LIGHT_SUN {
        return escapes(geometry, shadow);
    }
    let t_light = (Vec3::from(l.position) - shadow.origin).dot(shadow.dir);
    unoccluded_before(geometry, shadow, t_light)
}

/// Radiance of the sun disks a ray escaping along `dir` looks into. With `mis`, each is
/// weighted against next-event estimation, which could have sampled the same direction, as
/// the environment map is; `bsdf_pdf` is the ray's own pdf.
pub fn sun_disks_radiance(scene: &SceneRefs, dir: Vec3, bsdf_pdf: f32, mis: bool) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for l in &scene.lights[..scene.params.light_count as usize] {
        if l.kind != LIGHT_SUN || l.sun_one_minus_cos == 0.0 {
            continue;
        }
        if one_minus_cos_between(dir, -Vec3::from(l.direction)) > l.sun_one_minus_cos {
            continue;
        }
        let mut weight = 1.0;
        if mis {
            let light_pdf = l.light_probability / (2.0 * PI * l.sun_one_minus_cos);
            weight = power_heuristic(bsdf_pdf, light_pdf);
        }
        sum += Vec3::from(l.emitted) * weight;
    }
    sum
}
