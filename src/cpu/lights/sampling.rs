//! Light sampling for next-event estimation (WGSL side: `shaders/lights/sampling.wgsl`). An emitter is
//! chosen in proportion to its power, or by the light tree where the scene has one
//! (`light_tree.rs`), then a direction towards it: quads and triangles by area, spheres by
//! the cone of directions they subtend from outside, and by area from inside, the environment
//! map by luminance (`environment.rs`), point, spot and directional lights in `punctual.rs`.
//! All pdfs are per
//! unit solid angle at the shading point and include the selection probability.

use crate::cpu::core::frame::{basis, PI};
use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::Rng;
use crate::cpu::geometry::intersect::first_hit_is;
use crate::cpu::geometry::triangle::{
    triangle_normal, triangle_plane_distance, triangle_point, triangle_sample_barycentrics,
};
use crate::cpu::lights::environment::{environment_pdf, sample_environment};
use crate::cpu::lights::light_sample::LightSample;
use crate::cpu::lights::light_tree::{light_tree_active, tree_pick, tree_selection_probability};
use crate::cpu::lights::punctual::{punctual_visible, sample_punctual};
use crate::cpu::scene_refs::SceneRefs;
use crate::cpu::textures::texture::{emission_at, triangle_uv};
use crate::cpu::textures::vertex_color::vertex_colored_emission;
use crate::kernel::types::{
    Sphere, LIGHT_SUN, NO_TEXTURE, PRIMITIVE_ENVIRONMENT, PRIMITIVE_LIGHT, PRIMITIVE_QUAD,
    PRIMITIVE_TRIANGLE,
};
use glam::Vec3;

/// The emitter light sampling chose: which primitive, and the probability of choosing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterChoice {
    pub primitive: u32,
    pub index: u32,
    pub probability: f32,
}

/// Selection in proportion to power, in O(1) by the alias table (`src/kernel/scene/emitter_table.rs`): `u`
/// picks the slot, `u_alias` its emitter or the alias. The slot is ⌊u·n⌋ in f32 on both
/// devices (a correctly rounded product, then truncation), so both pick the same emitter.
pub fn pick_emitter(scene: &SceneRefs, u: f32, u_alias: f32) -> EmitterChoice {
    let n = scene.params.emitter_count;
    let slot = &scene.emitters[((u * n as f32) as u32).min(n - 1) as usize];
    if u_alias < slot.alias_threshold {
        return EmitterChoice {
            primitive: slot.primitive,
            index: slot.index,
            probability: slot.probability,
        };
    }
    EmitterChoice {
        primitive: slot.alias_primitive,
        index: slot.alias_index,
        probability: slot.alias_probability,
    }
}

/// The light tree's choice in place of the alias table's `e` (picked with `u_slot`): where
/// every emitter is finite, the tree picks with `u_slot` itself; otherwise the alias table's
/// choice between the infinite lights (kept as it is) and the finite ones stands, and the tree
/// picks among those with one more number. `None` where no finite emitter can light `p`.
fn tree_choice(
    scene: &SceneRefs,
    p: Vec3,
    u_slot: f32,
    e: EmitterChoice,
    rng: &mut Rng,
) -> Option<EmitterChoice> {
    let params = scene.params;
    let u = if params.light_tree_probability >= 1.0 {
        u_slot
    } else {
        let infinite = e.primitive == PRIMITIVE_ENVIRONMENT
            || (e.primitive == PRIMITIVE_LIGHT && scene.lights[e.index as usize].kind == LIGHT_SUN);
        if infinite {
            return Some(e);
        }
        rng.next_f32()
    };
    let (primitive, index, pmf) = tree_pick(scene.light_tree_nodes, p, u)?;
    Some(EmitterChoice {
        primitive,
        index,
        probability: params.light_tree_probability * pmf,
    })
}

/// The probability that next-event estimation at `p` picks the emitting sphere, quad or
/// triangle (primitive, index), whose probability by power is `by_power`.
fn selection_probability(
    scene: &SceneRefs,
    p: Vec3,
    primitive: u32,
    index: u32,
    by_power: f32,
) -> f32 {
    if light_tree_active(scene.params) {
        return tree_selection_probability(scene, p, primitive, index);
    }
    by_power
}

