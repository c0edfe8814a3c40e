//! `[camera]`: given by eye, target, up and vfov (or `projection = "orthographic"` and the
//! view's `height`), or taken from a glTF file (`from`, `index`).

use super::super::file::{CameraToml, S};
use super::super::limits::{MIN_LENGTH, MIN_SINE};
use super::super::mesh;
use super::super::{Camera, Projection};
use super::fields::{coordinates, fail, length_in_range, real, sine_between, vec3, FieldError};
use glam::Vec3;
use std::ops::Range;
use std::path::Path;

/// The camera, its file (`from`) read relative to `folder`; `span` is the `[camera]` table's.
pub(super) fn validate_camera(
    camera: &CameraToml,
    span: Range<usize>,
    folder: &Path,
) -> Result<Camera, FieldError> {
    let (eye, target, up, projection) = match &camera.from {
        Some(from) => from_file(camera, from, folder)?,
        None => given(camera, span)?,
    };
    if let Projection::Orthographic { .. } = projection {
        // Depth of field is a lens's, and an orthographic camera has none.
        let lens = [
            ("aperture", camera.aperture.as_ref()),
            ("focus_distance", camera.focus_distance.as_ref()),
        ];
        for (name, given) in lens {
            if let Some(x) = given {
                return fail(
                    x.span(),
                    format!("camera.{name}"),
                    "an orthographic camera has no lens: thin-lens depth of field does not \
                     apply to it (leave aperture and focus_distance out)",
                );
            }
        }
    }
    let view = target - eye;
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
    Ok(Camera {
        eye,
        target,
        up,
        projection,
        aperture,
        focus_distance,
    })
}

/// Whether `projection = ...` names the orthographic projection (or the perspective one).
fn is_orthographic(projection: &S<String>) -> Result<bool, FieldError> {
    match projection.get_ref().as_str() {
        "perspective" => Ok(false),
        "orthographic" => Ok(true),
        other => fail(
            projection.span(),
            "camera.projection",
            format!("unknown projection {other:?}; known: \"perspective\", \"orthographic\""),
        ),
    }
}

/// Eye, target, up and vfov (or height) as the file gives them, checked.
fn given(
    camera: &CameraToml,
    span: Range<usize>,
) -> Result<(Vec3, Vec3, Vec3, Projection), FieldError> {
    if let Some(index) = &camera.index {
        return fail(
            index.span(),
            "camera.index",
            "index picks one of a file's cameras: it needs camera.from",
        );
    }
    let orthographic = match &camera.projection {
        Some(p) => is_orthographic(p)?,
        None => false,
    };
    let needs = if orthographic {
        "an orthographic camera needs eye, target, up and height"
    } else {
        "the camera needs eye, target, up and vfov, or from = a glTF file"
    };
    let missing = |name: &str| FieldError {
        span: Some(span.clone()),
        field: format!("camera.{name}"),
        message: format!("missing: {needs}"),
    };
    let eye = camera.eye.as_ref().ok_or_else(|| missing("eye"))?;
    let target = camera.target.as_ref().ok_or_else(|| missing("target"))?;
    let up_given = camera.up.as_ref().ok_or_else(|| missing("up"))?;
    // The view's size: the field of view, or an orthographic camera's height; not both.
    let size_given = if orthographic {
        if let Some(vfov) = &camera.vfov {
            return fail(
                vfov.span(),
                "camera.vfov",
                "an orthographic camera has no field of view: camera.height is its view's \
                 height in world units",
            );
        }
        camera.height.as_ref().ok_or_else(|| missing("height"))?
    } else {
        if let Some(height) = &camera.height {
            return fail(
                height.span(),
                "camera.height",
                "the view's height is an orthographic camera's (projection = \
                 \"orthographic\"); a perspective camera's view is set by vfov",
            );
        }
        camera.vfov.as_ref().ok_or_else(|| missing("vfov"))?
    };
    let eye = coordinates(eye, "camera.eye")?;
    let target_value = coordinates(target, "camera.target")?;
    let up = vec3(up_given, "camera.up")?;
    let projection = if orthographic {
        let height = real(size_given, "camera.height")?;
        if height <= 0.0 {
            return fail(
                size_given.span(),
                "camera.height",
                format!("the view's height must be > 0, got {height}"),
            );
        }
        Projection::Orthographic {
            height: length_in_range(size_given, "camera.height", height, MIN_LENGTH)?,
        }
    } else {
        let vfov = real(size_given, "camera.vfov")?;
        if !(vfov > 0.0 && vfov < 180.0) {
            return fail(
                size_given.span(),
                "camera.vfov",
                format!("must be in (0, 180) degrees, got {vfov}"),
            );
        }
        Projection::Perspective { vfov }
    };
    let view = target_value - eye;
    if view.as_dvec3().length() == 0.0 {
        return fail(
            target.span(),
            "camera.target",
            "must differ from camera.eye (the view direction is target − eye)",
        );
    }
    if up == Vec3::ZERO || sine_between(up, view) <= MIN_SINE {
        return fail(
            up_given.span(),
            "camera.up",
            format!(
                "must not be zero or parallel to the view direction {}",
                view.normalize()
            ),
        );
    }
    Ok((eye, target_value, up, projection))
}

/// The camera of the glTF file `from` names: its `index`-th, or its first one.
fn from_file(
    camera: &CameraToml,
    from: &S<String>,
    folder: &Path,
) -> Result<(Vec3, Vec3, Vec3, Projection), FieldError> {
    let given = [
        ("eye", camera.eye.as_ref().map(|x| x.span())),
        ("target", camera.target.as_ref().map(|x| x.span())),
        ("up", camera.up.as_ref().map(|x| x.span())),
        ("vfov", camera.vfov.as_ref().map(|x| x.span())),
        ("projection", camera.projection.as_ref().map(|x| x.span())),
        ("height", camera.height.as_ref().map(|x| x.span())),
    ];
    for (name, span) in given {
        if let Some(span) = span {
            return fail(
                span,
                format!("camera.{name}"),
                "give either camera.from (a glTF file's camera, its projection included) or \
                 eye, target, up and vfov (or projection and height), not both",
            );
        }
    }
    let index = match &camera.index {
        Some(i) => {
            let v = *i.get_ref();
            if v < 0 {
                return fail(i.span(), "camera.index", format!("must be ≥ 0, got {v}"));
            }
            Some(v as usize)
        }
        None => None,
    };
    let file = from.get_ref();
    let path = folder.join(file);
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if !matches!(extension.as_str(), "gltf" | "glb") {
        return fail(
            from.span(),
            "camera.from",
            format!("{file}: only a glTF file (.gltf, .glb) holds cameras"),
        );
    }
    let found = mesh::gltf_camera(&path, index).map_err(|message| {
        let span = match (&camera.index, message.starts_with("there is no camera")) {
            (Some(i), true) => i.span(),
            _ => from.span(),
        };
        FieldError {
            span: Some(span),
            field: if camera.index.is_some() && message.starts_with("there is no camera") {
                "camera.index".into()
            } else {
                "camera.from".into()
            },
            message: format!("{file}: {message}"),
        }
    })?;
    let Some(c) = found else {
        return fail(
            from.span(),
            "camera.from",
            format!("{file}: the file has no camera"),
        );
    };
    Ok((c.eye, c.target(), c.up, c.projection))
}
