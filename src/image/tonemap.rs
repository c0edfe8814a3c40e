//! Tone mapping for display (PNG files): linear radiance × 2^exposure → a display-linear value
//! in [0, 1], which `output` then sRGB-encodes. EXR output never goes through this.
//!
//! Curves:
//! - `clamp`: the identity, clamped to [0, 1] (what glint has always written).
//! - `aces`: Krzysztof Narkowicz's fit of the ACES reference rendering and output transforms
//!   ("ACES Filmic Tone Mapping Curve", 2016): x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14),
//!   per channel, as published (without the 0.6 pre-exposure some ports add).
//! - `agx`: Troy Sobotka's AgX (Blender 4's default view transform), in Benjamin Wrensch's
//!   "minimal AgX" approximation (iolite engine blog, 2023): the inset matrix, a log2 encoding
//!   over [−12.47393, 4.026069] EV, the 6th-order polynomial fit of AgX's default contrast
//!   sigmoid, the inverse (outset) matrix, and the 2.2 power display EOTF; no look applied.

use crate::image::output::Image;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tonemap {
    #[default]
    Clamp,
    Aces,
    Agx,
}

impl Tonemap {
    pub const NAMES: &'static str = "clamp, aces or agx";

    pub fn parse(s: &str) -> Result<Tonemap, String> {
        match s {
            "clamp" => Ok(Tonemap::Clamp),
            "aces" => Ok(Tonemap::Aces),
            "agx" => Ok(Tonemap::Agx),
            _ => Err(format!("expected {}, got {s:?}", Tonemap::NAMES)),
        }
    }
}

/// How linear radiance becomes a displayed value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DisplayTransform {
    pub tonemap: Tonemap,
    /// Exposure in stops: radiance is multiplied by 2^exposure first.
    pub exposure: f32,
}

/// Parses an exposure in EV: any finite number.
pub fn parse_exposure(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .parse()
        .map_err(|_| format!("{s:?} is not a number of stops"))?;
    if !v.is_finite() || v.abs() > 64.0 {
        return Err(format!(
            "must be a finite number of stops in [-64, 64], got {s}"
        ));
    }
    Ok(v)
}

fn narkowicz_aces(x: f32) -> f32 {
    (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
}

/// Rows of the AgX inset matrix (linear sRGB → AgX's working space).
const AGX_INSET: [[f32; 3]; 3] = [
    [0.842_479_06, 0.078_433_6, 0.079_223_745],
    [0.042_328_242, 0.878_468_6, 0.079_166_13],
    [0.042_375_655, 0.078_433_6, 0.879_143],
];
/// Rows of its inverse, the outset matrix.
const AGX_OUTSET: [[f32; 3]; 3] = [
    [1.196_879, -0.098_020_88, -0.099_029_74],
    [-0.052_896_85, 1.151_903_1, -0.098_961_18],
    [-0.052_971_635, -0.098_043_45, 1.151_073_7],
];
const AGX_MIN_EV: f32 = -12.47393;
const AGX_MAX_EV: f32 = 4.026069;

fn mat_mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// The polynomial fit of AgX's default contrast sigmoid, on x in [0, 1].
fn agx_contrast(x: f32) -> f32 {
    let x2 = x * x;
    let x4 = x2 * x2;
    15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.00232
}

fn agx(rgb: [f32; 3]) -> [f32; 3] {
    let encoded = mat_mul(&AGX_INSET, rgb).map(|v| {
        // log2 of 0 (or less) is −∞: the clamp takes it to the darkest value.
        let ev = if v > 0.0 { v.log2() } else { AGX_MIN_EV };
        let t = (ev.clamp(AGX_MIN_EV, AGX_MAX_EV) - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV);
        agx_contrast(t)
    });
    mat_mul(&AGX_OUTSET, encoded).map(|v| v.clamp(0.0, 1.0).powf(2.2))
}

impl DisplayTransform {
    /// The display-linear value in [0, 1] of linear radiance `rgb`. NaN shows as black.
    pub fn apply(&self, rgb: [f32; 3]) -> [f32; 3] {
        let scale = self.exposure.exp2();
        // Past 1e9 every curve is flat at white; capping there keeps x² finite.
        let x = rgb.map(|v| {
            if v.is_nan() {
                0.0
            } else {
                (v * scale).clamp(0.0, 1e9)
            }
        });
        let mapped = match self.tonemap {
            Tonemap::Clamp => x,
            Tonemap::Aces => x.map(narkowicz_aces),
            Tonemap::Agx => agx(x),
        };
        mapped.map(|v| v.clamp(0.0, 1.0))
    }

    /// Whether `apply` changes nothing that the PNG encoder's own clamp would not.
    pub fn is_identity(&self) -> bool {
        self.tonemap == Tonemap::Clamp && self.exposure == 0.0
    }

    /// `image` as it is shown: every pixel through [`DisplayTransform::apply`].
    pub fn image(&self, image: &Image) -> Image {
        if self.is_identity() {
            return image.clone();
        }
        Image {
            width: image.width,
            height: image.height,
            pixels: image.pixels.iter().map(|&p| self.apply(p)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agx_outset_inverts_inset() {
        for i in 0..3 {
            let mut unit = [0.0; 3];
            unit[i] = 1.0;
            let back = mat_mul(&AGX_OUTSET, mat_mul(&AGX_INSET, unit));
            for (j, v) in back.into_iter().enumerate() {
                assert!((v - unit[j]).abs() < 1e-5, "{i} {j}: {v}");
            }
        }
    }

    #[test]
    fn curves_are_monotonic_black_at_zero_and_white_far_up() {
        for tonemap in [Tonemap::Clamp, Tonemap::Aces, Tonemap::Agx] {
            let t = DisplayTransform {
                tonemap,
                exposure: 0.0,
            };
            assert!(t.apply([0.0; 3])[0] < 1e-3, "{tonemap:?}");
            assert!(t.apply([1e6; 3])[0] > 0.97, "{tonemap:?}");
            // NaN and negative radiance show as black, +inf as the brightest value: the same
            // as black and 1e9 in those channels (AgX mixes channels, so compare whole pixels).
            assert_eq!(
                t.apply([f32::NAN, f32::INFINITY, -1.0]),
                t.apply([0.0, 1e9, 0.0]),
                "{tonemap:?}"
            );
            let mut last = -1.0;
            for i in 0..200 {
                let v = t.apply([(i as f32 * 0.1 - 10.0).exp2(); 3])[1];
                assert!(v >= last, "{tonemap:?} at step {i}");
                last = v;
            }
        }
    }

    #[test]
    fn exposure_is_in_stops() {
        let t = DisplayTransform {
            tonemap: Tonemap::Clamp,
            exposure: 1.0,
        };
        assert_eq!(t.apply([0.25, 0.5, 2.0]), [0.5, 1.0, 1.0]);
        assert!(parse_exposure("nan").is_err());
        assert!(parse_exposure("inf").is_err());
        assert_eq!(parse_exposure("-1.5"), Ok(-1.5));
    }
}
