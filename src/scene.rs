//! Scene files: TOML → validated [`Scene`] → the kernel's structs ([`KernelScene`]).
//!
//! Every error names the file, the line and column, and the field, so a user can fix it
//! without reading code. The format is documented in README.md.

use crate::shader_types::{
    self, Emitter, Params, MATERIAL_DIELECTRIC, MATERIAL_DIFFUSE, MATERIAL_METAL,
    MATERIAL_SPECULAR, PRIMITIVE_QUAD, PRIMITIVE_SPHERE, ROULETTE_OFF,
};
use glam::Vec3;
use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

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
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub vfov: f32,
    /// Lens diameter; 0 is a pinhole.
    pub aperture: f32,
    /// Distance to the plane in focus, along the view direction.
    pub focus_distance: f32,
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
        let w = (self.eye - self.target).normalize();
        let right = self.up.cross(w).normalize();
        CameraBasis {
            w,
            right,
            image_up: w.cross(right),
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
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    Diffuse,
    Specular,
    /// GGX microfacet conductor; roughness in [0, 1], GGX alpha = roughness².
    Metal {
        roughness: f32,
    },
    /// Smooth glass-like interface with this index of refraction.
    Dielectric {
        ior: f32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
    pub color: Vec3,
    /// `emission * strength`.
    pub emitted_radiance: Vec3,
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
}

/// The scene as the kernel reads it; the CPU reference traces from the same structs.
#[derive(Clone, Debug)]
pub struct KernelScene {
    pub params: Params,
    pub spheres: Vec<shader_types::Sphere>,
    pub quads: Vec<shader_types::Quad>,
    pub materials: Vec<shader_types::Material>,
    pub emitters: Vec<Emitter>,
}

impl Scene {
    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let bytes = std::fs::read(path).map_err(|e| SceneError {
            path: path.to_owned(),
            position: None,
            field: None,
            message: format!("cannot read the scene file: {e}"),
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
        raw.validate(name)
            .map_err(|e| at(e.span, Some(e.field), e.message))
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
        check_image_size(r.width as i64, r.height as i64)?;
        check_range(r.spp as i64, 1, MAX_SPP as i64).map_err(|m| format!("spp {m}"))?;
        check_range(r.max_bounces as i64, 0, MAX_BOUNCES_LIMIT as i64)
            .map_err(|m| format!("max_bounces {m}"))?;
        Ok(self)
    }

    /// Converts to the kernel's structs (camera basis precomputed, quads' duals, emission × strength).
    pub fn kernel_scene(&self) -> KernelScene {
        let c = &self.camera;
        let r = &self.render;
        let CameraBasis {
            w,
            right: u,
            image_up: v,
        } = c.basis();
        let half_height = (c.vfov.to_radians() * 0.5).tan();
        let half_width = half_height * r.width as f32 / r.height as f32;
        let lens_radius = 0.5 * c.aperture;
        let (emitters, sphere_light_probability, quad_light_probability) = self.emitter_table();
        let params = Params {
            eye: c.eye.into(),
            width: r.width,
            forward: (-w).into(),
            height: r.height,
            right: (u * half_width).into(),
            sample_start: 0,
            up: (v * half_height).into(),
            sample_count: 0,
            background: r.background.into(),
            max_bounces: r.max_bounces,
            lens_right: (u * lens_radius).into(),
            focus_distance: c.focus_distance,
            lens_up: (v * lens_radius).into(),
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
            pad0: 0,
            pad1: 0,
        };
        let spheres = self
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| shader_types::Sphere {
                center: s.center.into(),
                radius: s.radius,
                material: s.material,
                light_probability: sphere_light_probability[i],
                _pad: [0; 2],
            })
            .collect();
        let quads = self
            .quads
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let cross = q.u.cross(q.v);
                let normal = cross.normalize();
                shader_types::Quad {
                    corner: q.corner.into(),
                    material: q.material,
                    edge_u: q.u.into(),
                    area: cross.length(),
                    edge_v: q.v.into(),
                    plane_offset: normal.dot(q.corner),
                    normal: normal.into(),
                    light_probability: quad_light_probability[i],
                    u_dual: (q.u / q.u.dot(q.u)).into(),
                    v_dual: (q.v / q.v.dot(q.v)).into(),
                    ..Default::default()
                }
            })
            .collect();
        let materials = self
            .materials
            .iter()
            .map(|m| {
                let (kind, alpha, ior) = match m.kind {
                    MaterialKind::Diffuse => (MATERIAL_DIFFUSE, 0.0, 1.0),
                    MaterialKind::Specular => (MATERIAL_SPECULAR, 0.0, 1.0),
                    MaterialKind::Metal { roughness } => {
                        (MATERIAL_METAL, roughness * roughness, 1.0)
                    }
                    MaterialKind::Dielectric { ior } => (MATERIAL_DIELECTRIC, 0.0, ior),
                };
                shader_types::Material {
                    albedo: m.color.into(),
                    kind,
                    emission: m.emitted_radiance.into(),
                    alpha,
                    ior,
                    _pad: [0; 3],
                }
            })
            .collect();
        KernelScene {
            params,
            spheres,
            quads,
            materials,
            emitters,
        }
    }

    /// Every emitting primitive with its selection probability, proportional to its power
    /// (mean emitted radiance × area; the factor π is common to all), and that probability per
    /// sphere and per quad (0 for those that do not emit).
    fn emitter_table(&self) -> (Vec<Emitter>, Vec<f32>, Vec<f32>) {
        let radiance = |material: u32| self.materials[material as usize].emitted_radiance;
        let mut powers: Vec<(u32, u32, f64)> = Vec::new();
        for (i, s) in self.spheres.iter().enumerate() {
            let power = radiance(s.material).element_sum() as f64 / 3.0
                * 4.0
                * std::f64::consts::PI
                * (s.radius as f64).powi(2);
            if power > 0.0 {
                powers.push((PRIMITIVE_SPHERE, i as u32, power));
            }
        }
        for (i, q) in self.quads.iter().enumerate() {
            let power =
                radiance(q.material).element_sum() as f64 / 3.0 * q.u.cross(q.v).length() as f64;
            if power > 0.0 {
                powers.push((PRIMITIVE_QUAD, i as u32, power));
            }
        }
        let total: f64 = powers.iter().map(|p| p.2).sum();
        let mut cumulative = 0.0;
        let mut emitters: Vec<Emitter> = powers
            .iter()
            .map(|&(primitive, index, power)| {
                cumulative += power / total;
                Emitter {
                    primitive,
                    index,
                    cdf: cumulative as f32,
                    probability: (power / total) as f32,
                }
            })
            .collect();
        if let Some(last) = emitters.last_mut() {
            last.cdf = 1.0;
        }
        let mut sphere_probability = vec![0.0; self.spheres.len()];
        let mut quad_probability = vec![0.0; self.quads.len()];
        for e in &emitters {
            let per_primitive = if e.primitive == PRIMITIVE_SPHERE {
                &mut sphere_probability
            } else {
                &mut quad_probability
            };
            per_primitive[e.index as usize] = e.probability;
        }
        (emitters, sphere_probability, quad_probability)
    }
}

