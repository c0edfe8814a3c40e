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

/// One `[[lights]]` entry. The checks run in the order the fields' errors are reported: the
/// type, fields that do not apply to it, intensity and colour, the kind's own fields, then the
/// radiance of the light's surface.
fn validate_light(l: &LightToml, i: usize) -> Result<Light, FieldError> {
    let entry = LightEntry {
        toml: l,
        index: i,
        kind: l.kind.get_ref().as_str(),
    };
    entry.check_kind()?;
    entry.check_fields_apply()?;
    let (intensity, color) = entry.intensity_and_color()?;
    let kind = match entry.kind {
        "point" => entry.point()?,
        "spot" => entry.spot()?,
        _ => entry.directional()?,
    };
    let light = Light {
        kind,
        color,
        intensity,
    };
    entry.check_surface_radiance(&light)?;
    Ok(light)
}

/// The `index`th `[[lights]]` entry as written, of the type `kind` names.
struct LightEntry<'a> {
    toml: &'a LightToml,
    index: usize,
    kind: &'a str,
}

impl LightEntry<'_> {
    fn field(&self, f: &str) -> String {
        format!("lights[{}].{f}", self.index)
    }

    fn check_kind(&self) -> Result<(), FieldError> {
        let kind = self.kind;
        if !matches!(kind, "point" | "spot" | "directional") {
            return fail(
                self.toml.kind.span(),
                self.field("type"),
                format!(
                    "unknown light type {kind:?}; known types: \"point\", \"spot\", \"directional\""
                ),
            );
        }
        Ok(())
    }

    /// A field that does not apply is most likely a mistake: say so.
    fn check_fields_apply(&self) -> Result<(), FieldError> {
        let (l, kind) = (self.toml, self.kind);
        let applies = |name: &str| match name {
            "position" | "radius" => matches!(kind, "point" | "spot"),
            "direction" => matches!(kind, "spot" | "directional"),
            "inner_angle" | "outer_angle" => kind == "spot",
            "angle" => kind == "directional",
            _ => true,
        };
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
                    self.field(name),
                    format!("{name} does not apply to a {kind} light"),
                );
            }
        }
        Ok(())
    }

    /// `intensity` (≥ 0) and `color` (default white), their product within the numeric range
    /// radiance has.
    fn intensity_and_color(&self) -> Result<(f32, Vec3), FieldError> {
        let l = self.toml;
        let intensity = real(&l.intensity, &self.field("intensity"))?;
        if intensity < 0.0 {
            return fail(
                l.intensity.span(),
                self.field("intensity"),
                format!("must be ≥ 0, got {intensity}"),
            );
        }
        let color = match &l.color {
            Some(c) => non_negative(c, &self.field("color"))?,
            None => Vec3::ONE,
        };
        let emitted = color.as_dvec3() * intensity as f64;
        if emitted.max_element() > MAX_RADIANCE {
            return fail(
                l.intensity.span(),
                self.field("color × intensity"),
                format!(
                    "{:e} is too bright: at most {MAX_RADIANCE:e} per channel (the numeric range \
                     glint supports)",
                    emitted.max_element()
                ),
            );
        }
        Ok((intensity, color))
    }

    /// A field this type of light needs; its absence fails at the light's `type`.
    fn missing(&self, name: &str) -> FieldError {
        FieldError {
            span: Some(self.toml.kind.span()),
            field: self.field(name),
            message: format!("missing: a {} light needs {name}", self.kind),
        }
    }

    fn position(&self) -> Result<Vec3, FieldError> {
        let p = self
            .toml
            .position
            .as_ref()
            .ok_or_else(|| self.missing("position"))?;
        coordinates(p, &self.field("position"))
    }

    /// The way the light travels, normalized (in f64); it must not be zero.
    fn direction(&self) -> Result<Vec3, FieldError> {
        let d = self
            .toml
            .direction
            .as_ref()
            .ok_or_else(|| self.missing("direction"))?;
        let v = vec3(d, &self.field("direction"))?;
        let length = v.as_dvec3().length();
        if length == 0.0 {
            return fail(
                d.span(),
                self.field("direction"),
                "must not be zero: it is the way the light travels (a sun overhead is [0, -1, 0])",
            );
        }
        Ok((v.as_dvec3() / length).as_vec3())
    }

    /// An angle in [0, `max`] degrees, or `default` when absent.
    fn angle(
        &self,
        x: &Option<S<Real>>,
        name: &str,
        default: f32,
        max: f32,
    ) -> Result<f32, FieldError> {
        let Some(x) = x else { return Ok(default) };
        let v = real(x, &self.field(name))?;
        if !(0.0..=max).contains(&v) {
            return fail(
                x.span(),
                self.field(name),
                format!("must be in [0, {max}] degrees, got {v}"),
            );
        }
        Ok(v)
    }

    /// A point light: its `radius` (≥ 0, 0 a true point) and `position`.
    fn point(&self) -> Result<LightKind, FieldError> {
        let radius = match &self.toml.radius {
            Some(r) => {
                let v = real(r, &self.field("radius"))?;
                if v < 0.0 {
                    return fail(
                        r.span(),
                        self.field("radius"),
                        format!("must be ≥ 0 (0 is a true point), got {v}"),
                    );
                }
                if v > 0.0 {
                    length_in_range(r, &self.field("radius"), v, MIN_LENGTH)?;
                }
                v
            }
            None => 0.0,
        };
        Ok(LightKind::Point {
            position: self.position()?,
            radius,
        })
    }

    /// A spot light: a true point (radius 0), its cone's angles, `position` and `direction`.
    fn spot(&self) -> Result<LightKind, FieldError> {
        let l = self.toml;
        if let Some(r) = &l.radius {
            if real(r, &self.field("radius"))? != 0.0 {
                return fail(
                    r.span(),
                    self.field("radius"),
                    "a spot light is a true point (radius 0) for now; a point light may \
                     have a radius",
                );
            }
        }
        let inner_angle = self.angle(&l.inner_angle, "inner_angle", 0.0, 90.0)?;
        let outer_angle = self.angle(&l.outer_angle, "outer_angle", DEFAULT_OUTER_ANGLE, 90.0)?;
        if outer_angle < inner_angle {
            let span = l.outer_angle.as_ref().map_or(l.kind.span(), |x| x.span());
            return fail(
                span,
                self.field("outer_angle"),
                format!("must be at least inner_angle ({inner_angle}°), got {outer_angle}°"),
            );
        }
        Ok(LightKind::Spot {
            position: self.position()?,
            direction: self.direction()?,
            inner_angle,
            outer_angle,
        })
    }

    /// A directional light: its `direction` and the sun disk's `angle` (0, a true direction,
    /// unless given).
    fn directional(&self) -> Result<LightKind, FieldError> {
        Ok(LightKind::Directional {
            direction: self.direction()?,
            angle: self.angle(&self.toml.angle, "angle", 0.0, 90.0)?,
        })
    }

    /// A sphere light's or a sun disk's radiance grows as the radius or the angle shrinks:
    /// it must stay in the numeric range emission has.
    fn check_surface_radiance(&self, light: &Light) -> Result<(), FieldError> {
        let l = self.toml;
        let surface = light
            .sphere()
            .map(|(_, _, radiance)| ("radius", radiance, l.radius.as_ref()))
            .or_else(|| light.sun_radiance().map(|r| ("angle", r, l.angle.as_ref())));
        if let Some((name, radiance, Some(x))) = surface {
            let peak = radiance.max_element() as f64;
            if peak > MAX_RADIANCE || peak.is_nan() {
                return fail(
                    x.span(),
                    self.field(name),
                    format!(
                        "the light's surface would have a radiance of {peak:e}: at most \
                         {MAX_RADIANCE:e} (the numeric range glint supports); make it larger or \
                         dimmer"
                    ),
                );
            }
        }
        Ok(())
    }
}
