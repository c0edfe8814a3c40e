//! The two subpaths of bidirectional path tracing (WGSL side:
//! `shaders/integrator/bdpt/walk.wgsl`): one random walk, from the camera or from a light,
//! recording each vertex with its throughput and its densities both ways.
//!
//! The camera subpath draws the path tracer's own numbers (its camera stream, and per bounce
//! its BSDF and roulette streams); the light subpath draws streams of its own, numbered from
//! `LIGHT_SUBPATH`. Light carried from a light is importance, not radiance: at each vertex the
//! light subpath weights by the adjoint BSDF, f(wo = the next direction, wi = the previous),
//! with Veach's correction for shading normals, and without the η² that refraction applies
//! to radiance.

use crate::cpu::core::camera::{camera_direction_pdf, camera_ray, film_area};
use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::{
    stream_id, Rng, PURPOSE_BSDF, PURPOSE_FREE_FLIGHT, PURPOSE_LIGHT, PURPOSE_PHASE,
    PURPOSE_ROULETTE,
};
use crate::cpu::geometry::alpha::alpha_segment_key;
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::intersect::{crosses_shading_side, intersect_scene};
use crate::cpu::geometry::surface::offset_ray_origin;
use crate::cpu::integrator::aov::{aov_record_hit, aov_record_miss, aov_start, aovs_on, PathAov};
use crate::cpu::integrator::bdpt::vertex::{
    facing, to_area_density, BdptVertex, VERTEX_CAMERA, VERTEX_LIGHT, VERTEX_MEDIUM, VERTEX_SURFACE,
};
use crate::cpu::integrator::path::apply_normal_maps;
use crate::cpu::integrator::volume::volume_transmittance;
use crate::cpu::lights::emission::{
    infinite_light_radiance, sample_light_origin, EMITTER_AREA, EMITTER_DELTA_DIRECTION,
    EMITTER_INFINITE,
};
use crate::cpu::materials::material::{bsdf_eval, bsdf_pdf, bsdf_sample};
use crate::cpu::media::medium::{
    current_medium, is_interface, medium_crossed, medium_start, sample_flight, transmittance,
    MediumStack,
};
use crate::cpu::media::phase::{hg_phase, sample_hg};
use crate::cpu::scene_refs::SceneRefs;
use crate::cpu::textures::texture::material_at;
use crate::cpu::textures::vertex_color::vertex_colored;
use crate::kernel::types::{Material, NO_GRID, NO_MEDIUM, PROJECTION_ORTHOGRAPHIC};
use glam::Vec3;

/// The most scattering events a bidirectional path may have (`max_bounces` is refused above
/// it): the subpaths live in fixed arrays, in the kernel as here.
pub const BDPT_MAX_BOUNCES: u32 = 24;
/// Vertices of a camera subpath: the camera, and a surface per bounce and one more (an
/// emitter, or the sky).
pub const CAMERA_VERTICES: usize = BDPT_MAX_BOUNCES as usize + 2;
/// Vertices of a light subpath: the light and a surface per bounce.
pub const LIGHT_VERTICES: usize = BDPT_MAX_BOUNCES as usize + 1;

/// The first "bounce" of the light subpath's streams: far above any camera bounce.
pub const LIGHT_SUBPATH: u32 = 1 << 16;
/// The alpha-test segments of light subpaths and of connections (below them: the camera
/// subpath's, numbered as the path tracer numbers its own).
pub const LIGHT_SEGMENTS: u32 = 1 << 8;
pub const CONNECTION_SEGMENTS: u32 = 1 << 9;

/// Which pixel sample a walk belongs to, for its random numbers and alpha decisions.
#[derive(Clone, Copy, Debug)]
pub struct SampleId {
    pub pixel: u32,
    pub px: u32,
    pub py: u32,
    pub sample: u32,
}

pub fn blank_vertex() -> BdptVertex {
    BdptVertex {
        kind: VERTEX_SURFACE,
        emitter: EMITTER_AREA,
        hit: crate::cpu::integrator::bdpt::walk::empty_hit(),
        coat_normal: Vec3::Z,
        material: Material::default(),
        dir: Vec3::Z,
        beta: Vec3::ZERO,
        emitted: Vec3::ZERO,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
        media: MediumStack::default(),
        g: 0.0,
    }
}

