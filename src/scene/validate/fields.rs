//! The checks every part of a scene file shares: numbers, 3-vectors, lengths, radiances, and
//! the error that ties a failure to its field and place.

use super::super::check_range;
use super::super::file::{Real, Triple, S};
use super::super::limits::{MAX_COORDINATE, MAX_RADIANCE};
use glam::{DVec3, Vec3};
use std::ops::Range;

/// A validation failure before it is given the file name and a line.
pub(crate) struct FieldError {
    pub(crate) span: Option<Range<usize>>,
    pub(crate) field: String,
    pub(crate) message: String,
}

pub(super) fn fail<T>(
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

pub(super) fn real(x: &S<Real>, field: &str) -> Result<f32, FieldError> {
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
pub(super) fn vec3(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
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
pub(super) fn coordinates(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
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
pub(super) fn length_in_range(
    x: &S<Real>,
    field: &str,
    value: f32,
    min: f32,
) -> Result<f32, FieldError> {
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

pub(super) fn non_negative(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
    let v = vec3(x, field)?;
    if v.min_element() < 0.0 {
        return fail(x.span(), field, format!("components must be ≥ 0, got {v}"));
    }
    Ok(v)
}

/// A radiance (emitted or background): ≥ 0 and at most [`MAX_RADIANCE`] per channel.
pub(super) fn radiance_in_range(
    span: Range<usize>,
    field: &str,
    value: DVec3,
) -> Result<(), FieldError> {
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
pub(super) fn sine_between(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3().normalize(), b.as_dvec3().normalize());
    a.cross(b).length()
}

pub(super) fn int_in(x: &S<i64>, field: &str, min: i64, max: i64) -> Result<u32, FieldError> {
    check_range(*x.get_ref(), min, max)
        .map(|_| *x.get_ref() as u32)
        .or_else(|m| fail(x.span(), field, m))
}
