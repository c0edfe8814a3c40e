//! Path tracing (WGSL side: `shaders/integrator/path.wgsl`).

use crate::cpu::core::camera::camera_ray;
use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::{stream_id, Rng, PURPOSE_BSDF, PURPOSE_LIGHT, PURPOSE_ROULETTE};
use crate::cpu::geometry::alpha::alpha_segment_key;
use crate::cpu::geometry::hit::{Hit, NO_HIT};
use crate::cpu::geometry::intersect::{crosses_shading_side, intersect_scene};
use crate::cpu::geometry::surface::offset_ray_origin;
use crate::cpu::integrator::aov::{aov_record_hit, aov_record_miss, aov_start, aovs_on, PathAov};
use crate::cpu::integrator::path_media::{cross_interface, free_flight, medium_vertex};
use crate::cpu::integrator::volume::volume_transmittance;
use crate::cpu::lights::environment::environment_radiance;
use crate::cpu::lights::light_sample::{nee_weight, power_heuristic, LightSample};
use crate::cpu::lights::punctual::sun_disks_radiance;
use crate::cpu::lights::sampling::{light_pdf, light_visible, sample_light};
use crate::cpu::materials::material::{bsdf_eval, bsdf_pdf, bsdf_sample, is_delta};
use crate::cpu::media::medium::{
    is_interface, medium_crossed, medium_start, shadow_transmittance, MediumStack, TrackingStream,
};
use crate::cpu::scene_refs::SceneRefs;
use crate::cpu::textures::normal_map::normal_mapped;
use crate::cpu::textures::texture::material_at;
use crate::cpu::textures::vertex_color::vertex_colored;
use crate::kernel::types::{
    Material, Params, NO_TEXTURE, PRIMITIVE_ENVIRONMENT, PRIMITIVE_TRIANGLE,
};
use glam::Vec3;

/// A path in flight: what one more segment needs.
#[derive(Clone, Copy, Debug)]
pub struct PathState {
    pub ray: Ray,
    pub throughput: Vec3,
    pub radiance: Vec3,
    /// The surface point the current ray left from (light pdfs are evaluated there).
    pub ray_start: Vec3,
    /// How the current ray was sampled, for weighting the emitter it may hit.
    pub bsdf_pdf_of_ray: f32,
    /// Segments traced so far: each has its own random streams and alpha key.
    pub bounce: u32,
    /// Interfaces crossed so far (`cross_interface`): segments without a scattering event.
    pub crossings: u32,
    pub came_from_delta: bool,
    /// Albedo, normal and depth for the denoiser (aov.rs); untouched unless `params.aovs`.
    pub aov: PathAov,
    /// The participating media the ray is in (media/medium.rs); empty without media.
    pub media: MediumStack,
}

impl PathState {
    /// Scattering events so far, at surfaces and in media: what `max_bounces`, Russian
    /// roulette and the firefly clamp count. Interfaces crossed are not among them, as in
    /// pbrt-v4's and Mitsuba 3's volumetric path tracers and in bdpt's subpaths.
    pub fn scatterings(&self) -> u32 {
        self.bounce - self.crossings
    }
}

/// Firefly clamp (`--clamp`, biased): light that has scattered at least once contributes at
/// most `params.radiance_clamp` in its brightest channel, hue kept; 0 turns it off.
pub fn firefly_clamp(params: &Params, contribution: Vec3, scatterings: u32) -> Vec3 {
    let peak = contribution.x.max(contribution.y.max(contribution.z));
    if scatterings > 0 && params.radiance_clamp > 0.0 && peak > params.radiance_clamp {
        return contribution * (params.radiance_clamp / peak);
    }
    contribution
}

pub fn start_path(params: &Params, pixel: u32, px: u32, py: u32, sample: u32) -> PathState {
    let mut camera_rng = Rng::with_sampler(pixel, sample, 0, params.seed, params.sampler);
    let jitter = (camera_rng.next_f32(), camera_rng.next_f32());
    let lens = (camera_rng.next_f32(), camera_rng.next_f32());
    let ray = camera_ray(params, px, py, jitter, lens);
    PathState {
        ray,
        throughput: Vec3::ONE,
        radiance: Vec3::ZERO,
        ray_start: ray.origin,
        bsdf_pdf_of_ray: 0.0,
        bounce: 0,
        crossings: 0,
        came_from_delta: true,
        aov: aov_start(),
        media: medium_start(params),
    }
}

