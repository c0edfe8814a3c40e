//! Point, spot and directional (sun) lights: the scene's own light type, which a scene file's
//! `[[lights]]` fills (and which glTF's `KHR_lights_punctual` maps onto one for one), and its
//! kernel form (`shaders/lights/sampling.wgsl`, `src/cpu/lights/sampling.rs` sample it).
//!
//! Units are radiometric: a point or spot light's `intensity` is a radiant intensity (W/sr), a
//! directional light's an irradiance (W/m², on a surface facing it). `color` multiplies it.

use crate::kernel::types::{self, LIGHT_POINT, LIGHT_SPOT, LIGHT_SUN};
use glam::{DVec3, Vec3};

/// A light that is not a surface: a point, a spot or a sun.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    /// Linear RGB, ≥ 0; multiplies `intensity`.
    pub color: Vec3,
    /// Point and spot: radiant intensity (W/sr); directional: irradiance (W/m²).
    pub intensity: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightKind {
    /// Radiates `intensity` in every direction from `position`; with a `radius` > 0, a sphere
    /// of that radius which radiates the same (a sphere emitter, hit by rays like any other).
    Point { position: Vec3, radius: f32 },
    /// A point light whose intensity falls off away from `direction` (unit, the way the light
    /// travels): full within `inner_angle` of it, none beyond `outer_angle` (degrees), glTF's
    /// smooth falloff between.
    Spot {
        position: Vec3,
        direction: Vec3,
        inner_angle: f32,
        outer_angle: f32,
    },
    /// Parallel light travelling along `direction` (unit): a sun. `angle` > 0 (degrees) makes
    /// it a disk of that angular diameter, a cone of directions at infinity.
    Directional { direction: Vec3, angle: f32 },
}

impl Light {
    /// `color × intensity`.
    pub fn emitted(&self) -> DVec3 {
        self.color.as_dvec3() * self.intensity as f64
    }

    /// A point light with a radius: the sphere's centre, radius and uniform radiance. A sphere
    /// of radius r and radiance L has intensity L·πr² towards every direction (its projected
    /// area), so L = I / (πr²).
    pub fn sphere(&self) -> Option<(Vec3, f32, Vec3)> {
        match self.kind {
            LightKind::Point { position, radius } if radius > 0.0 => {
                let area = std::f64::consts::PI * (radius as f64).powi(2);
                Some((position, radius, (self.emitted() / area).as_vec3()))
            }
            _ => None,
        }
    }

    /// A sun disk's radiance: a disk of half-angle θ and uniform radiance L gives, on a
    /// surface facing it, E = L·π sin²θ. `None` for other lights and suns without a disk.
    pub fn sun_radiance(&self) -> Option<glam::Vec3> {
        match self.kind {
            LightKind::Directional { angle, .. } if angle > 0.0 => {
                let half = 0.5 * (angle as f64).to_radians();
                Some((self.emitted() / (std::f64::consts::PI * half.sin().powi(2))).as_vec3())
            }
            _ => None,
        }
    }

    /// Power over π (the π every emitter's power shares is dropped, as in
    /// `src/kernel/scene/emitter_table.rs`), channels averaged; `scene_radius` sizes a sun's disc of light.
    /// A point light radiates 4πI; a spot 2πI·((1 − cos inner) + (cos inner − cos outer)/2),
    /// as pbrt-v4 counts it; a sun E·πR² through the scene's disc, as the environment map does.
    pub fn power(&self, scene_radius: f64) -> f64 {
        let mean = self.emitted().element_sum() / 3.0;
        match self.kind {
            LightKind::Point { .. } => 4.0 * mean,
            LightKind::Spot {
                inner_angle,
                outer_angle,
                ..
            } => {
                let cos_inner = (inner_angle as f64).to_radians().cos();
                let cos_outer = (outer_angle as f64).to_radians().cos();
                2.0 * mean * ((1.0 - cos_inner) + 0.5 * (cos_inner - cos_outer))
            }
            LightKind::Directional { .. } => mean * scene_radius * scene_radius,
        }
    }

    /// The kernel's form, with the probability that light sampling picks it. (Point lights
    /// with a radius are spheres in the kernel, not lights: see [`Light::sphere`].)
    pub fn kernel_light(&self, light_probability: f32) -> types::Light {
        let emitted = self.emitted();
        let mut out = types::Light {
            light_probability,
            emitted: emitted.as_vec3().into(),
            spot_scale: 0.0,
            spot_offset: 1.0,
            ..Default::default()
        };
        match self.kind {
            LightKind::Point { position, .. } => {
                out.kind = LIGHT_POINT;
                out.position = position.into();
            }
            LightKind::Spot {
                position,
                direction,
                inner_angle,
                outer_angle,
            } => {
                // glTF KHR_lights_punctual's falloff: clamp(cd·scale + offset, 0, 1)², cd the
                // cosine from the axis, scale = 1 / max(0.001, cos inner − cos outer),
                // offset = −cos outer · scale.
                let cos_inner = (inner_angle as f64).to_radians().cos();
                let cos_outer = (outer_angle as f64).to_radians().cos();
                let scale = 1.0 / (cos_inner - cos_outer).max(0.001);
                out.kind = LIGHT_SPOT;
                out.position = position.into();
                out.direction = direction.into();
                out.spot_scale = scale as f32;
                out.spot_offset = (-cos_outer * scale) as f32;
            }
            LightKind::Directional { direction, angle } => {
                out.kind = LIGHT_SUN;
                out.direction = direction.into();
                // 1 − cos θ = 2 sin²(θ/2), without cancellation. A disk too small for a normal
                // f32 (GPUs flush subnormals to zero) is a delta sun on both devices.
                let half = 0.5 * (angle as f64).to_radians();
                let one_minus_cos = (2.0 * (0.5 * half).sin().powi(2)) as f32;
                if one_minus_cos >= f32::MIN_POSITIVE {
                    out.sun_one_minus_cos = one_minus_cos;
                    out.emitted = self.sun_radiance().unwrap_or_default().into();
                }
            }
        }
        out
    }
}
