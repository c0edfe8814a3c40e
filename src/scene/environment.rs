//! The environment map on the host: reading it, and the tables its importance sampling draws
//! from (WGSL side: `shaders/lights/environment.wgsl`, CPU mirror: `src/cpu/lights/environment.rs`).
//!
//! # Conventions
//! The map is equirectangular (latitude-longitude), top row first. A direction d in the map's
//! own frame (y up) lies at
//!   u = atan2(d.x, −d.z) / 2π  (wrapped into [0, 1): u = 0 looks along −z, u = ¼ along +x),
//!   v = acos(d.y) / π          (v = 0 is straight up, the image's top row),
//! as in Mitsuba 3, so the same file lights both renderers alike. `rotate = α` turns the map
//! by α degrees about +y, right-handed: what lay at −z is seen at −x for α = 90.
//!
//! Lookup is nearest-texel: the radiance is piecewise constant over texels, so the sampling
//! distribution below follows it exactly.
//!
//! # Sampling and its pdf
//! Texel (i, j) of a W×H map covers φ ∈ 2π[i, i+1)/W and θ ∈ π[j, j+1)/H, a solid angle
//!   Ω_j = (2π/W)·(cos θ_j − cos θ_{j+1}) = (2π/W)·2·sin θ_c·sin(π/2H),
//! with θ_c its centre's polar angle. A texel is chosen with probability
//!   p_ij = lum(L_ij)·sin θ_c / Σ lum·sin θ_c = lum(L_ij)·Ω_j / Σ lum·Ω
//! (the weights lum × sin θ are exactly proportional to lum × Ω, as Ω_j ∝ sin θ_c), by Vose's
//! alias table, then a direction uniformly in solid angle within it (φ and cos θ uniform). So
//! the solid-angle pdf is exactly p_ij / Ω_j over the texel, proportional to its luminance.
//! In image space that is the familiar p(u, v) = p_ij·W·H over the texel, divided by
//! dω/(du dv) = 2π²·sin θ, integrated over the texel instead of taken at its centre.

use super::image::{load_linear_image, Encoding, LinearImage};
use super::limits::MAX_RADIANCE;
use crate::kernel::types::{EnvironmentAlias, EnvironmentTexel};
use glam::Vec3;
use std::f64::consts::PI;
use std::path::Path;

/// A validated environment map: radiance already multiplied by `strength`.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub image: LinearImage,
    /// Degrees about +y.
    pub rotate_degrees: f32,
}

/// Luminance (Rec. 709 / sRGB primaries), which the sampling distribution follows.
pub fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

/// Reads the map at `path` and scales it by `strength`. The error is a sentence for the
/// caller to place after the file and field: unreadable or 0×0 images, and texels that are
/// not finite radiances (with the texel's position), fail.
pub fn load(path: &Path, strength: f32, rotate_degrees: f32) -> Result<Environment, String> {
    from_image(
        load_linear_image(path, Encoding::Srgb)?,
        strength,
        rotate_degrees,
    )
}

/// An environment from a map already in memory (a file's, or the generated studio map of
/// `studio.rs`), checked and scaled as [`load`] does.
pub fn from_image(
    mut image: LinearImage,
    strength: f32,
    rotate_degrees: f32,
) -> Result<Environment, String> {
    for (k, texel) in image.texels.iter_mut().enumerate() {
        let (x, y) = (k as u32 % image.width, k as u32 / image.width);
        if texel.iter().any(|c| !c.is_finite() || *c < 0.0) {
            return Err(format!(
                "texel ({x}, {y}) is {texel:?}; an environment map holds finite radiances ≥ 0"
            ));
        }
        for c in texel.iter_mut() {
            let scaled = *c as f64 * strength as f64;
            if scaled > MAX_RADIANCE {
                return Err(format!(
                    "texel ({x}, {y}) times the strength is a radiance of {scaled:e}: at most \
                     {MAX_RADIANCE:e} per channel (the numeric range glint supports)"
                ));
            }
            *c = scaled as f32;
        }
    }
    Ok(Environment {
        image,
        rotate_degrees,
    })
}

/// Solid angle of a texel in row `row` of a `width`×`height` map (see the module's notes).
pub fn texel_solid_angle(row: u32, width: u32, height: u32) -> f64 {
    let theta_centre = PI * (row as f64 + 0.5) / height as f64;
    2.0 * PI / width as f64 * 2.0 * theta_centre.sin() * (PI / (2.0 * height as f64)).sin()
}

