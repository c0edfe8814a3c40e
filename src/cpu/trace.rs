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

/// Running per-pixel statistics: the mean radiance and M2, the sum of squared deviations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    pub mean: Vec3,
    pub m2: Vec3,
}

/// The kernel's entry point for one pixel: `params.sample_count` samples starting at
/// `params.sample_start`, merged into `stats`, which holds the `params.sample_start` samples
/// before them.
pub fn render_pixel(scene: &SceneRefs, px: u32, py: u32, stats: &mut PixelStats) {
    let params = scene.params;
    let pixel = py * params.width + px;
    // Welford over this batch's samples...
    let mut mean = Vec3::ZERO;
    let mut m2 = Vec3::ZERO;
    for i in 0..params.sample_count {
        let x = trace_path(scene, pixel, px, py, params.sample_start + i);
        let delta = x - mean;
        mean += delta / (i + 1) as f32;
        m2 += delta * (x - mean);
    }
    // ...then merged into the totals (Chan, Golub and LeVeque's pairwise update).
    let n_old = params.sample_start as f32;
    let n_new = params.sample_count as f32;
    let n = n_old + n_new;
    let delta = mean - stats.mean;
    stats.mean += delta * (n_new / n);
    stats.m2 = stats.m2 + m2 + delta * delta * (n_old * n_new / n);
}
