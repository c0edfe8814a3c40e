//! Where light paths start, and how densely (WGSL side: `shaders/lights/emission.wgsl`): the
//! other half of light sampling, which bidirectional path tracing needs. An emitter is chosen
//! by the same alias table as for next-event estimation (`sampling.rs`), then a point on it and
//! a direction out of it:
//! - quads, spheres and triangles: a point uniform in area and a cosine-weighted direction on
//!   either side, since every emitter emits from both sides (the scene file's rule);
//! - point lights: a direction uniform on the sphere; spots: uniform in the cone of their outer
//!   angle, outside which they emit nothing;
//! - the environment map and the suns, infinitely far away: a direction as next-event
//!   estimation draws it (the light travels the opposite way), and a point uniform on a disk
//!   of the scene's radius facing it (Params' `scene_center`, `scene_radius`), as in pbrt.
//!
//! The densities are those bidirectional path tracing's MIS weights need: the area density of
//! a light path's first vertex (selection included) and the solid-angle density of its
//! direction, both for a sampled origin and for a point a camera path happens to hit.

use crate::cpu::core::frame::{basis, from_local, PI};
use crate::cpu::core::rng::Rng;
use crate::cpu::geometry::hit::Hit;
use crate::cpu::geometry::surface::{parametric_point, sphere_point};
use crate::cpu::geometry::triangle::{
    triangle_normal, triangle_sample_barycentrics, triangle_surface_point,
};
use crate::cpu::lights::environment::{environment_pdf, environment_radiance, sample_environment};
use crate::cpu::lights::punctual::{one_minus_cos_between, spot_falloff};
use crate::cpu::lights::sampling::pick_emitter;
use crate::cpu::scene_refs::SceneRefs;
use crate::cpu::textures::texture::{emission_at, sphere_uv, triangle_uv};
use crate::cpu::textures::vertex_color::vertex_colored_emission;
use crate::kernel::types::{
    Material, LIGHT_SPOT, LIGHT_SUN, PRIMITIVE_ENVIRONMENT, PRIMITIVE_LIGHT, PRIMITIVE_QUAD,
    PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use glam::{Vec3, Vec4};

/// A light vertex on a quad, sphere or triangle.
pub const EMITTER_AREA: u32 = 0;
/// A point or spot light: a position and no area, which no ray can hit.
pub const EMITTER_POINT: u32 = 1;
/// The environment map and the suns with a disk: directions at infinity.
pub const EMITTER_INFINITE: u32 = 2;
/// A sun without a disk: one direction at infinity, which no ray can hit.
pub const EMITTER_DELTA_DIRECTION: u32 = 3;

/// The start of a light path.
#[derive(Clone, Copy, Debug)]
pub struct LightOrigin {
    /// The point (for infinite lights, on the disk the light enters through) as a hit: its
    /// position, rounding error, normal (an area emitter's facing `dir`; the travel direction
    /// for infinite lights), primitive and index, and texture coordinates.
    pub hit: Hit,
    /// The way the light leaves (unit).
    pub dir: Vec3,
    /// What leaves along `dir`: radiance from areas and infinite lights, radiant intensity
    /// from point and spot lights, irradiance from a sun without a disk.
    pub emitted: Vec3,
    /// Area density of the point, the emitter's selection included (point lights: the
    /// selection alone; infinite lights: 1 / (π R²), the disk's).
    pub pdf_position: f32,
    /// Solid-angle density of `dir` (infinite lights: every infinite light's together,
    /// selection included; a sun without a disk: its selection probability).
    pub pdf_direction: f32,
    /// `EMITTER_AREA`, `EMITTER_POINT`, `EMITTER_INFINITE` or `EMITTER_DELTA_DIRECTION`.
    pub kind: u32,
    /// The emitter's material (area emitters), for the emission a camera path would see.
    pub material: u32,
}

fn blank_hit() -> Hit {
    Hit {
        t: 0.0,
        position: Vec3::ZERO,
        error: Vec3::ZERO,
        normal: Vec3::Z,
        shading_normal: Vec3::Z,
        material: 0,
        front_face: true,
        primitive: 0,
        index: 0,
        uv: Vec4::ZERO,
        barycentrics: Vec3::ZERO,
    }
}

/// A cosine-weighted direction about `n` on a side chosen by `u_side` (both sides emit),
/// and its solid-angle density |cos| / (2π).
fn two_sided_cosine(n: Vec3, u_side: f32, u: (f32, f32)) -> (Vec3, f32) {
    let r = u.0.sqrt();
    let phi = 2.0 * PI * u.1;
    let z = (1.0 - u.0).max(0.0).sqrt();
    let side = if u_side < 0.5 { n } else { -n };
    let dir = from_local(Vec3::new(r * phi.cos(), r * phi.sin(), z), side).normalize();
    (dir, z / (2.0 * PI))
}

/// A direction uniform in the cone about `axis` whose 1 − cos θmax is `one_minus_cos_max`.
fn uniform_cone(axis: Vec3, one_minus_cos_max: f32, u: (f32, f32)) -> Vec3 {
    let one_minus_cos = u.0 * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = 2.0 * PI * u.1;
    let (t, b) = basis(axis);
    (sin_theta * phi.cos() * t + sin_theta * phi.sin() * b + cos_theta * axis).normalize()
}

/// 1 − cos of a spot's outer angle, beyond which its falloff is 0 (2 for a point light: the
/// whole sphere).
pub fn spot_one_minus_cos_outer(scene: &SceneRefs, index: u32) -> f32 {
    let l = &scene.lights[index as usize];
    if l.kind != LIGHT_SPOT || l.spot_scale <= 0.0 {
        return 2.0;
    }
    (1.0 + l.spot_offset / l.spot_scale).clamp(0.0, 2.0)
}

/// The point on the scene's disk facing `travel` (the way the light goes) at disk coordinates
/// `u`: where a light path from infinitely far starts.
fn disk_entry(scene: &SceneRefs, travel: Vec3, u: (f32, f32)) -> Hit {
    let params = scene.params;
    let radius = params.scene_radius;
    let r = u.0.sqrt() * radius;
    let phi = 2.0 * PI * u.1;
    let (t, b) = basis(travel);
    let mut hit = blank_hit();
    hit.position =
        Vec3::from(params.scene_center) - radius * travel + r * (phi.cos() * t + phi.sin() * b);
    hit.normal = travel;
    hit.shading_normal = travel;
    hit
}

/// The density of directions at infinity, towards the sky along `dir`, summed over every
/// infinite light (the environment map and the suns with a disk), selection included: the
/// density with which a light path starts from `dir`, and the one with which next-event
/// estimation reaches it.
pub fn infinite_light_pdf(scene: &SceneRefs, dir: Vec3) -> f32 {
    let params = scene.params;
    let mut pdf = 0.0;
    if params.environment_width > 0 {
        pdf += params.environment_light_probability * environment_pdf(scene, dir);
    }
    for l in &scene.lights[..params.light_count as usize] {
        if l.kind == LIGHT_SUN
            && l.sun_one_minus_cos > 0.0
            && one_minus_cos_between(dir, -Vec3::from(l.direction)) <= l.sun_one_minus_cos
        {
            pdf += l.light_probability / (2.0 * PI * l.sun_one_minus_cos);
        }
    }
    pdf
}

/// What arrives along -`dir` from infinity (looking along `dir`): the background or the
/// environment map, and the sun disks there.
pub fn infinite_light_radiance(scene: &SceneRefs, dir: Vec3) -> Vec3 {
    let params = scene.params;
    let mut radiance = Vec3::from(params.background);
    if params.environment_width > 0 {
        radiance = environment_radiance(scene, dir);
    }
    for l in &scene.lights[..params.light_count as usize] {
        if l.kind == LIGHT_SUN
            && l.sun_one_minus_cos > 0.0
            && one_minus_cos_between(dir, -Vec3::from(l.direction)) <= l.sun_one_minus_cos
        {
            radiance += Vec3::from(l.emitted);
        }
    }
    radiance
}

/// The emission of an area emitter's material at a point of it (its texture and vertex
/// colours included), as a camera path hitting it sees it.
fn area_emission(scene: &SceneRefs, m: &Material, hit: &Hit) -> Vec3 {
    let emission = emission_at(&scene.textures(), m, hit.uv);
    if hit.primitive == PRIMITIVE_TRIANGLE {
        return vertex_colored_emission(
            scene.triangle_colors,
            m,
            hit.index,
            hit.barycentrics,
            emission,
        );
    }
    emission
}

/// Samples the start of a light path. Draws, in order: the emitter (two numbers, as
/// `sample_light`), the point (two), the side of a two-sided emitter (one) and the direction
/// (two); the environment map draws two more inside its texel.
pub fn sample_light_origin(scene: &SceneRefs, rng: &mut Rng) -> LightOrigin {
    let mut out = LightOrigin {
        hit: blank_hit(),
        dir: Vec3::Z,
        emitted: Vec3::ZERO,
        pdf_position: 0.0,
        pdf_direction: 0.0,
        kind: EMITTER_AREA,
        material: 0,
    };
    let params = scene.params;
    if params.emitter_count == 0 {
        return out;
    }
    let (u_slot, u_alias) = (rng.next_f32(), rng.next_f32());
    let e = pick_emitter(scene, u_slot, u_alias);
    let u_point = (rng.next_f32(), rng.next_f32());
    let u_side = rng.next_f32();
    let u_dir = (rng.next_f32(), rng.next_f32());
    out.hit.primitive = e.primitive;
    out.hit.index = e.index;
    if e.primitive == PRIMITIVE_ENVIRONMENT {
        let s = sample_environment(scene, u_dir, rng);
        let travel = -s.dir;
        out.hit = disk_entry(scene, travel, u_point);
        out.hit.primitive = PRIMITIVE_ENVIRONMENT;
        out.dir = travel;
        out.emitted = infinite_light_radiance(scene, s.dir);
        out.pdf_position = 1.0 / (PI * params.scene_radius * params.scene_radius);
        out.pdf_direction = infinite_light_pdf(scene, s.dir);
        out.kind = EMITTER_INFINITE;
        return out;
    }
    if e.primitive == PRIMITIVE_LIGHT {
        let l = &scene.lights[e.index as usize];
        if l.kind == LIGHT_SUN {
            let travel = if l.sun_one_minus_cos > 0.0 {
                -uniform_cone(-Vec3::from(l.direction), l.sun_one_minus_cos, u_dir)
            } else {
                Vec3::from(l.direction)
            };
            out.hit = disk_entry(scene, travel, u_point);
            out.hit.primitive = PRIMITIVE_LIGHT;
            out.hit.index = e.index;
            out.dir = travel;
            out.pdf_position = 1.0 / (PI * params.scene_radius * params.scene_radius);
            if l.sun_one_minus_cos > 0.0 {
                out.emitted = infinite_light_radiance(scene, -travel);
                out.pdf_direction = infinite_light_pdf(scene, -travel);
                out.kind = EMITTER_INFINITE;
            } else {
                out.emitted = Vec3::from(l.emitted);
                out.pdf_direction = e.probability;
                out.kind = EMITTER_DELTA_DIRECTION;
            }
            return out;
        }
        let one_minus_cos = spot_one_minus_cos_outer(scene, e.index);
        let axis = if l.kind == LIGHT_SPOT {
            Vec3::from(l.direction)
        } else {
            Vec3::Z
        };
        out.dir = uniform_cone(axis, one_minus_cos, u_dir);
        out.hit.position = Vec3::from(l.position);
        out.hit.normal = out.dir;
        out.hit.shading_normal = out.dir;
        out.emitted = Vec3::from(l.emitted) * spot_falloff(l, out.dir);
        out.pdf_position = e.probability;
        out.pdf_direction = 1.0 / (2.0 * PI * one_minus_cos);
        out.kind = EMITTER_POINT;
        return out;
    }
    let mut hit = blank_hit();
    hit.primitive = e.primitive;
    hit.index = e.index;
    let area;
    if e.primitive == PRIMITIVE_TRIANGLE {
        let tri = &scene.geometry.triangles[e.index as usize];
        let b = triangle_sample_barycentrics(u_point);
        let point = triangle_surface_point(tri, b);
        hit.position = point.position;
        hit.error = point.error;
        hit.normal = triangle_normal(tri);
        hit.material = tri.material;
        hit.barycentrics = b;
        hit.uv = triangle_uv(
            scene.geometry.triangle_uvs,
            scene.geometry.triangle_uvs1,
            e.index,
            b,
        );
        area = tri.area;
    } else if e.primitive == PRIMITIVE_QUAD {
        let q = &scene.geometry.quads[e.index as usize];
        let point = parametric_point(
            Vec3::from(q.corner),
            Vec3::from(q.edge_u),
            Vec3::from(q.edge_v),
            u_point.0,
            u_point.1,
        );
        hit.position = point.position;
        hit.error = point.error;
        hit.normal = Vec3::from(q.normal);
        hit.material = q.material;
        hit.uv = Vec4::new(u_point.0, u_point.1, u_point.0, u_point.1);
        area = q.area;
    } else {
        let s = &scene.geometry.spheres[e.index as usize];
        let z = 1.0 - 2.0 * u_point.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u_point.1;
        let outward = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let point = sphere_point(Vec3::from(s.center), s.radius, outward);
        hit.position = point.position;
        hit.error = point.error;
        hit.normal = outward;
        hit.material = s.material;
        let uv = sphere_uv(outward);
        hit.uv = Vec4::new(uv.x, uv.y, uv.x, uv.y);
        area = 4.0 * PI * s.radius * s.radius;
    }
    let (dir, pdf_direction) = two_sided_cosine(hit.normal, u_side, u_dir);
    // The vertex faces the way its light leaves, as a hit faces the ray that found it.
    hit.front_face = dir.dot(hit.normal) >= 0.0;
    if !hit.front_face {
        hit.normal = -hit.normal;
    }
    hit.shading_normal = hit.normal;
    let m = &scene.materials[hit.material as usize];
    out.emitted = area_emission(scene, m, &hit);
    out.material = hit.material;
    out.hit = hit;
    out.dir = dir;
    out.pdf_position = e.probability / area;
    out.pdf_direction = pdf_direction;
    out.kind = EMITTER_AREA;
    out
}

/// The area density with which `sample_light_origin` starts a light path at a point of the
/// area emitter (primitive, index), selection included: 0 for one the table never picks.
pub fn area_origin_pdf(scene: &SceneRefs, primitive: u32, index: u32) -> f32 {
    let g = &scene.geometry;
    if primitive == PRIMITIVE_TRIANGLE && (index as usize) < g.triangles.len() {
        let tri = &g.triangles[index as usize];
        return tri.light_probability / tri.area;
    }
    if primitive == PRIMITIVE_QUAD {
        let q = &g.quads[index as usize];
        return q.light_probability / q.area;
    }
    if primitive == PRIMITIVE_SPHERE {
        let s = &g.spheres[index as usize];
        return s.light_probability / (4.0 * PI * s.radius * s.radius);
    }
    0.0
}

/// The solid-angle density with which a point light (`index`) sends its light along `dir`.
pub fn point_direction_pdf(scene: &SceneRefs, index: u32, dir: Vec3) -> f32 {
    let l = &scene.lights[index as usize];
    let one_minus_cos = spot_one_minus_cos_outer(scene, index);
    if l.kind == LIGHT_SPOT && one_minus_cos_between(dir, Vec3::from(l.direction)) > one_minus_cos {
        return 0.0;
    }
    1.0 / (2.0 * PI * one_minus_cos)
}

/// The scene's disk radius density, 1 / (π R²).
pub fn disk_pdf(scene: &SceneRefs) -> f32 {
    let r = scene.params.scene_radius;
    1.0 / (PI * r * r)
}
