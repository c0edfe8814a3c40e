//! Scene files: TOML → validated [`Scene`] → the kernel's structs ([`KernelScene`]).
//!
//! Every error names the file, the line and column, and the field, so a user can fix it
//! without reading code. The format is documented in README.md.

//!
//! The parts, in the order data flows: [`file`] is the TOML as written, [`validate`] turns it
//! into a [`Scene`] or an error, and [`kernel`] lays the scene out for the kernel.

pub mod environment;
mod file;
pub mod grid;
pub mod image;
pub mod light;
pub mod limits;
pub mod medium;
pub mod mesh;
pub mod model;
pub mod model_toml;
pub mod stress;
pub mod studio;
pub mod texture;
mod validate;

use crate::input_file::{read_regular_file, SCENE_FILE_LIMIT};
use file::{line_column, SceneToml};
use glam::{Vec2, Vec3, Vec4};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Largest image side, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Largest image, in pixels (2^23, e.g. 3840×2160 fits): the accumulation buffer holds 16 bytes
/// per pixel and must fit one 128 MiB storage binding, the limit of lavapipe and many GPUs.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 23;
/// Bound on `max_bounces`: paths this long carry no measurable energy, and the bound keeps a
/// kernel loop from running for hours (lavapipe has no watchdog).
pub const MAX_BOUNCES_LIMIT: u32 = 1024;
/// Bound on samples per pixel, so every global sample index fits the kernel's u32 counter.
pub const MAX_SPP: u32 = 1 << 30;
/// Russian roulette starts after this many scattering events (when it is on).
pub const ROULETTE_START_BOUNCE: u32 = 3;

/// A bad scene: where, which field, and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", self.describe())]
pub struct SceneError {
    pub path: PathBuf,
    /// 1-based line and column, where the problem has a place in the file.
    pub position: Option<(usize, usize)>,
    /// Dotted path of the field, e.g. `spheres[1].radius`.
    pub field: Option<String>,
    pub message: String,
}

impl SceneError {
    fn describe(&self) -> String {
        let mut out = self.path.display().to_string();
        if let Some((line, col)) = self.position {
            out += &format!(":{line}:{col}");
        }
        out += ": ";
        if let Some(field) = &self.field {
            out += &format!("{field}: ");
        }
        out + &self.message
    }
}

/// A validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub name: String,
    pub camera: Camera,
    pub render: RenderSettings,
    pub materials: Vec<Material>,
    pub spheres: Vec<Sphere>,
    pub quads: Vec<Quad>,
    /// Every mesh's triangles, in the scene's coordinates, but those of instanced meshes.
    pub triangles: Vec<Triangle>,
    /// Meshes placed many times without copies (`[[meshes]] instances`, glTF meshes reused by
    /// nodes or `EXT_mesh_gpu_instancing`; see [`InstancedMesh`]); their triangles are not in
    /// `triangles`.
    pub instanced: Vec<InstancedMesh>,
    /// The textures materials refer to.
    pub textures: texture::TextureSet,
    /// `[environment]`: lights the scene in place of `render.background`.
    pub environment: Option<environment::Environment>,
    /// `[[lights]]`: point, spot and directional lights.
    pub lights: Vec<light::Light>,
    /// Participating media (`[media]`), and where they are.
    pub media: medium::Media,
}

/// A mesh placed many times and stored once: the two-level structure's bottom level
/// (src/kernel/scene/acceleration.rs lays it out, shaders/traverse/blas.wgsl traces it). Its triangles are
/// in the mesh file's own coordinates (a glTF primitive's, before its node's transform), and
/// each placement takes them to the scene's. Only opaque meshes that do not emit and have no
/// normal map are held so ([`Material::two_level`] says why, `mesh/reuse.rs` which parts);
/// others are flattened into [`Scene::triangles`].
#[derive(Clone, Debug, PartialEq)]
pub struct InstancedMesh {
    pub triangles: Vec<Triangle>,
    pub placements: Vec<glam::Mat4>,
}