pub fn empty_hit() -> crate::cpu::geometry::hit::Hit {
    crate::cpu::geometry::hit::Hit {
        t: NO_HIT,
        position: Vec3::ZERO,
        error: Vec3::ZERO,
        normal: Vec3::Z,
        shading_normal: Vec3::Z,
        material: 0,
        front_face: true,
        primitive: 0,
        index: 0,
        uv: glam::Vec4::ZERO,
        barycentrics: Vec3::ZERO,
    }
}

/// The scene with the alpha decisions of segment `segment` of this sample.
fn keyed<'a>(scene: &SceneRefs<'a>, id: SampleId, segment: u32) -> SceneRefs<'a> {
    if scene.has_alpha() {
        let key = alpha_segment_key(scene.params, id.pixel, id.sample, segment);
        return scene.with_alpha_key(key);
    }
    *scene
}

/// A walk's state between vertices: the ray leaving the last vertex, drawn with solid-angle
/// density `pdf_dir`, the throughput, the media the ray is in, and the number of segments
/// traced so far (each has its own random streams and alpha key; an interface crossed is a
/// segment without a vertex).
#[derive(Clone, Copy)]
struct Walk {
    ray: Ray,
    beta: Vec3,
    pdf_dir: f32,
    media: MediumStack,
    segment: u32,
}

/// Segments a walk traces at most: every vertex's, and interfaces between them.
pub fn segment_limit(max_vertices: usize) -> u32 {
    4 * max_vertices as u32 + 8
}

/// Follows the walk from `path[count - 1]`, adding vertices until `max_vertices`, an escape or
/// an absorption; returns the number of vertices. `from_light`: a light subpath (importance).
/// In a scene with media, each segment first samples a free flight through the medium it is
/// in (the path tracer's `sample_flight`): a scattering there is a medium vertex.
#[allow(clippy::too_many_arguments)]
fn random_walk(
    scene: &SceneRefs,
    mut walk: Walk,
    path: &mut [BdptVertex],
    mut count: usize,
    max_vertices: usize,
    from_light: bool,
    id: SampleId,
    aov: &mut PathAov,
    segments: &mut u32,
) -> usize {
    let params = scene.params;
    let media_on = params.medium_count > 0;
    let first_bounce = if from_light { LIGHT_SUBPATH } else { 0 };
    while count < max_vertices && walk.segment < segment_limit(max_vertices) {
        // Segment b leaves vertex count - 1 (the camera or the light: b = 0) where no
        // interface was crossed.
        let bounce = walk.segment;
        walk.segment += 1;
        let alpha_segment = if from_light {
            LIGHT_SEGMENTS + bounce
        } else {
            bounce
        };
        let ray = walk.ray;
        let hit_scene = keyed(scene, id, alpha_segment);
        let mut hit = intersect_scene(&hit_scene.geometry, &ray);
        *segments += 1;
        let prev = path[count - 1];
        if media_on {
            let stream = stream_id(first_bounce + bounce, PURPOSE_FREE_FLIGHT);
            let mut rng =
                Rng::with_sampler(id.pixel, id.sample, stream, params.seed, params.sampler);
            let slot = current_medium(params, &walk.media);
            let flight = sample_flight(scene, slot, &ray, hit.t, &mut rng);
            walk.beta *= flight.weight;
            if walk.beta == Vec3::ZERO {
                break;
            }
            if flight.scattered {
                let mut v = blank_vertex();
                v.kind = VERTEX_MEDIUM;
                v.hit.position = ray.origin + flight.t * ray.dir;
                v.g = params.media[slot as usize].g;
                v.media = walk.media;
                v.dir = -ray.dir;
                v.beta = walk.beta;
                v.pdf_fwd = first_vertex_density(scene, &prev, &v, walk.pdf_dir);
                path[count] = v;
                count += 1;
                if count >= max_vertices
                    || !scatter_in_medium(scene, &mut walk, path, count, first_bounce + bounce, id)
                {
                    break;
                }
                continue;
            }
        }
        if hit.t == NO_HIT {
            if !from_light {
                // The sky: a light vertex at infinity, for the camera subpath to end on.
                if aovs_on(params) {
                    aov_record_miss(aov, infinite_light_radiance(scene, ray.dir));
                }
                let mut v = blank_vertex();
                v.kind = VERTEX_LIGHT;
                v.emitter = EMITTER_INFINITE;
                v.dir = -ray.dir;
                v.beta = walk.beta;
                v.pdf_fwd = walk.pdf_dir;
                v.media = walk.media;
                path[count] = v;
                count += 1;
            }
            break;
        }
        let stored = &scene.materials[hit.material as usize];
        let m = vertex_colored(
            scene.triangle_colors,
            &material_at(&scene.textures(), stored, hit.uv),
            &hit,
        );
        let coat_normal = apply_normal_maps(scene, &m, &mut hit, -ray.dir);
        if !from_light && aovs_on(params) {
            aov_record_hit(aov, bounce, &hit, &m);
        }
        if !hit.front_face {
            walk.beta *= volume_transmittance(&m, hit.t);
        }
        if media_on && is_interface(&m) {
            // Not a vertex: the walk goes on in the medium beyond, its direction, density and
            // previous vertex unchanged (the path tracer's `cross_interface`).
            walk.media = medium_crossed(params, &walk.media, hit.material, hit.front_face);
            walk.ray.origin = offset_ray_origin(hit.position, hit.error, -hit.normal);
            continue;
        }
        let mut v = blank_vertex();
        v.kind = VERTEX_SURFACE;
        v.hit = hit;
        v.coat_normal = coat_normal;
        v.material = m;
        v.dir = -ray.dir;
        v.beta = walk.beta;
        v.media = walk.media;
        v.pdf_fwd = first_vertex_density(scene, &prev, &v, walk.pdf_dir);
        path[count] = v;
        count += 1;
        if count >= max_vertices
            || !scatter_at_surface(scene, &mut walk, path, count, from_light, bounce, id)
        {
            break;
        }
    }
    count
}

