//! The neutral studio environment a model file is lit by when no `--environment` is given
//! (`[environment] preset = "studio"` in a scene file), generated in memory: no file on disk.
//!
//! Grey only, so the model's own colours show as they are: a large soft box above and in front
//! of the model (towards +z, where the framing camera stands), two strip lights at its sides,
//! a soft light overhead, a bright ceiling fading to a darker horizon, and a dim floor.
//! Equirectangular in glint's convention (`environment.rs`): u = 0 looks along −z, +y is up.

use super::environment::{self, Environment};
use super::image::LinearImage;
use glam::Vec3;
use std::f32::consts::PI;

/// The map's size: the lights are tens of degrees wide, so 1.4° texels resolve them.
pub const WIDTH: u32 = 256;
pub const HEIGHT: u32 = 128;

/// The preset's name in scene files.
pub const PRESET: &str = "studio";

/// The unit direction with `elevation` above the horizon and `azimuth` from −z towards +x
/// (degrees).
fn unit(elevation: f32, azimuth: f32) -> Vec3 {
    let (e, a) = (elevation.to_radians(), azimuth.to_radians());
    Vec3::new(e.cos() * a.sin(), e.sin(), -e.cos() * a.cos())
}

/// 1 inside `radius` degrees of `centre`, 0 beyond `radius + soft`, smooth between.
fn disk(d: Vec3, centre: Vec3, radius: f32, soft: f32) -> f32 {
    let angle = d.dot(centre).clamp(-1.0, 1.0).acos().to_degrees();
    let t = ((radius + soft - angle) / soft).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The radiance seen along unit direction `d`.
fn radiance(d: Vec3) -> f32 {
    let key = 2.5 * disk(d, unit(40.0, 180.0), 25.0, 6.0);
    let top = 1.0 * disk(d, Vec3::Y, 20.0, 10.0);
    // Vertical strips: near a side's azimuth, within 35° of the horizon.
    let horizontal = Vec3::new(d.x, 0.0, d.z).normalize_or_zero();
    let strips: f32 = [100.0f32, -100.0]
        .iter()
        .map(|&azimuth| {
            let towards = disk(horizontal, unit(0.0, azimuth), 7.0, 3.0);
            let height = ((35.0 - d.y.asin().to_degrees().abs()) / 5.0).clamp(0.0, 1.0);
            1.5 * towards * height
        })
        .sum();
    let ambient = if d.y >= 0.0 { 0.25 + 0.3 * d.y } else { 0.12 };
    ambient + key + top + strips
}

/// The studio map at strength 1.
pub fn image() -> LinearImage {
    let mut texels = Vec::with_capacity((WIDTH * HEIGHT) as usize);
    for y in 0..HEIGHT {
        let theta = PI * (y as f32 + 0.5) / HEIGHT as f32;
        for x in 0..WIDTH {
            let phi = 2.0 * PI * (x as f32 + 0.5) / WIDTH as f32;
            let d = Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            );
            texels.push([radiance(d); 3]);
        }
    }
    LinearImage {
        width: WIDTH,
        height: HEIGHT,
        texels,
        alpha: Vec::new(),
        clamped: None,
    }
}

/// The studio environment, scaled and turned as a map file would be.
pub fn environment(strength: f32, rotate_degrees: f32) -> Result<Environment, String> {
    environment::from_image(image(), strength, rotate_degrees)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_key_light_faces_the_front_and_the_floor_is_dim() {
        let front = radiance(unit(40.0, 180.0));
        let back = radiance(unit(40.0, 0.0));
        let floor = radiance(-Vec3::Y);
        assert!(
            front > 2.5 && back < 1.0 && floor < 0.2,
            "{front} {back} {floor}"
        );
        let map = image();
        assert!(map
            .texels
            .iter()
            .all(|t| t[0] > 0.0 && t[0] == t[1] && t[1] == t[2]));
    }
}
