//! The kernel's `Params`: the render settings, the arrays' counts, the environment map's
//! size and rotation, and the camera.

use crate::kernel::types::{
    Emitter, Medium, Params, NO_MEDIUM, PRIMITIVE_ENVIRONMENT, PROJECTION_ORTHOGRAPHIC,
    PROJECTION_PERSPECTIVE, ROULETTE_OFF,
};
use crate::scene::environment::Environment;
use crate::scene::{Camera, CameraBasis, Projection, Scene, ROULETTE_START_BOUNCE};

/// Writes `camera` into `params` for its image size (`params.width`, `params.height`): the
/// basis precomputed, image-right and image-up scaled to half the viewport at unit distance
/// (perspective) or to half the view in world units (orthographic), and the lens. Apart from
/// the rest so the viewer can move the camera without rebuilding the scene's arrays (the BVH,
/// the environment map's tables).
pub fn place_camera(params: &mut Params, camera: &Camera) {
    let CameraBasis {
        w,
        right: u,
        image_up: v,
    } = camera.basis();
    let (projection, half_height) = match camera.projection {
        Projection::Perspective { vfov } => {
            (PROJECTION_PERSPECTIVE, (vfov.to_radians() * 0.5).tan())
        }
        Projection::Orthographic { height } => (PROJECTION_ORTHOGRAPHIC, 0.5 * height),
    };
    params.projection = projection;
    let half_width = half_height * params.width as f32 / params.height as f32;
    let lens_radius = 0.5 * camera.aperture;
    params.eye = camera.eye.into();
    params.forward = (-w).into();
    params.right = (u * half_width).into();
    params.up = (v * half_height).into();
    params.lens_right = (u * lens_radius).into();
    params.lens_up = (v * lens_radius).into();
    params.focus_distance = camera.focus_distance;
}

/// The grid media the kernel holds, in `KernelScene::grids` order: those that volumes placed
/// (each bounds its own box), in the order of the boundaries.
pub(super) fn placed_grids(media: &crate::scene::medium::Media) -> Vec<u32> {
    media
        .boundaries
        .iter()
        .map(|&(_, medium)| medium)
        .filter(|&m| media.list[m as usize].grid.is_some())
        .collect()
}

/// The index in `KernelScene::grids` of `medium`'s grid, or `NO_GRID`.
fn grid_index(media: &crate::scene::medium::Media, medium: u32) -> u32 {
    placed_grids(media)
        .iter()
        .position(|&m| m == medium)
        .map_or(crate::kernel::types::NO_GRID, |i| i as u32)
}

impl Scene {
    /// The media's slots (validation keeps them within `MAX_MEDIUM_SLOTS`): one per material
    /// that bounds a medium, then the global medium and the camera's where no object bounds
    /// it. The camera starts in the slot of an object filled with its medium where there is
    /// one, so that leaving that object returns to the medium outside it.
    fn place_media(&self, params: &mut Params) {
        let media = &self.media;
        params.global_medium = NO_MEDIUM;
        params.camera_medium = NO_MEDIUM;
        let mut count = 0;
        let mut slot = |medium: u32, boundary: u32| {
            let m = &media.list[medium as usize];
            params.media[count] = Medium {
                sigma_t: (m.sigma_a + m.sigma_s).into(),
                g: m.g,
                sigma_s: m.sigma_s.into(),
                boundary,
                // Grid media are numbered in the order of the list (`grid_arrays`).
                grid: grid_index(media, medium),
                _pad: [0; 3],
            };
            count += 1;
            count as u32 - 1
        };
        let mut camera = NO_MEDIUM;
        for &(material, medium) in &media.boundaries {
            let s = slot(medium, material);
            if media.camera == Some(medium) && camera == NO_MEDIUM {
                camera = s;
            }
        }
        let global = media.global.map_or(NO_MEDIUM, |m| slot(m, NO_MEDIUM));
        if let (Some(m), NO_MEDIUM) = (media.camera, camera) {
            camera = slot(m, NO_MEDIUM);
        }
        params.medium_count = count as u32;
        params.global_medium = global;
        params.camera_medium = camera;
    }

    /// The scene's `Params`, given its `emitters` (light sampling's table) and `environment`
    /// map; no samples yet, no AOVs nor clamp (the render's own settings set those).
    pub(super) fn kernel_params(
        &self,
        emitters: &[Emitter],
        environment: Option<&Environment>,
    ) -> Params {
        let r = &self.render;
        let (environment_cos, environment_sin) = environment.map_or((1.0, 0.0), |e| e.rotation());
        let mut params = Params {
            width: r.width,
            height: r.height,
            sample_start: 0,
            sample_count: 0,
            background: r.background.into(),
            max_bounces: r.max_bounces,
            light_sampling: r.light_sampling as u32,
            seed: r.seed,
            sphere_count: self.spheres.len() as u32,
            quad_count: self.quads.len() as u32,
            material_count: self.materials.len() as u32,
            emitter_count: emitters.len() as u32,
            roulette_start: if r.russian_roulette {
                ROULETTE_START_BOUNCE
            } else {
                ROULETTE_OFF
            },
            accumulated_samples: 0,
            aovs: 0,
            radiance_clamp: 0.0,
            // The scan's: the triangles placed as they are (instanced ones follow them).
            triangle_count: self.triangles.len() as u32,
            environment_width: environment.map_or(0, |e| e.image.width),
            environment_height: environment.map_or(0, |e| e.image.height),
            environment_cos,
            environment_sin,
            environment_light_probability: emitters
                .iter()
                .find(|e| e.primitive == PRIMITIVE_ENVIRONMENT)
                .map_or(0.0, |e| e.probability),
            light_count: self.lights.len() as u32,
            sampler: r.sampler.kernel_value(),
            integrator: r.integrator.kernel_value(),
            ..Default::default()
        };
        (params.scene_center, params.scene_radius) = self.bounding_sphere();
        self.place_media(&mut params);
        place_camera(&mut params, &self.camera);
        params
    }
}

/// The splat film's fixed-point scale (`src/cpu/integrator/splat.rs`): 2²⁴ units per the
/// scene's brightest radiance, that of its brightest emitter (area emitters and the
/// environment map's mean by their radiance, point lights by their intensity at the scene's
/// radius, suns by their irradiance over π). Pixels rarely exceed it, so a splat keeps some
/// 2²⁴ steps of resolution, and a pixel's sum has room for 2⁴⁰ times it.
pub fn splat_scale(scene: &super::KernelScene) -> f32 {
    let peak = |v: [f32; 3]| v[0].max(v[1]).max(v[2]);
    let radius = scene.params.scene_radius.max(1e-6);
    let mut brightest = peak(scene.params.background);
    for m in &scene.materials {
        brightest = brightest.max(peak(m.emission));
    }
    for l in &scene.lights {
        let per = if l.kind == crate::kernel::types::LIGHT_SUN {
            if l.sun_one_minus_cos > 0.0 {
                1.0
            } else {
                1.0 / std::f32::consts::PI
            }
        } else {
            1.0 / (radius * radius)
        };
        brightest = brightest.max(peak(l.emitted) * per);
    }
    if !scene.environment_texels.is_empty() {
        let n = scene.environment_texels.len() as f64;
        let mean: f64 = scene
            .environment_texels
            .iter()
            .map(|t| peak(t.radiance) as f64)
            .sum::<f64>()
            / n;
        brightest = brightest.max(mean as f32);
    }
    if !(brightest.is_finite() && brightest > 0.0) {
        brightest = 1.0;
    }
    16_777_216.0 / brightest
}