/// Samples the BSDF at the surface vertex `path[count - 1]` for the walk's next ray (with
/// Russian roulette); false when the walk ends there. `bounce` numbers its streams.
fn scatter_at_surface(
    scene: &SceneRefs,
    walk: &mut Walk,
    path: &mut [BdptVertex],
    count: usize,
    from_light: bool,
    bounce: u32,
    id: SampleId,
) -> bool {
    let params = scene.params;
    let first_bounce = if from_light { LIGHT_SUBPATH } else { 0 };
    let v = path[count - 1];
    let (hit, m, coat_normal) = (v.hit, v.material, v.coat_normal);
    let wo = v.dir;
    let mut bsdf_rng = Rng::with_sampler(
        id.pixel,
        id.sample,
        stream_id(first_bounce + bounce, PURPOSE_BSDF),
        params.seed,
        params.sampler,
    );
    let s = bsdf_sample(
        &m,
        wo,
        hit.shading_normal,
        coat_normal,
        hit.front_face,
        &mut bsdf_rng,
    );
    if s.weight == Vec3::ZERO || crosses_shading_side(s.dir, &hit) {
        return false;
    }
    let weight = if from_light {
        adjoint_weight(&v, wo, s.dir, s.weight, s.pdf, s.is_delta)
    } else {
        s.weight
    };
    // The density of sampling the previous vertex from here, light flowing the other way.
    let mut pdf_rev = 0.0;
    let pdf_dir = if s.is_delta {
        path[count - 1].delta = true;
        0.0
    } else {
        let (n, coat_n, front_face) = facing(&v, s.dir);
        pdf_rev = bsdf_pdf(&m, s.dir, wo, n, coat_n, front_face);
        s.pdf
    };
    let side = if s.dir.dot(hit.normal) >= 0.0 {
        hit.normal
    } else {
        // Through the surface: into or out of the medium it bounds.
        walk.media = medium_crossed(params, &walk.media, hit.material, hit.front_face);
        -hit.normal
    };
    let origin = offset_ray_origin(hit.position, hit.error, side);
    let ray = Ray { origin, dir: s.dir };
    continue_walk(
        scene,
        walk,
        path,
        count,
        (ray, weight, pdf_dir, pdf_rev),
        first_bounce + bounce,
        id,
    )
}

