//! `[[lights]]`: point, spot and directional lights (`src/scene/light.rs`).

use super::super::file::{LightToml, Real, S};
use super::super::light::{Light, LightKind};
use super::super::limits::{MAX_RADIANCE, MIN_LENGTH};
use super::fields::{coordinates, fail, length_in_range, non_negative, real, vec3, FieldError};
use glam::Vec3;

/// glTF's default spot cone: the outer angle is π/4, the inner 0.
const DEFAULT_OUTER_ANGLE: f32 = 45.0;

pub(super) fn validate_lights(toml: &[S<LightToml>]) -> Result<Vec<Light>, FieldError> {
    toml.iter()
        .enumerate()
        .map(|(i, l)| validate_light(l.get_ref(), i))
        .collect()
}

fn validate_light(l: &LightToml, i: usize) -> Result<Light, FieldError> {
    let field = |f: &str| format!("lights[{i}].{f}");
    let kind = l.kind.get_ref().as_str();
    let applies = |name: &str| match name {
        "position" | "radius" => matches!(kind, "point" | "spot"),
        "direction" => matches!(kind, "spot" | "directional"),
        "inner_angle" | "outer_angle" => kind == "spot",
        "angle" => kind == "directional",
        _ => true,
    };
    if !matches!(kind, "point" | "spot" | "directional") {
        return fail(
            l.kind.span(),
            field("type"),
            format!(
                "unknown light type {kind:?}; known types: \"point\", \"spot\", \"directional\""
            ),
        );
    }
    // A field that does not apply is most likely a mistake: say so.
    let given = [
        ("position", l.position.as_ref().map(|x| x.span())),
        ("direction", l.direction.as_ref().map(|x| x.span())),
        ("inner_angle", l.inner_angle.as_ref().map(|x| x.span())),
        ("outer_angle", l.outer_angle.as_ref().map(|x| x.span())),
        ("angle", l.angle.as_ref().map(|x| x.span())),
        ("radius", l.radius.as_ref().map(|x| x.span())),
    ];
    for (name, span) in given {
        if let (Some(span), false) = (span, applies(name)) {
            return fail(
                span,
                field(name),
                format!("{name} does not apply to a {kind} light"),
            );
        }
    }
    let intensity = real(&l.intensity, &field("intensity"))?;
    if intensity < 0.0 {
        return fail(
            l.intensity.span(),
            field("intensity"),
            format!("must be ≥ 0, got {intensity}"),
        );
    }
    let color = match &l.color {
        Some(c) => non_negative(c, &field("color"))?,
        None => Vec3::ONE,
    };
    let emitted = color.as_dvec3() * intensity as f64;
    if emitted.max_element() > MAX_RADIANCE {
        return fail(
            l.intensity.span(),
            field("color × intensity"),
            format!(
                "{:e} is too bright: at most {MAX_RADIANCE:e} per channel (the numeric range \
                 glint supports)",
                emitted.max_element()
            ),
        );
    }
    let missing = |name: &str| FieldError {
        span: Some(l.kind.span()),
        field: field(name),
        message: format!("missing: a {kind} light needs {name}"),
    };
    let position = || -> Result<Vec3, FieldError> {
        let p = l.position.as_ref().ok_or_else(|| missing("position"))?;
        coordinates(p, &field("position"))
    };
    let direction = || -> Result<Vec3, FieldError> {
        let d = l.direction.as_ref().ok_or_else(|| missing("direction"))?;
        let v = vec3(d, &field("direction"))?;
        let length = v.as_dvec3().length();
        if length == 0.0 {
            return fail(
                d.span(),
                field("direction"),
                "must not be zero: it is the way the light travels (a sun overhead is [0, -1, 0])",
            );
        }
        Ok((v.as_dvec3() / length).as_vec3())
    };
    let angle = |x: &Option<S<Real>>, name: &str, default: f32, max: f32| {
        let Some(x) = x else { return Ok(default) };
        let v = real(x, &field(name))?;
        if !(0.0..=max).contains(&v) {
            return fail(
                x.span(),
                field(name),
                format!("must be in [0, {max}] degrees, got {v}"),
            );
        }
        Ok(v)
    };
    let kind = match kind {
        "point" => {
            let radius = match &l.radius {
                Some(r) => {
                    let v = real(r, &field("radius"))?;
                    if v < 0.0 {
                        return fail(
                            r.span(),
                            field("radius"),
                            format!("must be ≥ 0 (0 is a true point), got {v}"),
                        );
                    }
                    if v > 0.0 {
                        length_in_range(r, &field("radius"), v, MIN_LENGTH)?;
                    }
                    v
                }
                None => 0.0,
            };
            LightKind::Point {
                position: position()?,
                radius,
            }
        }
        "spot" => {
            if let Some(r) = &l.radius {
                if real(r, &field("radius"))? != 0.0 {
                    return fail(
                        r.span(),
                        field("radius"),
                        "a spot light is a true point (radius 0) for now; a point light may \
                         have a radius",
                    );
                }
            }
            let inner_angle = angle(&l.inner_angle, "inner_angle", 0.0, 90.0)?;
            let outer_angle = angle(&l.outer_angle, "outer_angle", DEFAULT_OUTER_ANGLE, 90.0)?;
            if outer_angle < inner_angle {
                let span = l.outer_angle.as_ref().map_or(l.kind.span(), |x| x.span());
                return fail(
                    span,
                    field("outer_angle"),
                    format!("must be at least inner_angle ({inner_angle}°), got {outer_angle}°"),
                );
            }
            LightKind::Spot {
                position: position()?,
                direction: direction()?,
                inner_angle,
                outer_angle,
            }
        }
        _ => LightKind::Directional {
            direction: direction()?,
            angle: angle(&l.angle, "angle", 0.0, 90.0)?,
        },
    };
    let light = Light {
        kind,
        color,
        intensity,
    };
    // A sphere light's or a sun disk's radiance grows as the radius or the angle shrinks:
    // it must stay in the numeric range emission has.
    let surface = light
        .sphere()
        .map(|(_, _, radiance)| ("radius", radiance, l.radius.as_ref()))
        .or_else(|| light.sun_radiance().map(|r| ("angle", r, l.angle.as_ref())));
    if let Some((name, radiance, Some(x))) = surface {
        let peak = radiance.max_element() as f64;
        if peak > MAX_RADIANCE || peak.is_nan() {
            return fail(
                x.span(),
                field(name),
                format!(
                    "the light's surface would have a radiance of {peak:e}: at most \
                     {MAX_RADIANCE:e} (the numeric range glint supports); make it larger or \
                     dimmer"
                ),
            );
        }
    }
    Ok(light)
}