/// 1-based line and column (in characters) of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, text[line_start..offset].chars().count() + 1)
}

fn check_range(value: i64, min: i64, max: i64) -> Result<(), String> {
    if value < min || value > max {
        return Err(format!("must be in {min}..={max}, got {value}"));
    }
    Ok(())
}

fn check_image_size(width: i64, height: i64) -> Result<(), String> {
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

// ---- The file as written -------------------------------------------------------------------

/// A number: TOML integers are accepted where reals are meant (`radius = 90`).
#[derive(Clone, Copy, Debug)]
struct Real(f64);

impl<'de> Deserialize<'de> for Real {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct RealVisitor;
        impl Visitor<'_> for RealVisitor {
            type Value = Real;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Real, E> {
                Ok(Real(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Real, E> {
                Ok(Real(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Real, E> {
                Ok(Real(v as f64))
            }
        }
        d.deserialize_any(RealVisitor)
    }
}

type S<T> = Spanned<T>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneToml {
    camera: Option<S<CameraToml>>,
    render: Option<S<RenderToml>>,
    #[serde(default)]
    materials: BTreeMap<String, S<MaterialToml>>,
    #[serde(default)]
    spheres: Vec<S<SphereToml>>,
    #[serde(default)]
    quads: Vec<S<QuadToml>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraToml {
    eye: S<[Real; 3]>,
    target: S<[Real; 3]>,
    up: S<[Real; 3]>,
    vfov: S<Real>,
    aperture: Option<S<Real>>,
    focus_distance: Option<S<Real>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderToml {
    width: S<i64>,
    height: S<i64>,
    spp: S<i64>,
    max_bounces: S<i64>,
    background: Option<S<[Real; 3]>>,
    seed: Option<S<i64>>,
    light_sampling: Option<bool>,
    russian_roulette: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    #[serde(rename = "type")]
    kind: S<String>,
    color: Option<S<[Real; 3]>>,
    emission: Option<S<[Real; 3]>>,
    strength: Option<S<Real>>,
    roughness: Option<S<Real>>,
    ior: Option<S<Real>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereToml {
    center: S<[Real; 3]>,
    radius: S<Real>,
    material: S<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct QuadToml {
    corner: S<[Real; 3]>,
    u: S<[Real; 3]>,
    v: S<[Real; 3]>,
    material: S<String>,
}

/// A validation failure before it is given the file name and a line.
struct FieldError {
    span: Option<Range<usize>>,
    field: String,
    message: String,
}

fn fail<T>(
    span: Range<usize>,
    field: impl Into<String>,
    message: impl Into<String>,
) -> Result<T, FieldError> {
    Err(FieldError {
        span: Some(span),
        field: field.into(),
        message: message.into(),
    })
}

fn real(x: &S<Real>, field: &str) -> Result<f32, FieldError> {
    let v = x.get_ref().0;
    if !v.is_finite() {
        return fail(x.span(), field, format!("must be a finite number, got {v}"));
    }
    if v.abs() > f32::MAX as f64 {
        return fail(x.span(), field, format!("{v} does not fit a 32-bit float"));
    }
    Ok(v as f32)
}

fn vec3(x: &S<[Real; 3]>, field: &str) -> Result<Vec3, FieldError> {
    let mut out = [0.0f32; 3];
    for (o, r) in out.iter_mut().zip(x.get_ref()) {
        if !r.0.is_finite() || r.0.abs() > f32::MAX as f64 {
            return fail(
                x.span(),
                field,
                format!(
                    "every component must be a finite 32-bit number, got {}",
                    r.0
                ),
            );
        }
        *o = r.0 as f32;
    }
    Ok(Vec3::from(out))
}

fn non_negative(x: &S<[Real; 3]>, field: &str) -> Result<Vec3, FieldError> {
    let v = vec3(x, field)?;
    if v.min_element() < 0.0 {
        return fail(x.span(), field, format!("components must be ≥ 0, got {v}"));
    }
    Ok(v)
}

fn int_in(x: &S<i64>, field: &str, min: i64, max: i64) -> Result<u32, FieldError> {
    check_range(*x.get_ref(), min, max)
        .map(|_| *x.get_ref() as u32)
        .or_else(|m| fail(x.span(), field, m))
}

impl SceneToml {
    fn validate(self, name: String) -> Result<Scene, FieldError> {
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
        let camera = camera.into_inner();
        let render = self.render.ok_or_else(|| {
            whole(
                "[render]",
                "missing: the scene needs a [render] table".into(),
            )
        })?;
        let render_span = render.span();
        let render = render.into_inner();

        let eye = vec3(&camera.eye, "camera.eye")?;
        let target = vec3(&camera.target, "camera.target")?;
        let up = vec3(&camera.up, "camera.up")?;
        let vfov = real(&camera.vfov, "camera.vfov")?;
        if !(vfov > 0.0 && vfov < 180.0) {
            return fail(
                camera.vfov.span(),
                "camera.vfov",
                format!("must be in (0, 180) degrees, got {vfov}"),
            );
        }
        let view = target - eye;
        if view.length() == 0.0 || !view.length().is_finite() {
            return fail(
                camera.target.span(),
                "camera.target",
                "must differ from camera.eye (the view direction is target − eye)",
            );
        }
        if up.cross(view).length() <= 1e-6 * up.length() * view.length() {
            return fail(
                camera.up.span(),
                "camera.up",
                format!(
                    "must not be zero or parallel to the view direction {}",
                    view.normalize()
                ),
            );
        }
        let aperture = match &camera.aperture {
            Some(a) => {
                let v = real(a, "camera.aperture")?;
                if v < 0.0 {
                    return fail(
                        a.span(),
                        "camera.aperture",
                        format!("the lens diameter must be ≥ 0, got {v}"),
                    );
                }
                v
            }
            None => 0.0,
        };
        let focus_distance = match &camera.focus_distance {
            Some(f) => {
                let v = real(f, "camera.focus_distance")?;
                if v <= 0.0 {
                    return fail(
                        f.span(),
                        "camera.focus_distance",
                        format!("must be > 0, got {v}"),
                    );
                }
                v
            }
            None => view.length(),
        };

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
            Some(b) => non_negative(b, "render.background")?,
            None => Vec3::ZERO,
        };
        let seed = match &render.seed {
            Some(s) => int_in(s, "render.seed", 0, u32::MAX as i64)?,
            None => 0,
        };

        let mut materials = Vec::new();
        let mut index_of = BTreeMap::new();
        for (name, m) in &self.materials {
            let m = m.get_ref();
            let field = |f: &str| format!("materials.{name}.{f}");
            let positive =
                |x: &Option<S<Real>>, name: &str, what: &str| -> Result<f32, FieldError> {
                    let Some(x) = x else {
                        return fail(
                            m.kind.span(),
                            field(name),
                            format!("missing: a {what} needs {name}"),
                        );
                    };
                    real(x, &field(name))
                };
            let kind = match m.kind.get_ref().as_str() {
                "diffuse" => MaterialKind::Diffuse,
                "specular" => MaterialKind::Specular,
                "metal" => {
                    let roughness = positive(&m.roughness, "roughness", "metal")?;
                    if !(0.0..=1.0).contains(&roughness) {
                        return fail(
                            m.roughness.as_ref().unwrap().span(),
                            field("roughness"),
                            format!("must be in [0, 1] (0 = mirror), got {roughness}"),
                        );
                    }
                    MaterialKind::Metal { roughness }
                }
                "dielectric" => {
                    let ior = positive(&m.ior, "ior", "dielectric")?;
                    if ior <= 0.0 {
                        return fail(
                            m.ior.as_ref().unwrap().span(),
                            field("ior"),
                            format!("the index of refraction must be > 0, got {ior}"),
                        );
                    }
                    MaterialKind::Dielectric { ior }
                }
                other => {
                    return fail(
                        m.kind.span(),
                        field("type"),
                        format!(
                            "unknown material type {other:?}; known types: \"diffuse\", \"specular\", \"metal\", \"dielectric\""
                        ),
                    )
                }
            };
            // A field that does not apply is most likely a mistake: say so.
            for (value, name, applies) in [
                (
                    &m.roughness,
                    "roughness",
                    matches!(kind, MaterialKind::Metal { .. }),
                ),
                (
                    &m.ior,
                    "ior",
                    matches!(kind, MaterialKind::Dielectric { .. }),
                ),
            ] {
                if let (Some(v), false) = (value, applies) {
                    return fail(
                        v.span(),
                        field(name),
                        format!("{name} does not apply to a {} material", m.kind.get_ref()),
                    );
                }
            }
            let color = match (&m.color, kind) {
                (Some(c), _) => {
                    let color = non_negative(c, &field("color"))?;
                    if color.max_element() > 1.0 {
                        return fail(
                            c.span(),
                            field("color"),
                            format!("a reflectance must be in [0, 1] (more would create energy), got {color}"),
                        );
                    }
                    color
                }
                // Clear glass unless tinted.
                (None, MaterialKind::Dielectric { .. }) => Vec3::ONE,
                (None, _) => {
                    return fail(
                        m.kind.span(),
                        field("color"),
                        "missing: this material needs a color",
                    );
                }
            };
            let emission = match &m.emission {
                Some(e) => non_negative(e, &field("emission"))?,
                None => Vec3::ZERO,
            };
            let strength = match &m.strength {
                Some(s) => {
                    let v = real(s, &field("strength"))?;
                    if v < 0.0 {
                        return fail(s.span(), field("strength"), format!("must be ≥ 0, got {v}"));
                    }
                    v
                }
                None => 1.0,
            };
            index_of.insert(name.clone(), materials.len() as u32);
            materials.push(Material {
                name: name.clone(),
                kind,
                color,
                emitted_radiance: emission * strength,
            });
        }
        let material_ref = |m: &S<String>, field: String| -> Result<u32, FieldError> {
            index_of.get(m.get_ref()).copied().ok_or_else(|| {
                let known: Vec<_> = index_of.keys().map(|k| format!("{k:?}")).collect();
                FieldError {
                    span: Some(m.span()),
                    field,
                    message: format!(
                        "unknown material {:?}; defined materials: {}",
                        m.get_ref(),
                        if known.is_empty() {
                            "none".into()
                        } else {
                            known.join(", ")
                        }
                    ),
                }
            })
        };

        let mut spheres = Vec::new();
        for (i, s) in self.spheres.iter().enumerate() {
            let s = s.get_ref();
            let field = |f: &str| format!("spheres[{i}].{f}");
            let center = vec3(&s.center, &field("center"))?;
            let radius = real(&s.radius, &field("radius"))?;
            if radius <= 0.0 {
                return fail(
                    s.radius.span(),
                    field("radius"),
                    format!("must be > 0, got {radius}"),
                );
            }
            let material = material_ref(&s.material, field("material"))?;
            spheres.push(Sphere {
                center,
                radius,
                material,
            });
        }
        let mut quads = Vec::new();
        for (i, q) in self.quads.iter().enumerate() {
            let q = q.get_ref();
            let field = |f: &str| format!("quads[{i}].{f}");
            let corner = vec3(&q.corner, &field("corner"))?;
            let u = vec3(&q.u, &field("u"))?;
            let v = vec3(&q.v, &field("v"))?;
            let area = u.cross(v).length();
            if !area.is_finite() || area <= 1e-6 * u.length() * v.length() {
                return fail(
                    q.v.span(),
                    field("v"),
                    format!("degenerate quad: edges u = {u} and v = {v} are parallel or zero"),
                );
            }
            let material = material_ref(&q.material, field("material"))?;
            quads.push(Quad {
                corner,
                u,
                v,
                material,
            });
        }
        Ok(Scene {
            name,
            camera: Camera {
                eye,
                target,
                up,
                vfov,
                aperture,
                focus_distance,
            },
            render: RenderSettings {
                width: width as u32,
                height: height as u32,
                spp,
                max_bounces,
                background,
                seed,
                light_sampling: render.light_sampling.unwrap_or(true),
                russian_roulette: render.russian_roulette.unwrap_or(true),
            },
            materials,
            spheres,
            quads,
        })
    }
}