pub fn sphere_contains(s: &Sphere, p: Vec3) -> bool {
    let d = p - Vec3::from(s.center);
    d.dot(d) < s.radius * s.radius
}

/// 1 − cos θmax of the cone a sphere subtends from outside, without cancellation for small,
/// distant spheres: sin² / (1 + cos).
pub fn cone_one_minus_cos(s: &Sphere, p: Vec3) -> f32 {
    let d = Vec3::from(s.center) - p;
    let sin2 = (s.radius * s.radius / d.dot(d)).min(1.0);
    sin2 / (1.0 + (1.0 - sin2).sqrt())
}

/// Leaving a point p inside (or on) a sphere along a unit direction: the distance t to the
/// sphere and the cosine there, from the chord's geometry. With h = dir · (center − p), the
/// exit is at t = h + √(h² + r² − |center − p|²) and the cosine is that square root / r.
/// Keeping r² − |center − p|² apart (clamped at 0, for p on the surface) stays accurate for
/// nearly tangent directions, where h is tiny.
pub fn sphere_chord(s: &Sphere, p: Vec3, dir: Vec3) -> (f32, f32) {
    let oc = Vec3::from(s.center) - p;
    let h = dir.dot(oc);
    let root = (h * h + (s.radius * s.radius - oc.dot(oc)).max(0.0)).sqrt();
    (h + root, root / s.radius)
}

/// Solid-angle pdf of area sampling: distance² / (|cos| at the light · area).
pub fn area_to_solid_angle(t: f32, cos_light: f32, area: f32) -> f32 {
    t * t / (cos_light.abs().max(1e-12) * area)
}

/// Every pdf here is evaluated at the shading point `p` itself, the same way for a light
/// sample and for a BSDF-sampled ray, so the two strategies' MIS weights match. `probe` is `p`
/// moved off the surface to the side light arrives from: it decides whether p is inside a
/// sphere (a point on the sphere itself is ambiguous) and starts the shadow ray.
pub fn sample_light(scene: &SceneRefs, p: Vec3, probe: Vec3, rng: &mut Rng) -> LightSample {
    let mut out = LightSample {
        dir: Vec3::ZERO,
        pdf: 0.0,
        radiance: Vec3::ZERO,
        primitive: 0,
        index: 0,
        is_delta: false,
    };
    if scene.params.emitter_count == 0 {
        return out;
    }
    let (u_slot, u_alias) = (rng.next_f32(), rng.next_f32());
    let mut e = pick_emitter(scene, u_slot, u_alias);
    let u = (rng.next_f32(), rng.next_f32());
    if light_tree_active(scene.params) {
        match tree_choice(scene, p, u_slot, e, rng) {
            Some(choice) => e = choice,
            None => return out,
        }
    }
    out.primitive = e.primitive;
    out.index = e.index;
    if e.primitive == PRIMITIVE_LIGHT {
        return sample_punctual(scene, e.index, e.probability, p, u);
    }
    if e.primitive == PRIMITIVE_ENVIRONMENT {
        let s = sample_environment(scene, u, rng);
        out.dir = s.dir;
        out.pdf = e.probability * s.pdf;
        out.radiance = s.radiance;
        return out;
    }
    if e.primitive == PRIMITIVE_TRIANGLE {
        // Uniform on the triangle's area.
        let tri = &scene.geometry.triangles[e.index as usize];
        let b = triangle_sample_barycentrics(u);
        let to_light = triangle_point(tri, b) - p;
        let t = to_light.length();
        if t <= 0.0 {
            return out;
        }
        out.dir = to_light / t;
        out.pdf =
            e.probability * area_to_solid_angle(t, triangle_normal(tri).dot(out.dir), tri.area);
        // The emission where the sample lies (glTF's emissive texture).
        let m = &scene.materials[tri.material as usize];
        let emission = if m.emission_texture != NO_TEXTURE {
            let uv = triangle_uv(
                scene.geometry.triangle_uvs,
                scene.geometry.triangle_uvs1,
                e.index,
                b,
            );
            emission_at(&scene.textures(), m, uv)
        } else {
            Vec3::from(m.emission)
        };
        out.radiance = vertex_colored_emission(scene.triangle_colors, m, e.index, b, emission);
        return out;
    }
    if e.primitive == PRIMITIVE_QUAD {
        let q = &scene.geometry.quads[e.index as usize];
        let to_light =
            Vec3::from(q.corner) + u.0 * Vec3::from(q.edge_u) + u.1 * Vec3::from(q.edge_v) - p;
        let t = to_light.length();
        if t <= 0.0 {
            return out;
        }
        out.dir = to_light / t;
        out.pdf = e.probability * area_to_solid_angle(t, Vec3::from(q.normal).dot(out.dir), q.area);
        out.radiance = Vec3::from(scene.materials[q.material as usize].emission);
        return out;
    }
    let s = &scene.geometry.spheres[e.index as usize];
    out.radiance = Vec3::from(scene.materials[s.material as usize].emission);
    if sphere_contains(s, probe) {
        // Uniform on the sphere's area; from inside, every direction meets it exactly once.
        let z = 1.0 - 2.0 * u.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u.1;
        let normal = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let to_light = Vec3::from(s.center) + s.radius * normal - p;
        let distance = to_light.length();
        if distance <= 0.0 {
            return out;
        }
        out.dir = to_light / distance;
        // The same formula as light_pdf, so both strategies agree on this direction's pdf.
        let (t, cos_exit) = sphere_chord(s, p, out.dir);
        out.pdf = e.probability * area_to_solid_angle(t, cos_exit, 4.0 * PI * s.radius * s.radius);
        return out;
    }
    // Uniform in the cone of directions towards the sphere.
    let axis = (Vec3::from(s.center) - p).normalize();
    let one_minus_cos_max = cone_one_minus_cos(s, p);
    let one_minus_cos = u.0 * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = 2.0 * PI * u.1;
    let (t, b) = basis(axis);
    out.dir =
        (sin_theta * phi.cos() * t + sin_theta * phi.sin() * b + cos_theta * axis).normalize();
    out.pdf = e.probability / (2.0 * PI * one_minus_cos_max);
    out
}

