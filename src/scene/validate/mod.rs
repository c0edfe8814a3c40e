//! From the file as written to a validated [`Scene`]: every range, reference and degenerate
//! case checked, each failure tied to its field and its place in the file. The camera and the
//! render settings are checked here; each other part of the file in its own module.

mod camera;
mod environment;
mod fields;
mod lights;
mod materials;
mod media;
mod objects;

pub(super) use fields::FieldError;

use super::file::{RenderToml, SceneToml};
use super::medium::{Media, MAX_MEDIUM_SLOTS};
use super::{
    check_image_size, check_integrator_bounces, Integrator, LightSampler, RenderSettings, Sampler,
    Scene, MAX_BOUNCES_LIMIT, MAX_IMAGE_SIDE, MAX_SPP,
};
use fields::{fail, int_in, non_negative, radiance_in_range};
use glam::Vec3;
use std::ops::Range;
use std::path::Path;

impl SceneToml {
    /// The scene, and warnings to print; mesh files are read relative to `folder`.
    pub(super) fn validate(
        self,
        name: String,
        folder: &Path,
    ) -> Result<(Scene, Vec<String>), FieldError> {
        let whole = |field: &str, message: String| FieldError {
            span: None,
            field: field.into(),
            message,
        };
        let camera = self.camera.ok_or_else(|| {
            whole(
                "[camera]",
                "missing: the scene needs a [camera] table".into(),
            )
        })?;
        let camera_span = camera.span();
        let camera = camera.into_inner();
        let camera_toml_medium = camera.medium.clone();
        let render = self.render.ok_or_else(|| {
            whole(
                "[render]",
                "missing: the scene needs a [render] table".into(),
            )
        })?;
        let render_span = render.span();
        let render = render.into_inner();

        let camera = camera::validate_camera(&camera, camera_span, folder)?;

        let settings = validate_render(&render, render_span)?;
        let mut materials = materials::validate_materials(&self.materials, folder)?;
        let mut media = media::validate_media(&self.media, folder)?;
        let subsurface = media::subsurface_media(&self.materials, &mut materials, &mut media)?;
        let global = render
            .medium
            .as_ref()
            .map(|m| media.homogeneous(m, "render.medium"))
            .transpose()?;
        let camera_medium = camera_toml_medium
            .as_ref()
            .map(|m| media.homogeneous(m, "camera.medium"))
            .transpose()?
            .filter(|&m| Some(m) != global);
        let mut objects = objects::validate_objects(
            &self.spheres,
            &self.quads,
            &self.meshes,
            folder,
            &mut materials,
            &media,
            &subsurface,
        )?;
        objects::place_volumes(&self.volumes, &mut objects, &mut materials, &mut media)?;
        let camera_medium =
            media::camera_in_volume(&media, &objects.boundaries, camera.eye, camera_medium)
                .map_err(|m| whole("camera.eye", m))?;
        if objects.boundaries.len() + 2 > MAX_MEDIUM_SLOTS {
            return Err(whole(
                "media",
                format!(
                    "{} object materials bound media; the kernel holds at most {} (a material \
                     per medium, for every object filled with it)",
                    objects.boundaries.len(),
                    MAX_MEDIUM_SLOTS - 2
                ),
            ));
        }
        let mut warnings = objects.warnings;
        warnings.extend(media::downsampling_warnings(&media));
        let environment = match &self.environment {
            Some(e) => {
                let environment =
                    environment::validate_environment(e, render.background.is_some(), folder)?;
                if let (Some(clamped), Some(file)) = (environment.image.clamped, &e.get_ref().file)
                {
                    warnings.push(format!("{}: {}", file.get_ref(), clamped.warning()));
                }
                Some(environment)
            }
            None => None,
        };
        let mut textures = materials.textures;
        warnings.append(&mut textures.warnings);
        let scene = Scene {
            name,
            camera,
            render: settings,
            materials: materials.list,
            spheres: objects.spheres,
            quads: objects.quads,
            triangles: objects.triangles,
            instanced: objects.instanced,
            textures,
            environment,
            lights: {
                let mut all = lights::validate_lights(&self.lights)?;
                all.extend(objects.lights);
                all
            },
            media: Media {
                list: media.list,
                global,
                camera: camera_medium,
                boundaries: objects.boundaries,
            },
        };
        Ok((scene, warnings))
    }
}

/// `[render]` (at `render_span` in the file): the image size, samples, bounces, background and
/// seed, checked in that order.
fn validate_render(
    render: &RenderToml,
    render_span: Range<usize>,
) -> Result<RenderSettings, FieldError> {
    let (width, height) = (*render.width.get_ref(), *render.height.get_ref());
    check_image_size(width, height).or_else(|m| {
        let span = if width < 1 || width > MAX_IMAGE_SIDE as i64 {
            render.width.span()
        } else if height < 1 || height > MAX_IMAGE_SIDE as i64 {
            render.height.span()
        } else {
            render_span.clone()
        };
        fail(span, "render", m)
    })?;
    let spp = int_in(&render.spp, "render.spp", 1, MAX_SPP as i64)?;
    let max_bounces = int_in(
        &render.max_bounces,
        "render.max_bounces",
        0,
        MAX_BOUNCES_LIMIT as i64,
    )?;
    let background = match &render.background {
        Some(b) => {
            let v = non_negative(b, "render.background")?;
            radiance_in_range(b.span(), "render.background", v.as_dvec3())?;
            v
        }
        None => Vec3::ZERO,
    };
    let seed = match &render.seed {
        Some(s) => int_in(s, "render.seed", 0, u32::MAX as i64)?,
        None => 0,
    };
    let sampler = match &render.sampler {
        Some(s) => match Sampler::from_name(s.get_ref()) {
            Some(sampler) => sampler,
            None => fail(
                s.span(),
                "render.sampler",
                format!(
                    "unknown sampler {:?}; known: \"independent\", \"sobol\"",
                    s.get_ref()
                ),
            )?,
        },
        None => Sampler::default(),
    };
    let light_sampler = match &render.light_sampler {
        Some(s) => match LightSampler::from_name(s.get_ref()) {
            Some(light_sampler) => light_sampler,
            None => fail(
                s.span(),
                "render.light_sampler",
                format!(
                    "unknown light sampler {:?}; known: \"tree\", \"power\"",
                    s.get_ref()
                ),
            )?,
        },
        None => LightSampler::default(),
    };
    let integrator = match &render.integrator {
        Some(s) => match Integrator::from_name(s.get_ref()) {
            Some(integrator) => integrator,
            None => fail(
                s.span(),
                "render.integrator",
                format!(
                    "unknown integrator {:?}; known: \"path\", \"bdpt\"",
                    s.get_ref()
                ),
            )?,
        },
        None => Integrator::default(),
    };
    let settings = RenderSettings {
        width: width as u32,
        height: height as u32,
        spp,
        max_bounces,
        background,
        seed,
        light_sampling: render.light_sampling.unwrap_or(true),
        russian_roulette: render.russian_roulette.unwrap_or(true),
        sampler,
        integrator,
        light_sampler,
    };
    if let Err(message) = check_integrator_bounces(&settings) {
        fail(render.max_bounces.span(), "render.max_bounces", message)?;
    }
    Ok(settings)
}
