//! Bidirectional path tracing (Veach 1997; WGSL side: `shaders/integrator/bdpt/`). Each pixel
//! sample traces a camera subpath and a light subpath and joins every prefix of one to every
//! prefix of the other (`connect.rs`), each join weighted by the power heuristic over every
//! strategy that could have made its path. Joins that reach the camera from a light vertex
//! (light tracing) land in other pixels: they go to the splat film (`../splat.rs`), which the
//! image adds divided by the samples per pixel.
//!
//! Shared with the path tracer: the camera, the BSDFs, the lights and their pdfs, the
//! traversal; what is bidirectional's own is the vertices (`vertex.rs`), the two walks
//! (`walk.rs`), the joins and their weights.

pub mod connect;
pub mod vertex;
pub mod walk;

use crate::cpu::integrator::aov::PathAov;
use crate::cpu::integrator::bdpt::connect::connect;
use crate::cpu::integrator::bdpt::walk::{
    blank_vertex, camera_subpath, light_subpath, SampleId, CAMERA_VERTICES, LIGHT_VERTICES,
};
use crate::cpu::integrator::path::firefly_clamp;
use crate::cpu::integrator::splat::SplatFilm;
use crate::cpu::scene_refs::SceneRefs;
use glam::Vec3;

/// Which strategies a sample adds: all, weighted (a render), or one (s, t), weighted or not
/// (tests: each alone is an unbiased estimate unweighted, and the weighted ones sum to the
/// image).
#[derive(Clone, Copy, Debug)]
pub struct Strategies {
    pub only: Option<(usize, usize)>,
    pub weighted: bool,
}

pub const ALL_STRATEGIES: Strategies = Strategies {
    only: None,
    weighted: true,
};

/// One bidirectional sample of pixel `id`: the radiance of its camera-side strategies, its
/// light tracing splatted into `film`. `aov` records the camera subpath's first surface.
pub fn bdpt_sample(
    scene: &SceneRefs,
    id: SampleId,
    film: &SplatFilm,
    aov: &mut PathAov,
    segments: &mut u32,
) -> Vec3 {
    bdpt_sample_strategies(scene, id, film, aov, segments, ALL_STRATEGIES)
}

/// [`bdpt_sample`] with the strategies `strategies` says.
pub fn bdpt_sample_strategies(
    scene: &SceneRefs,
    id: SampleId,
    film: &SplatFilm,
    aov: &mut PathAov,
    segments: &mut u32,
    strategies: Strategies,
) -> Vec3 {
    let params = scene.params;
    let mut camera = [blank_vertex(); CAMERA_VERTICES];
    let mut light = [blank_vertex(); LIGHT_VERTICES];
    let camera_count = camera_subpath(scene, id, &mut camera, aov, segments);
    let light_count = light_subpath(scene, id, &mut light, segments);
    let mut radiance = Vec3::ZERO;
    for t in 1..=camera_count {
        for s in 0..=light_count {
            let scatterings = (s + t) as i64 - 2;
            if (s == 1 && t == 1) || scatterings < 0 || scatterings > params.max_bounces as i64 {
                continue;
            }
            if strategies.only.is_some_and(|only| only != (s, t)) {
                continue;
            }
            let (light_prefix, camera_prefix) = (&light[..light_count], &camera[..camera_count]);
            let c = connect(
                scene,
                light_prefix,
                camera_prefix,
                s,
                t,
                id,
                strategies.weighted,
            );
            let contribution = firefly_clamp(params, c.radiance, scatterings as u32);
            if t == 1 {
                if let Some(view) = c.view {
                    let pixel = view.pixel_y * params.width + view.pixel_x;
                    film.add(pixel, contribution, params.splat_scale);
                }
            } else {
                radiance += contribution;
            }
        }
    }
    radiance
}
