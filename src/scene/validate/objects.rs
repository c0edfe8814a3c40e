//! `[[spheres]]`, `[[quads]]` and `[[meshes]]`: the scene's geometry.

use super::super::file::{MeshToml, QuadToml, ScaleToml, SphereToml, S};
use super::super::light::Light;
use super::super::limits::{MIN_LENGTH, MIN_SINE};
use super::super::mesh::{self, MeshTransform};
use super::super::{AlphaMode, Material, Quad, Sphere, Triangle};
use super::fields::{coordinates, fail, length_in_range, real, sine_between, vec3, FieldError};
use super::materials::Materials;
use glam::Vec3;
use std::path::Path;

/// The scene's geometry, and warnings to print (from mesh files).
pub(super) struct Objects {
    pub(super) spheres: Vec<Sphere>,
    pub(super) quads: Vec<Quad>,
    pub(super) triangles: Vec<Triangle>,
    /// The punctual lights of glTF files (`[[meshes]] lights`, default true).
    pub(super) lights: Vec<Light>,
    pub(super) warnings: Vec<String>,
}

/// One warning per material that is alpha-tested or blended but used by spheres or quads,
/// which are always opaque (src/cpu/alpha.rs): alpha applies to meshes only.
fn opaque_only_warnings(spheres: &[Sphere], quads: &[Quad], materials: &[Material]) -> Vec<String> {
    let used = spheres
        .iter()
        .map(|s| s.material)
        .chain(quads.iter().map(|q| q.material))
        .collect::<std::collections::BTreeSet<_>>();
    used.into_iter()
        .map(|m| &materials[m as usize])
        .filter(|m| m.alpha.mode != AlphaMode::Opaque)
        .map(|m| {
            format!(
                "materials.{}: its alpha_mode applies to meshes only; spheres and quads that use \
                 it are opaque",
                m.name
            )
        })
        .collect()
}

/// The scene's spheres, quads and meshes (read relative to `folder`; their own materials are
/// added to `materials`).
pub(super) fn validate_objects(
    spheres_toml: &[S<SphereToml>],
    quads_toml: &[S<QuadToml>],
    meshes_toml: &[S<MeshToml>],
    folder: &Path,
    materials: &mut Materials,
) -> Result<Objects, FieldError> {
    let mut spheres = Vec::new();
    for (i, s) in spheres_toml.iter().enumerate() {
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
        let material = materials.reference(&s.material, field("material"))?;
        spheres.push(Sphere {
            center,
            radius,
            material,
        });
    }
    let mut quads = Vec::new();
    for (i, q) in quads_toml.iter().enumerate() {
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
        let material = materials.reference(&q.material, field("material"))?;
        quads.push(Quad {
            corner,
            u,
            v,
            material,
        });
    }
    let mut triangles = Vec::new();
    let mut lights = Vec::new();
    let mut warnings = opaque_only_warnings(&spheres, &quads, &materials.list);
    for (i, m) in meshes_toml.iter().enumerate() {
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
                    ScaleToml::PerAxis(a) => Vec3::new(a[0].0 as f32, a[1].0 as f32, a[2].0 as f32),
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
            Some(name) => Some(materials.reference(name, field("material"))?),
            None => None,
        };
        let file = m.file.get_ref();
        let transform = MeshTransform {
            scale,
            rotate_degrees: rotate,
            translate,
        };
        let loaded = mesh::load(
            &folder.join(file),
            file,
            &transform,
            material,
            m.smooth.unwrap_or(true),
            &mut materials.list,
            &mut materials.textures,
        )
        .or_else(|message| fail(m.file.span(), field("file"), message))?;
        warnings.extend(loaded.warnings);
        triangles.extend(loaded.triangles);
        if m.lights.unwrap_or(true) && mesh::is_gltf(Path::new(file)) {
            let (mut file_lights, file_warnings) =
                mesh::gltf_lights(&folder.join(file), transform.matrix()).or_else(|message| {
                    fail(m.file.span(), field("file"), format!("{file}: {message}"))
                })?;
            lights.append(&mut file_lights);
            warnings.extend(file_warnings.into_iter().map(|w| format!("{file}: {w}")));
        }
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
    Ok(Objects {
        spheres,
        quads,
        triangles,
        lights,
        warnings,
    })
}
