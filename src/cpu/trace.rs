//! Path tracing (WGSL side: `shaders/trace.wgsl`).

use super::camera::camera_ray;
use super::intersect::{intersect_scene, offset_ray_origin, NO_HIT};
use super::material::scatter;
use super::rng::Rng;
use super::Ray;
use crate::shader_types::{Material, Params, Quad, Sphere};
use glam::Vec3;

/// The scene as the kernel sees it.
pub struct SceneRefs<'a> {
    pub params: &'a Params,
    pub spheres: &'a [Sphere],
    pub quads: &'a [Quad],
    pub materials: &'a [Material],
}

/// Radiance carried by one camera path through pixel (px, py).
pub fn trace_path(scene: &SceneRefs, pixel: u32, px: u32, py: u32, sample: u32) -> Vec3 {
    let params = scene.params;
    let mut camera_rng = Rng::new(pixel, sample, 0, params.seed);
    let jitter = (camera_rng.next_f32(), camera_rng.next_f32());
    let mut ray = camera_ray(params, px, py, jitter);
    let mut throughput = Vec3::ONE;
    let mut radiance = Vec3::ZERO;
    let background = Vec3::from(params.background);
    // max_bounces counts scattering events.
    for bounce in 0..=params.max_bounces {
        let hit = intersect_scene(scene.spheres, scene.quads, &ray);
        if hit.t == NO_HIT {
            radiance += throughput * background;
            break;
        }
        let m = &scene.materials[hit.material as usize];
        radiance += throughput * Vec3::from(m.emission);
        if bounce == params.max_bounces {
            break;
        }
        let mut rng = Rng::new(pixel, sample, bounce + 1, params.seed);
        let s = scatter(m, ray.dir, hit.normal, &mut rng);
        throughput *= s.weight;
        if throughput == Vec3::ZERO {
            break;
        }
        let p = ray.origin + hit.t * ray.dir;
        // Leave on the side the new direction goes to.
        let side = if s.dir.dot(hit.normal) >= 0.0 {
            hit.normal
        } else {
            -hit.normal
        };
        ray = Ray {
            origin: offset_ray_origin(p, side),
            dir: s.dir,
        };
    }
    radiance
}

/// The kernel's entry point for one pixel: the sum of `params.sample_count` samples starting
/// at `params.sample_start`.
pub fn render_pixel(scene: &SceneRefs, px: u32, py: u32) -> Vec3 {
    let params = scene.params;
    let pixel = py * params.width + px;
    let mut sum = Vec3::ZERO;
    for i in 0..params.sample_count {
        sum += trace_path(scene, pixel, px, py, params.sample_start + i);
    }
    sum
}
