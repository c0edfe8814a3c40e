//! The range checks a mesh file's material values pass (glTF's and OBJ's alike), with the same
//! limits and messages as a scene file's materials.

use crate::scene::limits::{MAX_IOR, MAX_NORMAL_SCALE, MAX_RADIANCE, MIN_IOR};
use glam::Vec3;

/// A reflectance (a colour) in [0, 1] per channel.
pub(super) fn check_reflectance(name: &str, what: &str, c: Vec3) -> Result<Vec3, String> {
    if !c.is_finite() || c.min_element() < 0.0 || c.max_element() > 1.0 {
        return Err(format!(
            "material {name:?}: {what} must be in [0, 1], got {c}"
        ));
    }
    Ok(c)
}

/// An emitted radiance: ≥ 0 and within glint's numeric range, as in scene files.
pub(super) fn check_emission(name: &str, what: &str, e: Vec3) -> Result<Vec3, String> {
    if !e.is_finite() || e.min_element() < 0.0 {
        return Err(format!("material {name:?}: {what} must be ≥ 0, got {e}"));
    }
    if f64::from(e.max_element()) > MAX_RADIANCE {
        return Err(format!(
            "material {name:?}: {what} of {:e} is too bright: at most {MAX_RADIANCE:e} per \
             channel (the numeric range glint supports)",
            e.max_element()
        ));
    }
    Ok(e)
}

/// A dielectric's index of refraction within glint's numeric range, as in scene files.
pub(super) fn check_ior(name: &str, what: &str, ior: f32) -> Result<f32, String> {
    if !(MIN_IOR..=MAX_IOR).contains(&ior) {
        return Err(format!(
            "material {name:?}: {what} must be in [{MIN_IOR}, {MAX_IOR}] (the numeric range \
             glint supports), got {ior}"
        ));
    }
    Ok(ior)
}

/// A normal map's scale within glint's numeric range, as in scene files.
pub(super) fn check_normal_scale(material: &str, what: &str, scale: f32) -> Result<f32, String> {
    if !scale.is_finite() || f64::from(scale.abs()) > MAX_NORMAL_SCALE {
        return Err(format!(
            "material {material:?}: {what} must be a number in [-{MAX_NORMAL_SCALE:e}, \
             {MAX_NORMAL_SCALE:e}] (the numeric range glint supports), got {scale}"
        ));
    }
    Ok(scale)
}
