//! `[environment]`: the map, its strength and rotation.

use super::super::environment::{self, Environment};
use super::super::file::{EnvironmentToml, S};
use super::super::limits::MAX_RADIANCE;
use super::super::studio;
use super::fields::{fail, real, FieldError};
use std::path::Path;

/// `[environment]`: the map read relative to `folder`, its strength and rotation in range.
pub(super) fn validate_environment(
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
    match (&e.file, &e.preset) {
        (Some(_), Some(preset)) => fail(
            preset.span(),
            "environment.preset",
            "give either file (a map) or preset (a map glint generates), not both",
        ),
        (None, None) => fail(
            e_span,
            "environment.file",
            format!(
                "missing: [environment] needs file (an image) or preset = \"{}\"",
                studio::PRESET
            ),
        ),
        (None, Some(preset)) => {
            if preset.get_ref() != studio::PRESET {
                return fail(
                    preset.span(),
                    "environment.preset",
                    format!(
                        "unknown preset {:?}; known: \"{}\"",
                        preset.get_ref(),
                        studio::PRESET
                    ),
                );
            }
            studio::environment(strength, rotate)
                .or_else(|message| fail(preset.span(), "environment.preset", message))
        }
        (Some(file_span), None) => {
            let file = file_span.get_ref();
            if file.is_empty() {
                return fail(e_span, "environment.file", "must name an image file");
            }
            environment::load(&folder.join(file), strength, rotate).or_else(|message| {
                fail(
                    file_span.span(),
                    "environment.file",
                    format!("{file}: {message}"),
                )
            })
        }
    }
}