/// Samples the phase function at the medium vertex `path[count - 1]` for the walk's next ray
/// (with Russian roulette); false when the walk ends there. Phase sampling is exact: the
/// weight is 1, and the density back equals the density forth.
fn scatter_in_medium(
    scene: &SceneRefs,
    walk: &mut Walk,
    path: &mut [BdptVertex],
    count: usize,
    stream_bounce: u32,
    id: SampleId,
) -> bool {
    let params = scene.params;
    let v = path[count - 1];
    let stream = stream_id(stream_bounce, PURPOSE_PHASE);
    let mut phase_rng = Rng::with_sampler(id.pixel, id.sample, stream, params.seed, params.sampler);
    let (u1, u2) = (phase_rng.next_f32(), phase_rng.next_f32());
    let travelled = -v.dir;
    let dir = sample_hg(v.g, travelled, u1, u2);
    let pdf = hg_phase(v.g, travelled.dot(dir));
    let ray = Ray {
        origin: v.hit.position,
        dir,
    };
    continue_walk(
        scene,
        walk,
        path,
        count,
        (ray, Vec3::ONE, pdf, pdf),
        stream_bounce,
        id,
    )
}

/// The walk leaves vertex `path[count - 1]` along `next.0` with throughput factor `next.1`,
/// drawn with solid-angle density `next.2` (0: a delta lobe), the reverse density being
/// `next.3`; Russian roulette from `roulette_start`. False when the walk ends here.
fn continue_walk(
    scene: &SceneRefs,
    walk: &mut Walk,
    path: &mut [BdptVertex],
    count: usize,
    next: (Ray, Vec3, f32, f32),
    stream_bounce: u32,
    id: SampleId,
) -> bool {
    let params = scene.params;
    let (ray, weight, pdf_dir, pdf_rev) = next;
    let mut next_beta = walk.beta * weight;
    if next_beta == Vec3::ZERO {
        return false;
    }
    // The segment that arrived here is number walk.segment - 1: the path tracer's bounce.
    if walk.segment > params.roulette_start {
        let mut roulette_rng = Rng::with_sampler(
            id.pixel,
            id.sample,
            stream_id(stream_bounce, PURPOSE_ROULETTE),
            params.seed,
            params.sampler,
        );
        let q = next_beta.x.max(next_beta.y.max(next_beta.z)).min(0.95);
        if roulette_rng.next_f32() >= q {
            return false;
        }
        next_beta /= q;
    }
    let v = path[count - 1];
    let prev = path[count - 2];
    path[count - 2].pdf_rev = to_area_density(pdf_rev, &v, &prev);
    walk.beta = next_beta;
    walk.pdf_dir = pdf_dir;
    walk.ray = ray;
    true
}

/// The area density of a subpath's vertex `v` sampled from `prev` with solid-angle density
/// `pdf_dir`; from a light at infinity, the density across its beam, as pbrt has it.
fn first_vertex_density(scene: &SceneRefs, prev: &BdptVertex, v: &BdptVertex, pdf_dir: f32) -> f32 {
    if prev.is_infinite() {
        return crate::cpu::integrator::bdpt::vertex::light_direction_density(scene, prev, v);
    }
    if prev.kind == VERTEX_CAMERA && scene.params.projection == PROJECTION_ORTHOGRAPHIC {
        return crate::cpu::integrator::bdpt::vertex::density_to(scene, prev, None, v);
    }
    to_area_density(pdf_dir, prev, v)
}

