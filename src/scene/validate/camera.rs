//! `[camera]`: given by eye, target, up and vfov, or taken from a glTF file (`from`,
//! `index`).

use super::super::file::{CameraToml, S};
use super::super::limits::{MIN_LENGTH, MIN_SINE};
use super::super::mesh;
use super::super::Camera;
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
    let (eye, target, up, vfov) = match &camera.from {
        Some(from) => from_file(camera, from, folder)?,
        None => given(camera, span)?,
    };
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
        vfov,
        aperture,
        focus_distance,
    })
}

/// Eye, target, up and vfov as the file gives them, checked.
fn given(camera: &CameraToml, span: Range<usize>) -> Result<(Vec3, Vec3, Vec3, f32), FieldError> {
    if let Some(index) = &camera.index {
        return fail(
            index.span(),
            "camera.index",
            "index picks one of a file's cameras: it needs camera.from",
        );
    }
    let missing = |name: &str| FieldError {
        span: Some(span.clone()),
        field: format!("camera.{name}"),
        message: "missing: the camera needs eye, target, up and vfov, or from = a glTF file".into(),
    };
    let eye = camera.eye.as_ref().ok_or_else(|| missing("eye"))?;
    let target = camera.target.as_ref().ok_or_else(|| missing("target"))?;
    let up_given = camera.up.as_ref().ok_or_else(|| missing("up"))?;
    let vfov_given = camera.vfov.as_ref().ok_or_else(|| missing("vfov"))?;
    let eye = coordinates(eye, "camera.eye")?;
    let target_value = coordinates(target, "camera.target")?;
    let up = vec3(up_given, "camera.up")?;
    let vfov = real(vfov_given, "camera.vfov")?;
    if !(vfov > 0.0 && vfov < 180.0) {
        return fail(
            vfov_given.span(),
            "camera.vfov",
            format!("must be in (0, 180) degrees, got {vfov}"),
        );
    }
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
    Ok((eye, target_value, up, vfov))
}

/// The camera of the glTF file `from` names: its `index`-th, or its first perspective one.
fn from_file(
    camera: &CameraToml,
    from: &S<String>,
    folder: &Path,
) -> Result<(Vec3, Vec3, Vec3, f32), FieldError> {
    let given = [
        ("eye", camera.eye.as_ref().map(|x| x.span())),
        ("target", camera.target.as_ref().map(|x| x.span())),
        ("up", camera.up.as_ref().map(|x| x.span())),
        ("vfov", camera.vfov.as_ref().map(|x| x.span())),
    ];
    for (name, span) in given {
        if let Some(span) = span {
            return fail(
                span,
                format!("camera.{name}"),
                "give either camera.from (a glTF file's camera) or eye, target, up and vfov, \
                 not both",
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
            format!("{file}: the file has no perspective camera"),
        );
    };
    Ok((c.eye, c.target(), c.up, c.vfov))
}