impl Scene {
    /// The same scene with every instanced mesh copied into `triangles`, placement after
    /// placement, after the scene's own triangles: what the two-level structure must render
    /// the same as (tests/suite/instancing.rs).
    pub fn flattened(&self) -> Scene {
        let mut scene = self.clone();
        for mesh in std::mem::take(&mut scene.instanced) {
            for placement in &mesh.placements {
                scene
                    .triangles
                    .extend(mesh.triangles.iter().map(|t| mesh::placed(t, placement)));
            }
        }
        scene
    }

    /// Triangles the scene places: its own and every instance's.
    pub fn placed_triangle_count(&self) -> u64 {
        let instanced: u64 = self
            .instanced
            .iter()
            .map(|m| m.triangles.len() as u64 * m.placements.len() as u64)
            .sum();
        self.triangles.len() as u64 + instanced
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Triangle {
    pub vertices: [Vec3; 3],
    /// Unit vertex normals to interpolate for shading; `None` shades with the geometric normal.
    pub normals: Option<[Vec3; 3]>,
    pub material: u32,
    /// Texture coordinates at the vertices (v up), where the file gives them.
    pub uvs: Option<[Vec2; 3]>,
    /// The second set (glTF's TEXCOORD_1), where the file gives it.
    pub uvs1: Option<[Vec2; 3]>,
    /// Vertex tangents (xyz unit, w the bitangent's sign) where the material has a normal map.
    pub tangents: Option<[Vec4; 3]>,
    /// Vertex colours (linear RGBA, glTF's COLOR_0), where the file gives them.
    pub colors: Option<[Vec4; 3]>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub projection: Projection,
    /// Lens diameter; 0 is a pinhole (always for an orthographic camera).
    pub aperture: f32,
    /// Distance to the plane in focus, along the view direction.
    pub focus_distance: f32,
}

/// How the camera projects the scene onto the image (`[camera] projection`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Rays through the eye (or the lens): `vfov` is the vertical field of view in degrees, in
    /// (0, 180).
    Perspective { vfov: f32 },
    /// Parallel rays along the view direction, starting on the image plane (through the eye,
    /// across the view): `height` is the view's height in world units (> 0); its width follows
    /// the image's aspect ratio.
    Orthographic { height: f32 },
}

/// The camera's orthonormal basis, right-handed: `w` points from the target back at the eye,
/// image-right is `up × w`, image-up is `w × right`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    pub w: Vec3,
    pub right: Vec3,
    pub image_up: Vec3,
}

impl Camera {
    pub fn basis(&self) -> CameraBasis {
        // In f64: the squares of a short `up` (1e-25) or of a cross product of nearly
        // parallel vectors underflow in f32, and normalising them would give NaN.
        let w = (self.eye.as_dvec3() - self.target.as_dvec3()).normalize();
        let right = self.up.as_dvec3().cross(w).normalize();
        CameraBasis {
            w: w.as_vec3(),
            right: right.as_vec3(),
            image_up: w.cross(right).as_vec3(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_bounces: u32,
    pub background: Vec3,
    pub seed: u32,
    /// Next-event estimation with multiple importance sampling.
    pub light_sampling: bool,
    pub russian_roulette: bool,
    /// Where a path's random numbers come from.
    pub sampler: Sampler,
    /// Which estimator renders the image.
    pub integrator: Integrator,
    /// How next-event estimation picks an emitter.
    pub light_sampler: LightSampler,
}

/// `[render] light_sampler`, `--light-sampler`: how path tracing's next-event estimation
/// picks the emitter to sample (bidirectional path tracing always picks by power).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum LightSampler {
    /// A light tree (Conty Estevez and Kulla 2018, pbrt-v4's BVHLightSampler): emitters in
    /// proportion to a bound on what each sends to the shading point, from its power,
    /// distance and orientation; the environment map and suns keep their power share.
    Tree,
    /// In proportion to power alone, by the alias table: O(1), blind to where the shading
    /// point is.
    #[default]
    Power,
}

impl LightSampler {
    pub fn name(self) -> &'static str {
        match self {
            LightSampler::Tree => "tree",
            LightSampler::Power => "power",
        }
    }

    pub fn from_name(name: &str) -> Option<LightSampler> {
        match name {
            "tree" => Some(LightSampler::Tree),
            "power" => Some(LightSampler::Power),
            _ => None,
        }
    }
}

/// `[render] integrator`, `--integrator`: the light transport estimator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Integrator {
    /// Unidirectional path tracing with next-event estimation and MIS.
    #[default]
    Path,
    /// Bidirectional path tracing: every join of a camera and a light subpath, weighted by the
    /// power heuristic; finds caustics that path tracing cannot.
    Bdpt,
}

