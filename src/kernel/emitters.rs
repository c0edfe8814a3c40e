//! The mean radiance a triangle with an emission texture (glTF's emissiveTexture) emits, for
//! light sampling's choice of emitter by power (`kernel::scene::emitter_table`).
//!
//! The mean is over the texels the triangle's lookups can read: every lookup at a point of the
//! triangle blends texels inside the box its three texture coordinates span (mapped through the
//! texture's transform, widened by one texel for bilinear filtering, wrapped or clamped as the
//! lookup wraps), so a triangle whose box is black emits nothing anywhere and is no emitter,
//! and one that emits somewhere gets a power above 0. The box's mean is an estimate, not the
//! exact mean over the triangle: light sampling stays unbiased for any power above 0, since
//! the same probability enters both of multiple importance sampling's pdfs. A summed-area table
//! per texture and emission colour gives each box's sum in O(1).

use crate::kernel::types::{
    Texture, TEXTURE_CHECKER, TEXTURE_NEAREST, TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_REPEAT,
};
use crate::scene::texture::TextureSet;
use glam::{Vec2, Vec3};
use std::collections::HashMap;

/// Summed-area tables of emitted radiance (the mean of its channels) per image and emission
/// colour, built the first time a triangle asks.
pub(super) struct EmissionMeans<'a> {
    textures: &'a TextureSet,
    tables: HashMap<(u32, [u32; 3]), SummedArea>,
}

/// sums[(y + 1)·(width + 1) + x + 1]: the sum of texels [0, x] × [0, y].
struct SummedArea {
    width: u32,
    sums: Vec<f64>,
}

impl SummedArea {
    fn new(texture: &Texture, texels: &[[f32; 4]], emission: Vec3) -> SummedArea {
        let (w, h) = (texture.width as usize, texture.height as usize);
        let weight = emission.as_dvec3() / 3.0;
        let mut sums = vec![0.0f64; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut row = 0.0;
            for x in 0..w {
                let [r, g, b, _] = texels[texture.first_texel as usize + y * w + x];
                row += weight.x * r as f64 + weight.y * g as f64 + weight.z * b as f64;
                sums[(y + 1) * (w + 1) + x + 1] = sums[y * (w + 1) + x + 1] + row;
            }
        }
        SummedArea {
            width: texture.width,
            sums,
        }
    }

    /// The sum over texels x0..=x1, y0..=y1.
    fn sum(&self, (x0, x1): (u32, u32), (y0, y1): (u32, u32)) -> f64 {
        let at = |x: u32, y: u32| self.sums[(y * (self.width + 1) + x) as usize];
        at(x1 + 1, y1 + 1) - at(x0, y1 + 1) - at(x1 + 1, y0) + at(x0, y0)
    }
}

/// The texel ranges (one or two, inclusive) that lookups at coordinates in [lo, hi] along an
/// axis of `size` texels read, with wrap `mode`, filtered or `nearest`.
fn texel_ranges(lo: f32, hi: f32, size: u32, mode: u32, nearest: bool) -> Vec<(u32, u32)> {
    let whole = vec![(0, size - 1)];
    // Bilinear lookups at x read texels floor(x·size − 0.5) and the one after; nearest ones
    // floor(x·size).
    let (first, last) = if nearest {
        (
            (lo as f64 * size as f64).floor(),
            (hi as f64 * size as f64).floor(),
        )
    } else {
        (
            (lo as f64 * size as f64 - 0.5).floor(),
            (hi as f64 * size as f64 - 0.5).floor() + 1.0,
        )
    };
    if !(first.is_finite() && last.is_finite()) || last - first + 1.0 >= size as f64 {
        return whole;
    }
    if mode == TEXTURE_WRAP_CLAMP {
        let clamp = |i: f64| i.clamp(0.0, (size - 1) as f64) as u32;
        return vec![(clamp(first), clamp(last))];
    }
    if mode != TEXTURE_WRAP_REPEAT {
        // Mirrored repeat: the whole axis (an upper bound's worth of work saved is not worth
        // the case analysis).
        return whole;
    }
    let start = first.rem_euclid(size as f64) as u32;
    let end = start + (last - first) as u32;
    if end < size {
        vec![(start, end)]
    } else {
        vec![(start, size - 1), (0, end - size)]
    }
}

