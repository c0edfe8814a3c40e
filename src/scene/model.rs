//! A model file (`.glb`, `.gltf`, `.obj`, `.ply`) as a whole scene: `glint render model.glb`.
//!
//! The model is placed as the file places it. The camera is the file's first camera
//! (or the one `--camera` picks), else one that frames the model's bounding sphere from
//! the front; the file's punctual lights join it; the environment is a map file or the
//! generated studio map (`studio.rs`). [`model_toml`](super::model_toml) writes the scene as
//! a scene file that builds the same scene again.

use super::environment::{self, Environment};
use super::light::Light;
use super::limits::MAX_COORDINATE;
use super::mesh::{self, MeshTransform, NO_MATERIAL};
use super::texture::TextureSet;
use super::{
    check_image_size, studio, Camera, Material, MaterialKind, Projection, RenderSettings, Scene,
    SceneError,
};
use glam::{DVec3, Vec3};
use std::path::{Path, PathBuf};

/// The extensions of the model files `glint render` and `glint view` take in place of a scene.
pub const MODEL_EXTENSIONS: [&str; 4] = ["glb", "gltf", "obj", "ply"];

/// Vertical field of view of the framing camera, degrees.
pub const FRAMING_VFOV: f32 = 40.0;
/// The framing camera leaves this much room around the model's bounding sphere: the sphere's
/// outline spans 1/(1 + margin) of the frame's shorter side.
pub const FRAMING_MARGIN: f64 = 0.1;
/// Side of the image, in pixels, when neither the command line nor the camera sets it: the
/// longer side, the other from the camera's aspect ratio (square without one).
pub const DEFAULT_SIDE: u32 = 512;

/// The material of the parts a file gives none (a PLY file, an OBJ without `.mtl`).
pub const DEFAULT_MATERIAL: &str = "default";
pub const DEFAULT_COLOR: f32 = 0.8;

/// Whether `path` names a model file (by its extension) rather than a scene file.
pub fn is_model_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| MODEL_EXTENSIONS.contains(&e.to_string_lossy().to_lowercase().as_str()))
}

/// The scene `path` names: a scene file, or a model file built into a scene with `options`.
pub fn load_scene_or_model(path: &Path, options: &ModelOptions) -> Result<Scene, SceneError> {
    if is_model_file(path) {
        Ok(load_model(path, options)?.scene)
    } else {
        Scene::load(path)
    }
}

/// What the command line says about a model scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelOptions {
    /// `--camera N`: the file's N-th camera.
    pub camera: Option<usize>,
    /// `--environment FILE`; without it, the studio map.
    pub environment: Option<PathBuf>,
    pub environment_strength: f32,
    pub environment_rotate: f32,
    /// `--width`, `--height`: the other side follows the camera's aspect ratio.
    pub width: Option<u32>,
    pub height: Option<u32>,
}

impl Default for ModelOptions {
    fn default() -> Self {
        ModelOptions {
            camera: None,
            environment: None,
            environment_strength: 1.0,
            environment_rotate: 0.0,
            width: None,
            height: None,
        }
    }
}

/// The environment of a model scene.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    /// A map file, absolute.
    File(PathBuf),
    Studio,
}

/// A model scene and what writing it as a scene file needs.
#[derive(Clone, Debug)]
pub struct ModelScene {
    pub scene: Scene,
    /// The model's file name, as the scene file next to it names it.
    pub file_name: String,
    /// Whether every part has the default material (the file gives none).
    pub default_material: bool,
    pub environment: EnvironmentSource,
    pub environment_strength: f32,
    pub environment_rotate: f32,
}