/// Traces one segment of the path (and its shadow ray); true when the path has ended.
/// `segments` counts the ray segments traced, as the kernel's counter does. `MEDIA` is the
/// kernel's HAS_MEDIA, true only for scenes with media (`params.medium_count > 0`): compiled
/// out like the kernel's, media's branches cost media-free scenes nothing (without it, they
/// changed how the compiler inlined this function's steps, and cost the Cornell box ~2%).
pub fn path_step<const MEDIA: bool>(
    scene: &SceneRefs,
    path: &mut PathState,
    pixel: u32,
    sample: u32,
    segments: &mut u32,
) -> bool {
    let params = scene.params;
    let ray = path.ray;
    let bounce = path.bounce;
    let light_sampling = params.light_sampling != 0 && params.emitter_count > 0;
    // This segment's alpha decisions (alpha.rs): segment `bounce`, the one the ray leaving the
    // previous vertex (or the camera) opened. A copy only where alpha is read at all.
    let keyed;
    let scene = if scene.has_alpha() {
        keyed = scene.with_alpha_key(alpha_segment_key(params, pixel, sample, bounce));
        &keyed
    } else {
        scene
    };
    let mut hit = intersect_scene(&scene.geometry, &ray);
    *segments += 1;
    // The kernel compiles media in only for scenes that have them (HAS_MEDIA).
    if MEDIA {
        let flight = free_flight(scene, path, hit.t, pixel, sample);
        if flight.scattered {
            let position = ray.origin + flight.t * ray.dir;
            return medium_vertex(
                scene,
                path,
                position,
                light_sampling,
                pixel,
                sample,
                segments,
            );
        }
        if path.throughput == Vec3::ZERO {
            return true;
        }
    }
    if hit.t == NO_HIT {
        add_escaped_light(scene, path, light_sampling);
        return true;
    }
    // The material as stored, unless textures or vertex colours change it at this hit (the
    // kernel's HAS_TEXTURES and HAS_VERTEX_COLORS): a 160-byte copy per hit otherwise.
    let stored = &scene.materials[hit.material as usize];
    let varied;
    let m = if scene.textures.is_empty() && scene.triangle_colors.is_empty() {
        stored
    } else {
        varied = vertex_colored(
            scene.triangle_colors,
            &material_at(&scene.textures(), stored, hit.uv),
            &hit,
        );
        &varied
    };
    let coat_normal = apply_normal_maps(scene, m, &mut hit, -ray.dir);
    if aovs_on(params) {
        aov_record_hit(&mut path.aov, bounce, &hit, m);
    }
    // The kernel compiles this in only for scenes with attenuating volumes (HAS_VOLUME).
    if !hit.front_face {
        path.throughput *= volume_transmittance(m, hit.t);
    }
    add_hit_emission(scene, path, m, &hit, light_sampling);
    // Before the bounce limit: a path that has scattered max_bounces times still leaves
    // through the interfaces around it, to the light beyond.
    if MEDIA && is_interface(m) {
        return cross_interface(scene, path, &hit);
    }
    // max_bounces counts scattering events (`PathState::scatterings`).
    if path.scatterings() >= params.max_bounces {
        return true;
    }
    let vertex = Vertex {
        material: m,
        hit: &hit,
        coat_normal,
        origin: offset_ray_origin(hit.position, hit.error, hit.normal),
    };
    if light_sampling && !is_delta(m) {
        add_light_sample::<MEDIA>(scene, path, &vertex, pixel, sample, segments);
    }
    scatter::<MEDIA>(params, path, &vertex, pixel, sample)
}

/// A scattering vertex: the material there, the hit with its mapped shading normal, the coat's
/// own normal and the origin of rays leaving on the geometric normal's side.
struct Vertex<'a> {
    material: &'a Material,
    hit: &'a Hit,
    coat_normal: Vec3,
    origin: Vec3,
}

/// The MIS weight of the light that a BSDF-sampled ray reaches on emitter (primitive, index),
/// against light sampling from the vertex the ray left: 1 where light sampling is off or could
/// not have found the ray (it left a delta lobe).
fn bsdf_ray_mis_weight(
    scene: &SceneRefs,
    path: &PathState,
    primitive: u32,
    index: u32,
    light_sampling: bool,
) -> f32 {
    if light_sampling && !path.came_from_delta {
        let ray = path.ray;
        let pdf = light_pdf(scene, path.ray_start, ray.origin, ray.dir, primitive, index);
        return power_heuristic(path.bsdf_pdf_of_ray, pdf);
    }
    1.0
}