/// The pdf with which [`sample_light`]`(p, probe)` would have produced `dir`, a direction that
/// meets the emitting primitive (primitive, index).
pub fn light_pdf(
    scene: &SceneRefs,
    p: Vec3,
    probe: Vec3,
    dir: Vec3,
    primitive: u32,
    index: u32,
) -> f32 {
    if primitive == PRIMITIVE_ENVIRONMENT {
        return scene.params.environment_light_probability * environment_pdf(scene, dir);
    }
    if primitive == PRIMITIVE_TRIANGLE {
        let tri = &scene.geometry.triangles[index as usize];
        let normal = triangle_normal(tri);
        let t = triangle_plane_distance(tri, normal, p, dir);
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(t > 0.0) {
            return 0.0;
        }
        let chosen = selection_probability(scene, p, primitive, index, tri.light_probability);
        return chosen * area_to_solid_angle(t, normal.dot(dir), tri.area);
    }
    if primitive == PRIMITIVE_QUAD {
        let q = &scene.geometry.quads[index as usize];
        let normal = Vec3::from(q.normal);
        let cos_light = normal.dot(dir);
        let t = (q.plane_offset - normal.dot(p)) / cos_light;
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(t > 0.0) {
            return 0.0;
        }
        let chosen = selection_probability(scene, p, primitive, index, q.light_probability);
        return chosen * area_to_solid_angle(t, cos_light, q.area);
    }
    let s = &scene.geometry.spheres[index as usize];
    let chosen = selection_probability(scene, p, primitive, index, s.light_probability);
    if sphere_contains(s, probe) {
        let (t, cos_exit) = sphere_chord(s, p, dir);
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(t > 0.0) {
            return 0.0;
        }
        return chosen * area_to_solid_angle(t, cos_exit, 4.0 * PI * s.radius * s.radius);
    }
    chosen / (2.0 * PI * cone_one_minus_cos(s, p))
}

/// Whether a shadow ray along a light sample reaches the light it sampled.
pub fn light_visible(scene: &SceneRefs, shadow: &Ray, light: &LightSample) -> bool {
    if light.primitive == PRIMITIVE_LIGHT {
        return punctual_visible(scene, shadow, light);
    }
    first_hit_is(&scene.geometry, shadow, light.primitive, light.index)
}