impl Integrator {
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Path => "path",
            Integrator::Bdpt => "bdpt",
        }
    }

    pub fn from_name(name: &str) -> Option<Integrator> {
        match name {
            "path" => Some(Integrator::Path),
            "bdpt" => Some(Integrator::Bdpt),
            _ => None,
        }
    }

    /// `Params::integrator`.
    pub fn kernel_value(self) -> u32 {
        match self {
            Integrator::Path => crate::kernel::types::INTEGRATOR_PATH,
            Integrator::Bdpt => crate::kernel::types::INTEGRATOR_BDPT,
        }
    }
}

/// `[render] sampler`, `--sampler`: the numbers each sample's decisions draw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Sampler {
    /// Independent uniform numbers (a PCG stream per sample): what the statistical tests that
    /// assume independent samples use.
    #[default]
    Independent,
    /// Owen-scrambled Sobol points (hash-based, Burley 2020), each pair of draws of a decision
    /// a 2D point: lower error at a given spp.
    Sobol,
}

impl Sampler {
    pub fn name(self) -> &'static str {
        match self {
            Sampler::Independent => "independent",
            Sampler::Sobol => "sobol",
        }
    }

    pub fn from_name(name: &str) -> Option<Sampler> {
        match name {
            "independent" => Some(Sampler::Independent),
            "sobol" => Some(Sampler::Sobol),
            _ => None,
        }
    }

    /// `Params::sampler`.
    pub fn kernel_value(self) -> u32 {
        match self {
            Sampler::Independent => crate::cpu::core::rng::SAMPLER_INDEPENDENT,
            Sampler::Sobol => crate::cpu::core::rng::SAMPLER_SOBOL,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    Diffuse,
    /// KHR_materials_unlit: reflects nothing, emits `emitted_radiance` (the base colour) times
    /// the colour texture and the vertex colour.
    Unlit,
    Specular,
    /// GGX microfacet conductor; roughness in [0, 1], GGX alpha = roughness² (unused where
    /// [`Material::roughness_texture`] is set).
    Metal {
        roughness: f32,
    },
    /// Smooth glass-like interface with this index of refraction.
    Dielectric {
        ior: f32,
    },
    /// glTF's metallic-roughness material (`src/cpu/materials/pbr.rs`): a dielectric specular layer over
    /// a diffuse base, mixed with a conductor by `metallic`.
    Pbr {
        roughness: f32,
        metallic: f32,
        ior: f32,
        specular: f32,
        specular_color: Vec3,
        /// The transmissive share of the dielectric part (KHR_materials_transmission), and
        /// the index into [`Scene::textures`] of a texture whose first channel multiplies it.
        transmission: f32,
        transmission_texture: Option<u32>,
        /// Beer–Lambert attenuation inside the mesh (KHR_materials_volume): the colour white
        /// light has after `attenuation_distance`; None for none (glTF's +∞).
        attenuation_color: Vec3,
        attenuation_distance: Option<f32>,
        /// KHR_materials_clearcoat and KHR_materials_sheen on top.
        layers: PbrLayers,
    },
}

/// KHR_materials_clearcoat's coat and KHR_materials_sheen's sheen on a pbr material
/// (`src/cpu/materials/clearcoat.rs`, `src/cpu/materials/sheen.rs`); the default has neither. Textures are
/// indices into [`Scene::textures`]: the coat's first channel multiplies `clearcoat`, the
/// coat roughness's first channel `clearcoat_roughness`, the sheen colour's RGB `sheen_color`,
/// the sheen roughness's first channel `sheen_roughness`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PbrLayers {
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub clearcoat_texture: Option<u32>,
    pub clearcoat_roughness_texture: Option<u32>,
    /// The coat's normal map and its scale.
    pub clearcoat_normal_texture: Option<(u32, f32)>,
    /// Black: no sheen.
    pub sheen_color: Vec3,
    pub sheen_roughness: f32,
    pub sheen_color_texture: Option<u32>,
    pub sheen_roughness_texture: Option<u32>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
    pub color: Vec3,
    /// `emission * strength`.
    pub emitted_radiance: Vec3,
    /// Index into [`Scene::textures`] multiplying `color` at each hit (1 for TOML textures).
    pub color_texture: Option<u32>,
    /// Index into [`Scene::textures`] whose first channel multiplies the roughness (1 for TOML
    /// textures) and whose second multiplies a pbr material's `metallic`.
    pub roughness_texture: Option<u32>,
    /// Index into [`Scene::textures`] multiplying `emitted_radiance` at each point (glTF's
    /// emissiveTexture; light sampling weighs each triangle by the texture's mean over it,
    /// `src/kernel/emitters.rs`).
    pub emission_texture: Option<u32>,
    /// Index into [`Scene::textures`] of a tangent-space normal map (glTF's normalTexture),
    /// and the scale of its x and y.
    pub normal_texture: Option<(u32, f32)>,
    /// glTF's alphaMode and alpha (`src/cpu/geometry/alpha.rs`); on triangles only.
    pub alpha: Alpha,
}