/// The path's ray left the scene: the background or the environment map, and the sun disks,
/// weighted against next-event estimation from the previous vertex.
fn add_escaped_light(scene: &SceneRefs, path: &mut PathState, light_sampling: bool) {
    let params = scene.params;
    let ray = path.ray;
    // The kernel compiles the map in only for scenes that have one (HAS_ENVIRONMENT).
    let mut escaped = Vec3::from(params.background);
    if params.environment_width > 0 {
        escaped = environment_radiance(scene, ray.dir);
    }
    if aovs_on(params) {
        aov_record_miss(&mut path.aov, escaped);
    }
    if params.environment_width > 0 {
        // The map is an emitter like the others: a BSDF-sampled ray that reaches it
        // shares its light with next-event estimation from the previous vertex.
        escaped *= bsdf_ray_mis_weight(scene, path, PRIMITIVE_ENVIRONMENT, 0, light_sampling);
    }
    // The kernel compiles sun disks in only for scenes that have one (HAS_SUN_DISKS).
    if params.light_count > 0 {
        let mis = light_sampling && !path.came_from_delta;
        escaped += sun_disks_radiance(scene, ray.dir, path.bsdf_pdf_of_ray, mis);
    }
    path.radiance += firefly_clamp(params, path.throughput * escaped, path.scatterings());
}

/// The material's normal maps at a triangle hit: the base's replaces `hit`'s shading normal;
/// returns the pbr coat's own shading normal (KHR_materials_clearcoat): its
/// clearcoatNormalTexture, else the unmapped one, since the base's normal map does not reach
/// it. That one is normalised again as the kernel does (shaders/integrator/path.wgsl says
/// why), where there is a coat: nothing else reads it.
pub fn apply_normal_maps(scene: &SceneRefs, m: &Material, hit: &mut Hit, wo: Vec3) -> Vec3 {
    let mut coat_normal = hit.shading_normal;
    if m.clearcoat > 0.0 {
        coat_normal = coat_normal.normalize();
    }
    if hit.primitive == PRIMITIVE_TRIANGLE {
        if m.clearcoat > 0.0 && m.clearcoat_normal_texture != NO_TEXTURE {
            coat_normal = normal_mapped(
                &scene.textures(),
                hit,
                m.clearcoat_normal_texture,
                m.clearcoat_normal_scale,
                &scene.triangle_tangents[hit.index as usize],
                wo,
            );
        }
        if m.normal_texture != NO_TEXTURE {
            hit.shading_normal = normal_mapped(
                &scene.textures(),
                hit,
                m.normal_texture,
                m.normal_scale,
                &scene.triangle_tangents[hit.index as usize],
                wo,
            );
        }
    }
    coat_normal
}

/// The light the hit surface emits towards the path. An emitter hit by a BSDF-sampled ray
/// shares its light with next-event estimation from the previous vertex; camera rays and delta
/// bounces count in full.
fn add_hit_emission(
    scene: &SceneRefs,
    path: &mut PathState,
    m: &Material,
    hit: &Hit,
    light_sampling: bool,
) {
    let emission = Vec3::from(m.emission);
    if emission.cmpgt(Vec3::ZERO).any() {
        let weight = bsdf_ray_mis_weight(scene, path, hit.primitive, hit.index, light_sampling);
        path.radiance += firefly_clamp(
            scene.params,
            path.throughput * emission * weight,
            path.scatterings(),
        );
    }
}

/// Next-event estimation: light arriving after one more scattering event, through a shadow
/// ray, weighted against BSDF sampling.
fn add_light_sample<const MEDIA: bool>(
    scene: &SceneRefs,
    path: &mut PathState,
    vertex: &Vertex,
    pixel: u32,
    sample: u32,
    segments: &mut u32,
) {
    let params = scene.params;
    let hit = vertex.hit;
    let stream = stream_id(path.bounce, PURPOSE_LIGHT);
    let mut light_rng = Rng::with_sampler(pixel, sample, stream, params.seed, params.sampler);
    let light = sample_light(scene, hit.position, vertex.origin, &mut light_rng);
    if light.pdf > 0.0 && !crosses_shading_side(light.dir, hit) {
        add_unblocked_light::<MEDIA>(scene, path, vertex, &light, pixel, sample, segments);
    }
}