/// The throughput weight of a light subpath's scattering at `v`, which sampled `wi` for light
/// arriving from `wo` (the way it came) with `bsdf_sample`'s `weight` and `pdf`: the adjoint
/// BSDF f(wi, wo) |wi·ns|, corrected for shading normals by |wi·ng| |wo·ns| / (|wo·ng| |wi·ns|)
/// (Veach 1997, §5.3), over the pdf. Delta lobes keep the sample's weight, without the
/// radiance scaling η² their refraction applies.
fn adjoint_weight(
    v: &BdptVertex,
    wo: Vec3,
    wi: Vec3,
    weight: Vec3,
    pdf: f32,
    is_delta: bool,
) -> Vec3 {
    let ng = v.hit.normal;
    let cos_o_geometric = wo.dot(ng).abs();
    if cos_o_geometric == 0.0 {
        return Vec3::ZERO;
    }
    if is_delta {
        let (_, _, front_face) = facing(v, wo);
        if wi.dot(ng) * wo.dot(ng) < 0.0 {
            // Refraction: the sample's weight carries (η_o / η_i)² for radiance; importance
            // does not scale.
            let ior = v.material.ior;
            let eta = if front_face { 1.0 / ior } else { ior };
            return weight / (eta * eta);
        }
        return weight;
    }
    if pdf <= 0.0 {
        return Vec3::ZERO;
    }
    let f_cos_wo = adjoint_f_cos(v, wo, wi);
    f_cos_wo / pdf
}

/// f(wo = `toward`, wi = `from`) |toward · ns| of a light subpath's surface vertex, with
/// Veach's shading-normal correction: what light (importance) arriving from `from` sends
/// towards `toward`, as a throughput factor (at a medium vertex, the phase function).
pub fn adjoint_f_cos(v: &BdptVertex, from: Vec3, toward: Vec3) -> Vec3 {
    if v.kind == VERTEX_MEDIUM {
        return Vec3::splat(hg_phase(v.g, -from.dot(toward)));
    }
    let ng = v.hit.normal;
    let cos_from_geometric = from.dot(ng).abs();
    if cos_from_geometric == 0.0 {
        return Vec3::ZERO;
    }
    let (n, coat_n, front_face) = facing(v, toward);
    // bsdf_eval gives f(toward, from) |from · ns|.
    let f_cos_from = bsdf_eval(&v.material, toward, from, n, coat_n, front_face);
    f_cos_from * (toward.dot(ng).abs() / cos_from_geometric)
}

/// f(wo, wi) |wi · ns| of a camera subpath's surface vertex: radiance from wi sent to wo (at
/// a medium vertex, the phase function).
pub fn radiance_f_cos(v: &BdptVertex, wo: Vec3, wi: Vec3) -> Vec3 {
    if v.kind == VERTEX_MEDIUM {
        return Vec3::splat(hg_phase(v.g, -wo.dot(wi)));
    }
    let (n, coat_n, front_face) = facing(v, wo);
    bsdf_eval(&v.material, wo, wi, n, coat_n, front_face)
}

/// The camera subpath of pixel sample `id`: the camera vertex and up to `max_bounces + 1`
/// surfaces (or the sky). Returns the vertex count.
pub fn camera_subpath(
    scene: &SceneRefs,
    id: SampleId,
    path: &mut [BdptVertex; CAMERA_VERTICES],
    aov: &mut PathAov,
    segments: &mut u32,
) -> usize {
    let params = scene.params;
    let mut camera_rng = Rng::with_sampler(id.pixel, id.sample, 0, params.seed, params.sampler);
    let jitter = (camera_rng.next_f32(), camera_rng.next_f32());
    let lens = (camera_rng.next_f32(), camera_rng.next_f32());
    let ray = camera_ray(params, id.px, id.py, jitter, lens);
    let mut camera = blank_vertex();
    camera.kind = VERTEX_CAMERA;
    camera.hit.position = ray.origin;
    camera.beta = Vec3::ONE;
    // An orthographic camera's direction is fixed: light tracing cannot reach it.
    camera.delta = params.projection == PROJECTION_ORTHOGRAPHIC;
    let pdf_dir = if params.projection == PROJECTION_ORTHOGRAPHIC {
        1.0 / film_area(params)
    } else {
        camera_direction_pdf(params, ray.dir)
    };
    let max_vertices = (params.max_bounces as usize + 2).min(CAMERA_VERTICES);
    camera.media = medium_start(params);
    let walk = Walk {
        ray,
        beta: Vec3::ONE,
        pdf_dir,
        media: camera.media,
        segment: 0,
    };
    path[0] = camera;
    random_walk(scene, walk, path, 1, max_vertices, false, id, aov, segments)
}