impl<'a> EmissionMeans<'a> {
    pub(super) fn new(textures: &'a TextureSet) -> EmissionMeans<'a> {
        EmissionMeans {
            textures,
            tables: HashMap::new(),
        }
    }

    /// The mean emitted radiance (mean of the channels) of a triangle of material emission
    /// `emission` × texture `texture`, with texture coordinates `uvs` at its corners.
    pub(super) fn triangle_mean(&mut self, emission: Vec3, texture: u32, uvs: [Vec2; 3]) -> f64 {
        let t = self.textures.descriptors[texture as usize];
        if t.kind == TEXTURE_CHECKER {
            let mean = (Vec3::from(t.color0) + Vec3::from(t.color1)) * 0.5;
            return (emission * mean).element_sum() as f64 / 3.0;
        }
        let mapped = uvs.map(|uv| {
            let h = Vec3::new(uv.x, uv.y, 1.0);
            Vec2::new(
                Vec3::from(t.transform_u).dot(h),
                Vec3::from(t.transform_v).dot(h),
            )
        });
        let lo = mapped[0].min(mapped[1]).min(mapped[2]);
        let hi = mapped[0].max(mapped[1]).max(mapped[2]);
        let nearest = t.sampling & TEXTURE_NEAREST != 0;
        let xs = texel_ranges(lo.x, hi.x, t.width, t.sampling & 0xff, nearest);
        let ys = texel_ranges(lo.y, hi.y, t.height, (t.sampling >> 8) & 0xff, nearest);
        let texels = &self.textures.texels;
        let table = self
            .tables
            .entry((t.first_texel, emission.to_array().map(f32::to_bits)))
            .or_insert_with(|| SummedArea::new(&t, texels, emission));
        let (mut sum, mut count) = (0.0, 0u64);
        for &x in &xs {
            for &y in &ys {
                sum += table.sum(x, y);
                count += (x.1 - x.0 + 1) as u64 * (y.1 - y.0 + 1) as u64;
            }
        }
        // Rounding in the table's differences can leave a black box a tiny negative sum.
        (sum / count as f64).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::texel_ranges;
    use crate::kernel::types::{TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR, TEXTURE_WRAP_REPEAT};

    #[test]
    fn ranges_cover_the_texels_lookups_read() {
        // 8 texels: [0.3, 0.4] reads x·8 − 0.5 in [1.9, 2.7]: texels 1 to 3.
        assert_eq!(
            texel_ranges(0.3, 0.4, 8, TEXTURE_WRAP_REPEAT, false),
            vec![(1, 3)]
        );
        // Across the seam: [0.95, 1.05] reads [7.1, 7.9]: 7 and 8 ≡ 0.
        assert_eq!(
            texel_ranges(0.95, 1.05, 8, TEXTURE_WRAP_REPEAT, false),
            vec![(7, 7), (0, 0)]
        );
        assert_eq!(
            texel_ranges(-0.5, -0.45, 8, TEXTURE_WRAP_REPEAT, false),
            vec![(3, 4)]
        );
        assert_eq!(
            texel_ranges(1.5, 2.0, 8, TEXTURE_WRAP_CLAMP, false),
            vec![(7, 7)]
        );
        assert_eq!(
            texel_ranges(0.0, 2.0, 8, TEXTURE_WRAP_REPEAT, false),
            vec![(0, 7)]
        );
        assert_eq!(
            texel_ranges(0.3, 0.4, 8, TEXTURE_WRAP_MIRROR, false),
            vec![(0, 7)]
        );
        // Nearest: [0.5, 1] of 4 texels, clamped, reads texels 2 and 3 only (u = 1 clamps to
        // the last); repeated, u = 1 wraps to texel 0.
        assert_eq!(
            texel_ranges(0.5, 1.0, 4, TEXTURE_WRAP_CLAMP, true),
            vec![(2, 3)]
        );
        assert_eq!(
            texel_ranges(0.5, 1.0, 4, TEXTURE_WRAP_REPEAT, true),
            vec![(2, 3), (0, 0)]
        );
    }
}
