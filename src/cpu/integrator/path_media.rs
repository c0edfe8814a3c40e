//! The path tracer's steps in participating media (WGSL side:
//! `shaders/integrator/path_media.wgsl`): a segment's free flight, scattering at a medium
//! vertex (next-event estimation weighted against phase sampling, then phase sampling), and
//! crossing an interface, which is no scattering event.

use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::{
    stream_id, Rng, PURPOSE_FREE_FLIGHT, PURPOSE_MEDIUM_LIGHT, PURPOSE_PHASE, PURPOSE_ROULETTE,
};
use crate::cpu::geometry::alpha::alpha_segment_key;
use crate::cpu::geometry::hit::Hit;
use crate::cpu::geometry::surface::offset_ray_origin;
use crate::cpu::integrator::path::{firefly_clamp, PathState};
use crate::cpu::lights::light_sample::nee_weight;
use crate::cpu::lights::sampling::sample_light;
use crate::cpu::media::medium::{
    current_medium, medium_crossed, sample_flight, segment_limit, shadow_transmittance, FreeFlight,
    TrackingStream,
};
use crate::cpu::media::phase::{hg_phase, sample_hg};
use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::NO_MEDIUM;
use glam::Vec3;

/// The path's ray travels through its medium towards a surface at `t_hit` (`NO_HIT`: none):
/// where it scatters first, if before the surface, with the throughput weighted.
pub fn free_flight(
    scene: &SceneRefs,
    path: &mut PathState,
    t_hit: f32,
    pixel: u32,
    sample: u32,
) -> FreeFlight {
    let params = scene.params;
    let slot = current_medium(params, &path.media);
    if slot == NO_MEDIUM {
        return FreeFlight {
            t: t_hit,
            weight: Vec3::ONE,
            scattered: false,
        };
    }
    let stream = stream_id(path.bounce, PURPOSE_FREE_FLIGHT);
    let mut rng = Rng::with_sampler(pixel, sample, stream, params.seed, params.sampler);
    let flight = sample_flight(scene, slot, &path.ray, t_hit, &mut rng);
    path.throughput *= flight.weight;
    flight
}

/// A scattering event at `position` in the path's medium: light sampled through the media
/// (weighted against the phase function's sampling), then the next direction from the phase
/// function, with Russian roulette as at a surface; true when the path ends here.
pub fn medium_vertex(
    scene: &SceneRefs,
    path: &mut PathState,
    position: Vec3,
    light_sampling: bool,
    pixel: u32,
    sample: u32,
    segments: &mut u32,
) -> bool {
    let params = scene.params;
    let bounce = path.bounce;
    // A scattering event like a surface's: max_bounces counts it.
    if path.scatterings() >= params.max_bounces {
        return true;
    }
    let g = params.media[current_medium(params, &path.media) as usize].g;
    let d = path.ray.dir;
    if light_sampling {
        let stream = stream_id(bounce, PURPOSE_MEDIUM_LIGHT);
        let mut light_rng = Rng::with_sampler(pixel, sample, stream, params.seed, params.sampler);
        let light = sample_light(scene, position, position, &mut light_rng);
        if light.pdf > 0.0 {
            let phase = hg_phase(g, d.dot(light.dir));
            *segments += 1;
            // The shadow ray leaves as the next segment will: its alpha key (path.rs).
            let keyed;
            let shadow_scene = if scene.has_alpha() {
                keyed = scene.with_alpha_key(alpha_segment_key(params, pixel, sample, bounce + 1));
                &keyed
            } else {
                scene
            };
            let shadow = Ray {
                origin: position,
                dir: light.dir,
            };
            let tracking = TrackingStream {
                pixel,
                sample,
                bounce,
            };
            let through = shadow_transmittance(
                shadow_scene,
                &shadow,
                &light,
                &path.media,
                segments,
                tracking,
            );
            if through.cmpgt(Vec3::ZERO).any() {
                let weight = nee_weight(&light, phase);
                let contribution =
                    path.throughput * through * light.radiance * (phase * weight / light.pdf);
                path.radiance += firefly_clamp(params, contribution, path.scatterings() + 1);
            }
        }
    }
    let stream = stream_id(bounce, PURPOSE_PHASE);
    let mut phase_rng = Rng::with_sampler(pixel, sample, stream, params.seed, params.sampler);
    let (u1, u2) = (phase_rng.next_f32(), phase_rng.next_f32());
    let dir = sample_hg(g, d, u1, u2);
    let pdf = hg_phase(g, d.dot(dir));
    // Phase sampling is exact: the phase function over its pdf is 1.
    let mut throughput = path.throughput;
    if path.scatterings() >= params.roulette_start {
        // The same decision as at a surface (path.rs): continue with probability q.
        let stream = stream_id(bounce, PURPOSE_ROULETTE);
        let mut roulette_rng =
            Rng::with_sampler(pixel, sample, stream, params.seed, params.sampler);
        let q = throughput.x.max(throughput.y.max(throughput.z)).min(0.95);
        if roulette_rng.next_f32() >= q {
            return true;
        }
        throughput /= q;
    }
    path.throughput = throughput;
    path.came_from_delta = false;
    path.bsdf_pdf_of_ray = pdf;
    path.ray = Ray {
        origin: position,
        dir,
    };
    path.ray_start = position;
    path.bounce = bounce + 1;
    false
}

/// The path goes straight through an interface (media/medium.rs's `is_interface`) into the
/// medium beyond. Not a scattering event: the previous vertex's pdf, origin and delta flag
/// stay, so that a light hit beyond is weighted against next-event estimation from that
/// vertex, whose shadow rays cross interfaces too. The segment has random streams of its own
/// but is not counted against max_bounces; the path ends at `segment_limit` segments, as a
/// bdpt camera subpath does. True when the path ends here.
pub fn cross_interface(scene: &SceneRefs, path: &mut PathState, hit: &Hit) -> bool {
    let params = scene.params;
    if path.bounce + 1 >= segment_limit(params.max_bounces + 2) {
        return true;
    }
    path.media = medium_crossed(params, &path.media, hit.material, hit.front_face);
    path.ray = Ray {
        origin: offset_ray_origin(hit.position, hit.error, -hit.normal),
        dir: path.ray.dir,
    };
    path.bounce += 1;
    path.crossings += 1;
    false
}