/// The light subpath of pixel sample `id`: a light and up to `max_bounces` surfaces. Returns
/// the vertex count (0 when the scene has no light to start from).
pub fn light_subpath(
    scene: &SceneRefs,
    id: SampleId,
    path: &mut [BdptVertex; LIGHT_VERTICES],
    segments: &mut u32,
) -> usize {
    let params = scene.params;
    let mut origin_rng = Rng::with_sampler(
        id.pixel,
        id.sample,
        stream_id(LIGHT_SUBPATH, PURPOSE_LIGHT),
        params.seed,
        params.sampler,
    );
    let origin = sample_light_origin(scene, &mut origin_rng);
    if origin.pdf_position <= 0.0 || origin.pdf_direction <= 0.0 || origin.emitted == Vec3::ZERO {
        return 0;
    }
    let mut light = blank_vertex();
    light.kind = VERTEX_LIGHT;
    light.emitter = origin.kind;
    light.hit = origin.hit;
    light.dir = origin.dir;
    light.emitted = origin.emitted;
    light.material.emission = origin.emitted.into();
    // At infinity, the density of the direction (for a sun without a disk, its selection):
    // what connecting to it divides by, and what a camera path escaping there compares.
    light.pdf_fwd = if origin.kind == EMITTER_INFINITE || origin.kind == EMITTER_DELTA_DIRECTION {
        origin.pdf_direction
    } else {
        origin.pdf_position
    };
    let cos = if origin.kind == EMITTER_AREA {
        origin.hit.normal.dot(origin.dir).abs()
    } else {
        1.0
    };
    light.beta = origin.emitted / origin.pdf_position;
    path[0] = light;
    let max_vertices = (params.max_bounces as usize + 1).min(LIGHT_VERTICES);
    if max_vertices < 2 {
        return 1;
    }
    let beta = origin.emitted * (cos / (origin.pdf_position * origin.pdf_direction));
    let start = if origin.kind == EMITTER_AREA {
        offset_ray_origin(origin.hit.position, origin.hit.error, origin.hit.normal)
    } else {
        origin.hit.position
    };
    let ray = Ray {
        origin: start,
        dir: origin.dir,
    };
    let mut unused_aov = aov_start();
    let walk = Walk {
        ray,
        beta: beta * light_media_transmittance(scene, origin.kind),
        pdf_dir: origin.pdf_direction,
        media: MediumStack::default(),
        segment: 0,
    };
    random_walk(
        scene,
        walk,
        path,
        1,
        max_vertices,
        true,
        id,
        &mut unused_aov,
        segments,
    )
}

/// Light subpaths start in the global medium (an empty stack): emitters are taken to lie
/// outside every medium an object bounds (a light inside a fogged box would start its walk
/// in the global medium instead; connections, traced from the camera side, are right
/// regardless). Light from infinity crosses a homogeneous global medium of infinite extent,
/// as the path tracer's shadow rays to it do: its transmittance is 0 in every channel that
/// attenuates.
fn light_media_transmittance(scene: &SceneRefs, kind: u32) -> Vec3 {
    let params = scene.params;
    if params.medium_count == 0 || (kind != EMITTER_INFINITE && kind != EMITTER_DELTA_DIRECTION) {
        return Vec3::ONE;
    }
    let slot = current_medium(params, &MediumStack::default());
    if slot == NO_MEDIUM || params.media[slot as usize].grid != NO_GRID {
        return Vec3::ONE;
    }
    transmittance(Vec3::from(params.media[slot as usize].sigma_t), NO_HIT)
}