/// Builds the scene of model file `path`; warnings go to stderr. Errors name the file and the
/// element or flag.
pub fn load_model(path: &Path, options: &ModelOptions) -> Result<ModelScene, SceneError> {
    let error = |message: String| SceneError {
        path: path.to_owned(),
        position: None,
        field: None,
        message,
    };
    let file_name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut warnings = Vec::new();
    let mut materials = Vec::new();
    let mut textures = TextureSet::default();
    let identity = MeshTransform {
        scale: Vec3::ONE,
        rotate_degrees: Vec3::ZERO,
        translate: Vec3::ZERO,
    };
    let mut default_material = false;
    let loaded = match mesh::load(
        path,
        &file_name,
        &identity,
        None,
        true,
        &mut materials,
        &mut textures,
    ) {
        Err(message) if message.contains(NO_MATERIAL) => {
            // Parts without a material: the whole model gets the default one.
            default_material = true;
            materials = vec![default_material_value()];
            textures = TextureSet::default();
            mesh::load(
                path,
                &file_name,
                &identity,
                Some(0),
                true,
                &mut materials,
                &mut textures,
            )
        }
        other => other,
    }
    .map_err(|message| error(strip_prefix(&message, &file_name)))?;
    warnings.extend(loaded.warnings);
    warnings.append(&mut textures.warnings);
    let (triangles, instanced) = (loaded.triangles, loaded.instanced);
    // Framed on every placed vertex, instanced meshes' too (placed here, not stored).
    let (centre, radius) = bounding_sphere(triangles.iter().flat_map(|t| t.vertices).chain(
        instanced.iter().flat_map(|m| {
            m.placements.iter().flat_map(move |p| {
                m.triangles
                    .iter()
                    .flat_map(move |t| t.vertices.map(|v| p.transform_point3(v)))
            })
        }),
    ));

    let is_gltf = mesh::is_gltf(path);
    let file_camera = if is_gltf {
        mesh::gltf_camera(path, options.camera).map_err(|m| match options.camera {
            Some(i) => error(format!("--camera {i}: {m}")),
            None => error(m),
        })?
    } else if let Some(i) = options.camera {
        return Err(error(format!(
            "--camera {i}: {}",
            mesh::no_such_camera(i, 0)
        )));
    } else {
        None
    };
    let aspect = file_camera.as_ref().and_then(|c| c.aspect);
    let (width, height) = image_size(options.width, options.height, aspect);
    check_image_size(width as i64, height as i64).map_err(error)?;
    let camera = match &file_camera {
        Some(c) => pinhole(c.eye, c.target(), c.up, c.projection),
        None => framing_camera(centre, radius, width as f64 / height as f64).map_err(error)?,
    };

    let lights: Vec<Light> = if is_gltf {
        let (lights, light_warnings) =
            mesh::gltf_lights(path, glam::Mat4::IDENTITY).map_err(error)?;
        warnings.extend(
            light_warnings
                .into_iter()
                .map(|w| format!("{file_name}: {w}")),
        );
        lights
    } else {
        Vec::new()
    };

    let (environment, source) = model_environment(options).map_err(error)?;
    if let Some(clamped) = environment.image.clamped {
        if let EnvironmentSource::File(f) = &source {
            warnings.push(format!("{}: {}", f.display(), clamped.warning()));
        }
    }
    for w in warnings {
        crate::errln!("glint: warning: {w}");
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let scene = Scene {
        name,
        camera,
        render: RenderSettings {
            width,
            height,
            spp: 64,
            max_bounces: 8,
            background: Vec3::ZERO,
            seed: 0,
            light_sampling: true,
            russian_roulette: true,
            sampler: Default::default(),
            integrator: Default::default(),
            light_sampler: Default::default(),
        },
        materials,
        spheres: Vec::new(),
        quads: Vec::new(),
        triangles,
        instanced,
        textures,
        environment: Some(environment),
        lights,
        media: Default::default(),
    };
    Ok(ModelScene {
        scene,
        file_name,
        default_material,
        environment: source,
        environment_strength: options.environment_strength,
        environment_rotate: options.environment_rotate,
    })
}

/// The mesh reader's messages start with the name shown; the error's path says it already.
fn strip_prefix(message: &str, shown: &str) -> String {
    message
        .strip_prefix(&format!("{shown}: "))
        .unwrap_or(message)
        .to_string()
}

fn default_material_value() -> Material {
    Material::untextured(
        DEFAULT_MATERIAL.into(),
        MaterialKind::Diffuse,
        Vec3::splat(DEFAULT_COLOR),
        Vec3::ZERO,
        super::Alpha::OPAQUE,
    )
}

/// The environment `--environment` names, or the studio map.
fn model_environment(options: &ModelOptions) -> Result<(Environment, EnvironmentSource), String> {
    let (strength, rotate) = (options.environment_strength, options.environment_rotate);
    match &options.environment {
        Some(file) => {
            let environment = environment::load(file, strength, rotate)
                .map_err(|m| format!("--environment {}: {m}", file.display()))?;
            let absolute = std::path::absolute(file)
                .map_err(|e| format!("--environment {}: {e}", file.display()))?;
            Ok((environment, EnvironmentSource::File(absolute)))
        }
        None => Ok((
            studio::environment(strength, rotate)
                .map_err(|m| format!("the studio environment: {m}"))?,
            EnvironmentSource::Studio,
        )),
    }
}

/// The image size from the command line's sides and the camera's aspect ratio (width /
/// height): a side not given follows from the other, or from [`DEFAULT_SIDE`].
pub fn image_size(width: Option<u32>, height: Option<u32>, aspect: Option<f32>) -> (u32, u32) {
    let a = aspect.unwrap_or(1.0) as f64;
    let side = |x: f64| x.round().clamp(1.0, u32::MAX as f64) as u32;
    match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, side(w as f64 / a)),
        (None, Some(h)) => (side(h as f64 * a), h),
        (None, None) if a >= 1.0 => (DEFAULT_SIDE, side(DEFAULT_SIDE as f64 / a)),
        (None, None) => (side(DEFAULT_SIDE as f64 * a), DEFAULT_SIDE),
    }
}