/// The sampled light's contribution if the BSDF passes it and nothing blocks the shadow ray.
fn add_unblocked_light<const MEDIA: bool>(
    scene: &SceneRefs,
    path: &mut PathState,
    vertex: &Vertex,
    light: &LightSample,
    pixel: u32,
    sample: u32,
    segments: &mut u32,
) {
    let params = scene.params;
    let (m, hit) = (vertex.material, vertex.hit);
    let bounce = path.bounce;
    let wo = -path.ray.dir;
    let f_cos = bsdf_eval(
        m,
        wo,
        light.dir,
        hit.shading_normal,
        vertex.coat_normal,
        hit.front_face,
    );
    if !f_cos.cmpgt(Vec3::ZERO).any() {
        return;
    }
    // A light behind a rough transmissive surface (bsdf_eval passes it only there) is reached
    // through the surface itself: the shadow ray starts on its far side, so that this surface
    // does not block it while every other one (a closed object's far wall) still does.
    let origin = if light.dir.dot(hit.normal) < 0.0 {
        offset_ray_origin(hit.position, hit.error, -hit.normal)
    } else {
        vertex.origin
    };
    let shadow = Ray {
        origin,
        dir: light.dir,
    };
    *segments += 1;
    // The shadow ray leaves this vertex as the next bounce's ray will: the same segment's key,
    // so both see the same blended triangles.
    let keyed;
    let shadow_scene = if scene.has_alpha() {
        let key = alpha_segment_key(params, pixel, sample, bounce + 1);
        keyed = scene.with_alpha_key(key);
        &keyed
    } else {
        scene
    };
    // Through participating media the light arrives attenuated, through interfaces too (the
    // kernel's HAS_MEDIA); else it is seen or not, and `through` stays 1.
    let mut through = Vec3::ONE;
    if MEDIA {
        let mut media = path.media;
        if light.dir.dot(hit.normal) < 0.0 {
            media = medium_crossed(params, &media, hit.material, hit.front_face);
        }
        let tracking = TrackingStream {
            pixel,
            sample,
            bounce,
        };
        through = shadow_transmittance(shadow_scene, &shadow, light, &media, segments, tracking);
        if !through.cmpgt(Vec3::ZERO).any() {
            return;
        }
    } else if !light_visible(shadow_scene, &shadow, light) {
        return;
    }
    let pdf = bsdf_pdf(
        m,
        wo,
        light.dir,
        hit.shading_normal,
        vertex.coat_normal,
        hit.front_face,
    );
    let weight = nee_weight(light, pdf);
    let contribution = path.throughput * f_cos * light.radiance * (weight / light.pdf) * through;
    path.radiance += firefly_clamp(params, contribution, path.scatterings() + 1);
}

/// Samples the BSDF for the path's next ray, with Russian roulette from
/// `params.roulette_start`; true when the path ends here.
fn scatter<const MEDIA: bool>(
    params: &Params,
    path: &mut PathState,
    vertex: &Vertex,
    pixel: u32,
    sample: u32,
) -> bool {
    let (m, hit) = (vertex.material, vertex.hit);
    let bounce = path.bounce;
    let p = hit.position;
    let wo = -path.ray.dir;
    let mut bsdf_rng = Rng::with_sampler(
        pixel,
        sample,
        stream_id(bounce, PURPOSE_BSDF),
        params.seed,
        params.sampler,
    );
    let s = bsdf_sample(
        m,
        wo,
        hit.shading_normal,
        vertex.coat_normal,
        hit.front_face,
        &mut bsdf_rng,
    );
    let mut throughput = path.throughput * s.weight;
    if throughput == Vec3::ZERO || crosses_shading_side(s.dir, hit) {
        return true;
    }
    // A direction through the surface enters or leaves the medium it bounds (HAS_MEDIA; the
    // kernel does this before the roulette, where its branch costs media-free scenes nothing).
    if MEDIA && s.dir.dot(hit.normal) < 0.0 {
        path.media = medium_crossed(params, &path.media, hit.material, hit.front_face);
    }
    if path.scatterings() >= params.roulette_start {
        // Russian roulette: continue with probability q and divide by it, so the estimate
        // stays unbiased while dim paths end early.
        let mut roulette_rng = Rng::with_sampler(
            pixel,
            sample,
            stream_id(bounce, PURPOSE_ROULETTE),
            params.seed,
            params.sampler,
        );
        let q = throughput.x.max(throughput.y.max(throughput.z)).min(0.95);
        if roulette_rng.next_f32() >= q {
            return true;
        }
        throughput /= q;
    }
    path.throughput = throughput;
    path.came_from_delta = s.is_delta;
    path.bsdf_pdf_of_ray = s.pdf;
    // Leave on the side the new direction goes to.
    let side = if s.dir.dot(hit.normal) >= 0.0 {
        hit.normal
    } else {
        -hit.normal
    };
    path.ray = Ray {
        origin: offset_ray_origin(p, hit.error, side),
        dir: s.dir,
    };
    path.ray_start = p;
    path.bounce = bounce + 1;
    false
}

/// One camera path through pixel (px, py), traced to its end: its radiance, and its AOVs.
pub fn trace_path(
    scene: &SceneRefs,
    pixel: u32,
    px: u32,
    py: u32,
    sample: u32,
    segments: &mut u32,
) -> PathState {
    let mut path = start_path(scene.params, pixel, px, py, sample);
    if scene.params.medium_count > 0 {
        while !path_step::<true>(scene, &mut path, pixel, sample, segments) {}
    } else {
        while !path_step::<false>(scene, &mut path, pixel, sample, segments) {}
    }
    path
}