/// What the kernel reads of the map.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentTables {
    /// Radiance and sampling pdf per texel, top row first.
    pub texels: Vec<EnvironmentTexel>,
    /// Vose's alias table over the texels.
    pub alias: Vec<EnvironmentAlias>,
    /// ∫ L dω over the sphere, mean of the three channels: the map's share of emitter power.
    pub radiance_integral: f64,
}

impl Environment {
    /// The direction of the map's (u, v) = (0.25, 0.5) in the scene: +x turned by `rotate`.
    pub fn rotation(&self) -> (f32, f32) {
        let a = (self.rotate_degrees as f64).to_radians();
        (a.cos() as f32, a.sin() as f32)
    }

    pub fn tables(&self) -> EnvironmentTables {
        let (w, h) = (self.image.width, self.image.height);
        let mut weights = Vec::with_capacity(self.image.texels.len());
        let mut radiance_integral = 0.0;
        for y in 0..h {
            let omega = texel_solid_angle(y, w, h);
            for x in 0..w {
                let texel = self.image.texel(x, y);
                weights.push(luminance(texel) * omega);
                radiance_integral += (texel[0] + texel[1] + texel[2]) as f64 / 3.0 * omega;
            }
        }
        let total: f64 = weights.iter().sum();
        let texels = self
            .image
            .texels
            .iter()
            .zip(&weights)
            .enumerate()
            .map(|(k, (&radiance, &weight))| {
                let omega = texel_solid_angle(k as u32 / w, w, h);
                EnvironmentTexel {
                    radiance,
                    pdf: if total > 0.0 {
                        (weight / total / omega) as f32
                    } else {
                        0.0
                    },
                }
            })
            .collect();
        EnvironmentTables {
            texels,
            alias: alias_table(&weights),
            radiance_integral,
        }
    }
}

/// Vose's alias method ("A linear algorithm for generating random numbers with a given
/// distribution", 1991), in f64: bin k is kept with probability `threshold`, else its alias
/// is taken. All-zero weights give a table nothing is ever drawn from (it is not used).
pub fn alias_table(weights: &[f64]) -> Vec<EnvironmentAlias> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut table = vec![
        EnvironmentAlias {
            threshold: 1.0,
            alias_texel: 0,
        };
        n
    ];
    if total <= 0.0 {
        return table;
    }
    for (k, entry) in table.iter_mut().enumerate() {
        entry.alias_texel = k as u32;
    }
    let mut scaled: Vec<f64> = weights.iter().map(|w| w / total * n as f64).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&k| scaled[k] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        table[s] = EnvironmentAlias {
            threshold: scaled[s] as f32,
            alias_texel: l as u32,
        };
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left holds probability 1 up to rounding.
    for k in small.into_iter().chain(large) {
        table[k] = EnvironmentAlias {
            threshold: 1.0,
            alias_texel: k as u32,
        };
    }
    table
}

/// Radius of a sphere about the scene's bounds, for the map's emitter power: light from the
/// map reaches the scene through a disc of about this radius (as in pbrt's infinite lights).
pub fn scene_radius(points: impl Iterator<Item = Vec3>) -> f64 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if lo.x > hi.x {
        return 1.0;
    }
    (0.5 * (hi.as_dvec3() - lo.as_dvec3()).length()).max(1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alias_table_reproduces_the_weights() {
        let weights = [0.0, 1.0, 5.0, 0.5, 2.5, 0.0, 1.0];
        let table = alias_table(&weights);
        let n = weights.len() as f64;
        let total: f64 = weights.iter().sum();
        let mut p = vec![0.0; weights.len()];
        for (k, e) in table.iter().enumerate() {
            p[k] += e.threshold as f64 / n;
            p[e.alias_texel as usize] += (1.0 - e.threshold as f64) / n;
        }
        for (k, w) in weights.iter().enumerate() {
            assert!(
                (p[k] - w / total).abs() < 1e-6,
                "bin {k}: {} vs {}",
                p[k],
                w / total
            );
        }
    }

    #[test]
    fn texel_solid_angles_cover_the_sphere() {
        let (w, h) = (7, 5);
        let sum: f64 = (0..h).map(|y| w as f64 * texel_solid_angle(y, w, h)).sum();
        assert!((sum - 4.0 * PI).abs() < 1e-12, "{sum}");
    }
}