impl Material {
    /// A material without texture maps; the mesh readers add theirs once they have read them.
    pub fn untextured(
        name: String,
        kind: MaterialKind,
        color: Vec3,
        emitted_radiance: Vec3,
        alpha: Alpha,
    ) -> Material {
        Material {
            name,
            kind,
            color,
            emitted_radiance,
            color_texture: None,
            roughness_texture: None,
            emission_texture: None,
            normal_texture: None,
            alpha,
        }
    }

    /// Whether the material has a normal map (its own, or its coat's), which needs vertex
    /// tangents.
    pub fn has_normal_map(&self) -> bool {
        self.normal_texture.is_some()
            || matches!(&self.kind, MaterialKind::Pbr { layers, .. }
                if layers.clearcoat_normal_texture.is_some())
    }

    /// Whether a mesh in this material may be stored once and placed by transforms (the
    /// two-level structure, [`InstancedMesh`]), rather than copied per placement. Not when it
    /// emits: light sampling picks emitting triangles by their power in the scene's
    /// coordinates, one table entry per placed triangle (src/kernel/scene/emitter_table.rs), which an
    /// instance would have to sample through its transform. Not when alpha-tested or blended,
    /// nor with a normal map: the alpha test and the tangent frame would need the instance
    /// too. Those are copied as before, which is exact.
    pub fn two_level(&self) -> bool {
        self.emitted_radiance == Vec3::ZERO
            && self.emission_texture.is_none()
            && self.alpha.mode == AlphaMode::Opaque
            && !self.has_normal_map()
    }
}

/// How a material's alpha (its opacity times its colour texture's alpha) is used: glTF's
/// alphaMode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Where alpha is below `cutoff` there is no surface, for every ray.
    Mask { cutoff: f32 },
    /// Stochastic transparency: a ray passes with probability 1 − alpha.
    Blend,
}

/// A material's alpha: its mode and constant opacity (glTF's baseColorFactor.a).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alpha {
    pub mode: AlphaMode,
    pub opacity: f32,
}

impl Alpha {
    /// Opaque: what every material is unless its file says otherwise.
    pub const OPAQUE: Alpha = Alpha {
        mode: AlphaMode::Opaque,
        opacity: 1.0,
    };
}

#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Quad {
    pub corner: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub material: u32,
}

/// Command-line values that replace the scene's `[render]` ones.
#[derive(Clone, Debug, Default)]
pub struct RenderOverrides {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub spp: Option<u32>,
    pub max_bounces: Option<u32>,
    pub seed: Option<u32>,
    pub light_sampling: Option<bool>,
    pub sampler: Option<Sampler>,
    pub integrator: Option<Integrator>,
    pub light_sampler: Option<LightSampler>,
}

