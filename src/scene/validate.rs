//! From the file as written to a validated [`Scene`]: every range, reference and degenerate
//! case checked, each failure tied to its field and its place in the file.

use super::environment::{self, Environment};
use super::file::{EnvironmentToml, Real, RoughnessToml, ScaleToml, SceneToml, Triple, S};
use super::limits::{MAX_COORDINATE, MAX_IOR, MAX_RADIANCE, MIN_IOR, MIN_LENGTH, MIN_SINE};
use super::mesh::{self, MeshTransform};
use super::texture::{TextureSet, TextureUse};
use super::{
    check_image_size, check_range, Camera, Material, MaterialKind, Quad, RenderSettings, Scene,
    Sphere, MAX_BOUNCES_LIMIT, MAX_IMAGE_SIDE, MAX_SPP,
};
use glam::{DVec3, Vec3};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

/// A validation failure before it is given the file name and a line.
pub(super) struct FieldError {
    pub(super) span: Option<Range<usize>>,
    pub(super) field: String,
    pub(super) message: String,
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

/// A 3-vector: exactly three finite numbers (integers accepted), each fitting an f32.
fn vec3(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
    let toml::Value::Array(items) = x.get_ref() else {
        return fail(
            x.span(),
            field,
            format!(
                "must be an array of three numbers [x, y, z], got a {}",
                x.get_ref().type_str()
            ),
        );
    };
    if items.len() != 3 {
        return fail(
            x.span(),
            field,
            format!(
                "must be exactly three numbers [x, y, z], got {} elements",
                items.len()
            ),
        );
    }
    let mut out = [0.0f32; 3];
    for (i, (o, item)) in out.iter_mut().zip(items).enumerate() {
        let v = match item {
            toml::Value::Float(v) => *v,
            toml::Value::Integer(v) => *v as f64,
            other => {
                return fail(
                    x.span(),
                    field,
                    format!(
                        "element {i} must be a number, got a {} ({other})",
                        other.type_str()
                    ),
                )
            }
        };
        if !v.is_finite() || v.abs() > f32::MAX as f64 {
            return fail(
                x.span(),
                field,
                format!("every component must be a finite 32-bit number, got {v}"),
            );
        }
        *o = v as f32;
    }
    Ok(Vec3::from(out))
}

/// A point or an edge vector: a 3-vector within the supported coordinate range.
fn coordinates(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
    let v = vec3(x, field)?;
    if v.abs().max_element() > MAX_COORDINATE {
        return fail(
            x.span(),
            field,
            format!(
                "every component must be within ±{MAX_COORDINATE:e} (the numeric range glint \
                 supports), got {v}"
            ),
        );
    }
    Ok(v)
}

/// A length with a lower bound of `min` (0 or [`MIN_LENGTH`]) and the coordinate range's
/// upper bound.
fn length_in_range(x: &S<Real>, field: &str, value: f32, min: f32) -> Result<f32, FieldError> {
    if !(min..=MAX_COORDINATE).contains(&value) {
        return fail(
            x.span(),
            field,
            format!(
                "must be in [{}, {MAX_COORDINATE:e}] (the numeric range glint supports), got \
                 {value:e}",
                if min == 0.0 {
                    "0".into()
                } else {
                    format!("{min:e}")
                }
            ),
        );
    }
    Ok(value)
}

fn non_negative(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
    let v = vec3(x, field)?;
    if v.min_element() < 0.0 {
        return fail(x.span(), field, format!("components must be ≥ 0, got {v}"));
    }
    Ok(v)
}

/// A radiance (emitted or background): ≥ 0 and at most [`MAX_RADIANCE`] per channel.
fn radiance_in_range(span: Range<usize>, field: &str, value: DVec3) -> Result<(), FieldError> {
    if value.max_element() > MAX_RADIANCE {
        return fail(
            span,
            field,
            format!(
                "a radiance of {:e} is too bright: at most {MAX_RADIANCE:e} per channel (the \
                 numeric range glint supports)",
                value.max_element()
            ),
        );
    }
    Ok(())
}

/// Sine of the angle between two non-zero vectors, in f64 so that short or long ones neither
/// underflow nor overflow.
fn sine_between(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3().normalize(), b.as_dvec3().normalize());
    a.cross(b).length()
}