/// A camera without a lens (a pinhole, or an orthographic camera), its focus distance computed
/// as a scene file's is.
pub fn pinhole(eye: Vec3, target: Vec3, up: Vec3, projection: Projection) -> Camera {
    Camera {
        eye,
        target,
        up,
        projection,
        aperture: 0.0,
        focus_distance: (target - eye).as_dvec3().length() as f32,
    }
}

/// The centre of the points' bounding box and the largest distance from it to a point.
pub fn bounding_sphere(points: impl Iterator<Item = Vec3> + Clone) -> (DVec3, f64) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in points.clone() {
        lo = lo.min(p.as_dvec3());
        hi = hi.max(p.as_dvec3());
    }
    let centre = 0.5 * (lo + hi);
    let radius = points
        .map(|p| p.as_dvec3().distance(centre))
        .fold(0.0, f64::max);
    (centre, radius)
}

/// A camera on +z of the sphere looking at its centre along −z, with a
/// [`FRAMING_VFOV`] vertical field of view, far enough that the sphere's outline spans
/// 1/(1 + [`FRAMING_MARGIN`]) of the frame's shorter side (`aspect` = width / height).
pub fn framing_camera(centre: DVec3, radius: f64, aspect: f64) -> Result<Camera, String> {
    let radius = if radius > 0.0 { radius } else { 1.0 };
    let half = (FRAMING_VFOV as f64 / 2.0).to_radians().tan();
    // The sphere's outline seen at distance d subtends a half-angle asin(r/d); its image
    // spans tan of that on a plane at distance 1.
    let fit = half * aspect.min(1.0) / (1.0 + FRAMING_MARGIN);
    let distance = radius / fit.atan().sin();
    let eye = centre + DVec3::new(0.0, 0.0, distance);
    if eye.abs().max_element() > MAX_COORDINATE as f64 {
        return Err(format!(
            "the model is too large to frame: a camera {distance:e} away from it lies outside \
             ±{MAX_COORDINATE:e} (the numeric range glint supports)"
        ));
    }
    Ok(pinhole(
        eye.as_vec3(),
        centre.as_vec3(),
        Vec3::Y,
        Projection::Perspective { vfov: FRAMING_VFOV },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_side_follows_the_aspect_ratio() {
        assert_eq!(image_size(None, None, None), (512, 512));
        assert_eq!(image_size(None, None, Some(2.0)), (512, 256));
        assert_eq!(image_size(None, None, Some(0.5)), (256, 512));
        assert_eq!(image_size(Some(300), None, Some(1.5)), (300, 200));
        assert_eq!(image_size(None, Some(100), Some(1.5)), (150, 100));
        assert_eq!(image_size(Some(7), Some(9), Some(1.5)), (7, 9));
    }

    #[test]
    fn the_framing_camera_leaves_the_margin() {
        let c = framing_camera(DVec3::new(1.0, 2.0, 3.0), 2.0, 1.0).unwrap();
        let d = (c.eye - c.target).length() as f64;
        // The outline's half-height on the image plane against the frame's.
        let outline = (2.0 / d).asin().tan();
        let frame = 20f64.to_radians().tan();
        assert!(
            (outline * 1.1 / frame - 1.0).abs() < 1e-5,
            "{outline} {frame}"
        );
        assert_eq!(c.target, Vec3::new(1.0, 2.0, 3.0));
        assert!(c.eye.z > 3.0 && c.eye.x == 1.0 && c.eye.y == 2.0);
    }
}