impl Scene {
    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let bytes = read_regular_file(path, SCENE_FILE_LIMIT, "scene file").map_err(|message| {
            SceneError {
                path: path.to_owned(),
                position: None,
                field: None,
                message,
            }
        })?;
        let text = String::from_utf8(bytes).map_err(|e| SceneError {
            path: path.to_owned(),
            position: None,
            field: None,
            message: format!(
                "not a TOML scene: the file is not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        })?;
        Scene::parse(&text, path)
    }

    /// Parses and validates scene text; `path` is only used in messages and for the name.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let at = |span: Option<Range<usize>>, field: Option<String>, message: String| SceneError {
            path: path.to_owned(),
            position: span.map(|s| line_column(text, s.start)),
            field,
            message,
        };
        if text.trim().is_empty() {
            return Err(at(
                None,
                None,
                "the file is empty: a scene needs at least [camera], [render] and one object"
                    .into(),
            ));
        }
        if text.contains('\0') {
            return Err(at(
                None,
                None,
                "not a TOML scene: the file contains NUL bytes (binary data?)".into(),
            ));
        }
        let raw: SceneToml = toml::from_str(text).map_err(|e| {
            at(
                e.span(),
                None,
                format!("TOML error: {}", e.message().trim_end()),
            )
        })?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());
        let folder = path.parent().unwrap_or(Path::new(""));
        let (scene, warnings) = raw
            .validate(name, folder)
            .map_err(|e| at(e.span, Some(e.field), e.message))?;
        for w in warnings {
            crate::errln!("glint: warning: {}: {w}", path.display());
        }
        Ok(scene)
    }

    /// Applies command-line overrides and checks the result as the scene's own values are checked.
    pub fn with_overrides(mut self, o: &RenderOverrides) -> Result<Scene, String> {
        let r = &mut self.render;
        r.width = o.width.unwrap_or(r.width);
        r.height = o.height.unwrap_or(r.height);
        r.spp = o.spp.unwrap_or(r.spp);
        r.max_bounces = o.max_bounces.unwrap_or(r.max_bounces);
        r.seed = o.seed.unwrap_or(r.seed);
        r.light_sampling = o.light_sampling.unwrap_or(r.light_sampling);
        r.sampler = o.sampler.unwrap_or(r.sampler);
        r.integrator = o.integrator.unwrap_or(r.integrator);
        r.light_sampler = o.light_sampler.unwrap_or(r.light_sampler);
        check_image_size(r.width as i64, r.height as i64)?;
        check_range(r.spp as i64, 1, MAX_SPP as i64).map_err(|m| format!("spp {m}"))?;
        check_range(r.max_bounces as i64, 0, MAX_BOUNCES_LIMIT as i64)
            .map_err(|m| format!("max_bounces {m}"))?;
        check_integrator_bounces(r)?;
        Ok(self)
    }
}

/// Bidirectional subpaths live in fixed arrays (`src/cpu/integrator/bdpt/walk.rs`): their
/// length is bounded.
pub(crate) fn check_integrator_bounces(r: &RenderSettings) -> Result<(), String> {
    let limit = crate::cpu::integrator::bdpt::walk::BDPT_MAX_BOUNCES;
    if r.integrator == Integrator::Bdpt && r.max_bounces > limit {
        return Err(format!(
            "max_bounces {} is above {limit}, the most the bdpt integrator traces",
            r.max_bounces
        ));
    }
    Ok(())
}

pub(crate) fn check_range(value: i64, min: i64, max: i64) -> Result<(), String> {
    if value < min || value > max {
        return Err(format!("must be in {min}..={max}, got {value}"));
    }
    Ok(())
}

pub(crate) fn check_image_size(width: i64, height: i64) -> Result<(), String> {
    for (name, side) in [("width", width), ("height", height)] {
        if side < 1 {
            return Err(format!("{name} must be at least 1, got {side}"));
        }
        if side > MAX_IMAGE_SIDE as i64 {
            return Err(format!(
                "{name} {side} is too large: at most {MAX_IMAGE_SIDE} pixels a side"
            ));
        }
    }
    let pixels = width * height;
    if pixels as u64 > MAX_IMAGE_PIXELS {
        return Err(format!(
            "{width}×{height} = {pixels} pixels is too large to hold: at most {MAX_IMAGE_PIXELS} \
             pixels (e.g. 3840×2160), so the accumulation buffer fits one 128 MiB GPU binding"
        ));
    }
    Ok(())
}