fn int_in(x: &S<i64>, field: &str, min: i64, max: i64) -> Result<u32, FieldError> {
    check_range(*x.get_ref(), min, max)
        .map(|_| *x.get_ref() as u32)
        .or_else(|m| fail(x.span(), field, m))
}

/// `[environment]`: the map read relative to `folder`, its strength and rotation in range.
fn validate_environment(
    e: &S<EnvironmentToml>,
    has_background: bool,
    folder: &Path,
) -> Result<Environment, FieldError> {
    if has_background {
        return fail(
            e.span(),
            "environment",
            "give either render.background (a constant colour) or [environment] (a map), not both",
        );
    }
    let e_span = e.span();
    let e = e.get_ref();
    let strength = match &e.strength {
        Some(s) => {
            let v = real(s, "environment.strength")?;
            if !(0.0..=MAX_RADIANCE as f32).contains(&v) {
                return fail(
                    s.span(),
                    "environment.strength",
                    format!("must be in [0, {MAX_RADIANCE:e}], got {v}"),
                );
            }
            v
        }
        None => 1.0,
    };
    let rotate = match &e.rotate {
        Some(r) => {
            let v = real(r, "environment.rotate")?;
            if v.abs() > 360.0 {
                return fail(
                    r.span(),
                    "environment.rotate",
                    format!("must be in [-360, 360] degrees, got {v}"),
                );
            }
            v
        }
        None => 0.0,
    };
    let file = e.file.get_ref();
    if file.is_empty() {
        return fail(e_span, "environment.file", "must name an image file");
    }
    environment::load(&folder.join(file), strength, rotate).or_else(|message| {
        fail(
            e.file.span(),
            "environment.file",
            format!("{file}: {message}"),
        )
    })
}

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
        let camera = camera.into_inner();
        let render = self.render.ok_or_else(|| {
            whole(
                "[render]",
                "missing: the scene needs a [render] table".into(),
            )
        })?;
        let render_span = render.span();
        let render = render.into_inner();

        let eye = coordinates(&camera.eye, "camera.eye")?;
        let target = coordinates(&camera.target, "camera.target")?;
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
        if view.as_dvec3().length() == 0.0 {
            return fail(
                camera.target.span(),
                "camera.target",
                "must differ from camera.eye (the view direction is target − eye)",
            );
        }
        if up == Vec3::ZERO || sine_between(up, view) <= MIN_SINE {
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
                length_in_range(a, "camera.aperture", v, 0.0)?
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
                length_in_range(f, "camera.focus_distance", v, MIN_LENGTH)?
            }
            None => view.as_dvec3().length() as f32,
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

        let mut materials = Vec::new();
        let mut textures = TextureSet::default();
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
                    let Some(r) = &m.roughness else {
                        return fail(
                            m.kind.span(),
                            field("roughness"),
                            "missing: a metal needs roughness",
                        );
                    };
                    let roughness = match r.get_ref() {
                        RoughnessToml::Value(v) => {
                            real(&S::new(r.span(), *v), &field("roughness"))?
                        }
                        // A texture (read below); the constant is unused.
                        RoughnessToml::Other(_) => 1.0,
                    };
                    if !(0.0..=1.0).contains(&roughness) {
                        return fail(
                            r.span(),
                            field("roughness"),
                            format!("must be in [0, 1] (0 = mirror), got {roughness}"),
                        );
                    }
                    MaterialKind::Metal { roughness }
                }
                "dielectric" => {
                    let ior = positive(&m.ior, "ior", "dielectric")?;
                    if !(MIN_IOR..=MAX_IOR).contains(&ior) {
                        return fail(
                            m.ior.as_ref().unwrap().span(),
                            field("ior"),
                            format!(
                                "the index of refraction must be in [{MIN_IOR}, {MAX_IOR}] (the \
                                 numeric range glint supports), got {ior}"
                            ),
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
            for (span, name, applies) in [
                (
                    m.roughness.as_ref().map(|r| r.span()),
                    "roughness",
                    matches!(kind, MaterialKind::Metal { .. }),
                ),
                (
                    m.ior.as_ref().map(|r| r.span()),
                    "ior",
                    matches!(kind, MaterialKind::Dielectric { .. }),
                ),
            ] {
                if let (Some(span), false) = (span, applies) {
                    return fail(
                        span,
                        field(name),
                        format!("{name} does not apply to a {} material", m.kind.get_ref()),
                    );
                }
            }
            let roughness_texture = match &m.roughness {
                Some(r) => match r.get_ref() {
                    RoughnessToml::Other(value) => Some(texture(
                        &S::new(r.span(), value.clone()),
                        &field("roughness"),
                        folder,
                        TextureUse::Roughness,
                        &mut textures,
                    )?),
                    RoughnessToml::Value(_) => None,
                },
                None => None,
            };
            let color_texture = match &m.color {
                Some(c) if c.get_ref().is_table() => Some(texture(
                    c,
                    &field("color"),
                    folder,
                    TextureUse::Color,
                    &mut textures,
                )?),
                _ => None,
            };
            let color = match (&m.color, kind) {
                // Textured: the constant is unused.
                (Some(_), _) if color_texture.is_some() => Vec3::ONE,
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
            let emission =
                match &m.emission {
                    Some(e) if e.get_ref().is_table() => return fail(
                        e.span(),
                        field("emission"),
                        "takes no texture: only color (and a metal's roughness) may be textured",
                    ),
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
            // Each factor may be in range and the product not (1e30 × 1e30): check the product,
            // in f64, where it is exact enough and cannot overflow.
            if let Some(e) = &m.emission {
                let span = m.strength.as_ref().map_or(e.span(), |s| s.span());
                radiance_in_range(
                    span,
                    &field("emission × strength"),
                    emission.as_dvec3() * strength as f64,
                )?;
            }
            index_of.insert(name.clone(), materials.len() as u32);
            materials.push(Material {
                name: name.clone(),
                kind,
                color,
                emitted_radiance: emission * strength,
                color_texture,
                roughness_texture,
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
            let center = coordinates(&s.center, &field("center"))?;
            let radius = real(&s.radius, &field("radius"))?;
            if radius <= 0.0 {
                return fail(
                    s.radius.span(),
                    field("radius"),
                    format!("must be > 0, got {radius}"),
                );
            }
            length_in_range(&s.radius, &field("radius"), radius, MIN_LENGTH)?;
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
            let corner = coordinates(&q.corner, &field("corner"))?;
            let u = coordinates(&q.u, &field("u"))?;
            let v = coordinates(&q.v, &field("v"))?;
            // Scale-relative: the angle between the edges, not the area against a fixed bound.
            if u == Vec3::ZERO || v == Vec3::ZERO || sine_between(u, v) <= MIN_SINE {
                return fail(
                    q.v.span(),
                    field("v"),
                    format!("degenerate quad: edges u = {u} and v = {v} are parallel or zero"),
                );
            }
            for (edge, name, span) in [(u, "u", q.u.span()), (v, "v", q.v.span())] {
                let length = edge.as_dvec3().length();
                if length < MIN_LENGTH as f64 {
                    return fail(
                        span,
                        field(name),
                        format!(
                            "the edge is {length:e} long, shorter than {MIN_LENGTH:e} (the \
                             numeric range glint supports)"
                        ),
                    );
                }
            }
            let material = material_ref(&q.material, field("material"))?;
            quads.push(Quad {
                corner,
                u,
                v,
                material,
            });
        }
        let mut triangles = Vec::new();
        let mut warnings = Vec::new();
        for (i, m) in self.meshes.iter().enumerate() {
            let m = m.get_ref();
            let field = |f: &str| format!("meshes[{i}].{f}");
            let translate = match &m.translate {
                Some(t) => coordinates(t, &field("translate"))?,
                None => Vec3::ZERO,
            };
            let rotate = match &m.rotate {
                Some(r) => vec3(r, &field("rotate"))?,
                None => Vec3::ZERO,
            };
            let scale = match &m.scale {
                None => Vec3::ONE,
                Some(s) => {
                    let v = match s.get_ref() {
                        ScaleToml::Uniform(r) => Vec3::splat(r.0 as f32),
                        ScaleToml::PerAxis(a) => {
                            Vec3::new(a[0].0 as f32, a[1].0 as f32, a[2].0 as f32)
                        }
                    };
                    if !v.is_finite() || v.min_element() <= 0.0 {
                        return fail(
                            s.span(),
                            field("scale"),
                            format!("degenerate transform: every scale factor must be finite and > 0, got {v}"),
                        );
                    }
                    v
                }
            };
            let material = match &m.material {
                Some(name) => Some(material_ref(name, field("material"))?),
                None => None,
            };
            let file = m.file.get_ref();
            let loaded = mesh::load(
                &folder.join(file),
                file,
                &MeshTransform {
                    scale,
                    rotate_degrees: rotate,
                    translate,
                },
                material,
                m.smooth.unwrap_or(true),
                &mut materials,
                &mut textures,
            )
            .or_else(|message| fail(m.file.span(), field("file"), message))?;
            warnings.extend(loaded.warnings);
            triangles.extend(loaded.triangles);
            if triangles.len() > mesh::MAX_TRIANGLES {
                return fail(
                    m.file.span(),
                    field("file"),
                    format!(
                        "the scene's meshes hold more than {} triangles",
                        mesh::MAX_TRIANGLES
                    ),
                );
            }
        }
        let environment = match &self.environment {
            Some(e) => {
                let environment = validate_environment(e, render.background.is_some(), folder)?;
                if let Some(clamped) = environment.image.clamped {
                    warnings.push(format!(
                        "{}: {}",
                        e.get_ref().file.get_ref(),
                        clamped.warning()
                    ));
                }
                Some(environment)
            }
            None => None,
        };
        warnings.append(&mut textures.warnings);
        let scene = Scene {
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
            triangles,
            textures,
            environment,
        };
        Ok((scene, warnings))
    }
}

/// A texture as written in a material field: `{ texture = "file" }` (relative to `folder`) or
/// `{ checker = [[r, g, b], [r, g, b]], scale = s }` (scale optional, default 1). Returns its
/// index in `textures`.
fn texture(
    x: &S<toml::Value>,
    field: &str,
    folder: &Path,
    usage: TextureUse,
    textures: &mut TextureSet,
) -> Result<u32, FieldError> {
    let expected = "must be a constant, { texture = \"file.png\" } or { checker = [[r, g, b], [r, g, b]], scale = s }";
    let Some(table) = x.get_ref().as_table() else {
        return fail(x.span(), field, format!("{expected}, got {}", x.get_ref()));
    };
    let keys: Vec<&str> = table.keys().map(|k| k.as_str()).collect();
    match keys.as_slice() {
        ["texture"] => {
            let Some(file) = table["texture"].as_str() else {
                return fail(x.span(), field, "texture must be a file name (a string)");
            };
            textures
                .image(&folder.join(file), usage)
                .or_else(|message| fail(x.span(), field, format!("{file}: {message}")))
        }
        ["checker"] | ["checker", "scale"] | ["scale", "checker"] => {
            let colors = match table["checker"].as_array() {
                Some(c) if c.len() == 2 => c,
                _ => {
                    return fail(
                        x.span(),
                        field,
                        "checker must be two colors [[r, g, b], [r, g, b]]",
                    )
                }
            };
            let mut pair = [Vec3::ZERO; 2];
            for (out, c) in pair.iter_mut().zip(colors) {
                let color = vec3(&S::new(x.span(), c.clone()), &format!("{field}.checker"))?;
                if color.min_element() < 0.0 || color.max_element() > 1.0 {
                    return fail(
                        x.span(),
                        format!("{field}.checker"),
                        format!("every value must be in [0, 1], got {color}"),
                    );
                }
                *out = color;
            }
            let scale = match table.get("scale") {
                None => 1.0,
                Some(toml::Value::Float(v)) => *v,
                Some(toml::Value::Integer(v)) => *v as f64,
                Some(other) => {
                    return fail(
                        x.span(),
                        format!("{field}.scale"),
                        format!("must be a number, got {other}"),
                    )
                }
            };
            if !(scale > 0.0 && scale <= 1e6) {
                return fail(
                    x.span(),
                    format!("{field}.scale"),
                    format!("must be in (0, 1e6] squares per unit of u and v, got {scale}"),
                );
            }
            Ok(textures.checker(pair, scale as f32))
        }
        _ => fail(
            x.span(),
            field,
            format!("{expected}; unknown keys: {}", keys.join(", ")),
        ),
    }
}
