//! Textures (WGSL side: `shaders/textures/texture.wgsl`): texture coordinates at a hit, image lookups
//! with bilinear or nearest filtering and repeat, clamped or mirrored wrapping, procedural
//! checkers, and the material at a hit.
//! The filtering is written out by hand on both sides, in the same f32 operations, because a
//! hardware sampler's filtering precision is implementation-defined.

use crate::kernel::types::{
    Material, Texture, TriangleUvs, NO_TEXTURE, TEXTURE_CHECKER, TEXTURE_NEAREST,
    TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR,
};
use glam::{UVec2, Vec2, Vec3, Vec4};

/// The same f32 as the WGSL literal.
const PI_INV: f32 = std::f32::consts::FRAC_1_PI;

/// The scene's textures as the kernel reads them: descriptors and all images' texels.
#[derive(Clone, Copy, Debug, Default)]
pub struct Textures<'a> {
    pub descriptors: &'a [Texture],
    pub texels: &'a [[f32; 4]],
}

/// atan2(y, x) in (−π, π] from a polynomial (Abramowitz and Stegun 4.4.49, |error| ≤ 2·10⁻⁸
/// rad, below an f32 ulp of π): Vulkan lets `atan` and `acos` be off by 4096 ulps, which would
/// make the GPU's texture coordinates, and colours, differ from the CPU's.
#[allow(clippy::excessive_precision)]
pub fn polynomial_atan2(y: f32, x: f32) -> f32 {
    let ax = x.abs();
    let ay = y.abs();
    let big = ax.max(ay);
    let t = if big == 0.0 { 0.0 } else { ax.min(ay) / big };
    let t2 = t * t;
    let mut r = (((((((-0.0040540580 * t2 + 0.0218612288) * t2 - 0.0559098861) * t2
        + 0.0964200441)
        * t2
        - 0.1390853351)
        * t2
        + 0.1994653599)
        * t2
        - 0.3332985605)
        * t2
        + 0.9999993329)
        * t;
    if ay > ax {
        r = std::f32::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = std::f32::consts::PI - r;
    }
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// A sphere's (longitude, latitude) at the unit outward normal `n`: u = 0.5 + atan2(−z, x)/2π
/// (the seam faces −x; u grows counterclockwise seen from +y, so images are not mirrored seen
/// from outside), v = 0.5 + latitude/π (v = 1 at the top pole, +y; 0 at the bottom one).
pub fn sphere_uv(n: Vec3) -> Vec2 {
    let u = 0.5 + polynomial_atan2(-n.z, n.x) * (0.5 * PI_INV);
    let v = 0.5 + polynomial_atan2(n.y, (n.x * n.x + n.z * n.z).sqrt()) * PI_INV;
    Vec2::new(u, v)
}

/// Interpolated vertex texture coordinates at barycentrics `b` (`b.x` for `uv0`).
pub fn interpolated_uv(t: &TriangleUvs, b: Vec3) -> Vec2 {
    b.x * Vec2::from(t.uv0) + b.y * Vec2::from(t.uv1) + b.z * Vec2::from(t.uv2)
}

/// A hit's texture coordinates: set 0 in xy, set 1 (glTF's TEXCOORD_1) in zw. Spheres, quads
/// and scenes without a texture on set 1 have one set, in both.
pub fn both_sets(uv: Vec2) -> Vec4 {
    Vec4::new(uv.x, uv.y, uv.x, uv.y)
}

/// Triangle `index`'s texture coordinates (both sets) at barycentrics `b`; `uvs1` (set 1) is
/// empty, the kernel's `HAS_TEXCOORD_1` off, when no texture reads it.
pub fn triangle_uv(uvs: &[TriangleUvs], uvs1: &[TriangleUvs], index: u32, b: Vec3) -> Vec4 {
    let uv = interpolated_uv(&uvs[index as usize], b);
    match uvs1.get(index as usize) {
        Some(t) => {
            let uv1 = interpolated_uv(t, b);
            Vec4::new(uv.x, uv.y, uv1.x, uv1.y)
        }
        None => both_sets(uv),
    }
}

/// Texel (x, y) of an image, counted from its bottom-left corner.
fn texel(textures: &Textures, t: &Texture, x: u32, y: u32) -> Vec3 {
    let [r, g, b, _] = textures.texels[(t.first_texel + y * t.width + x) as usize];
    Vec3::new(r, g, b)
}

/// The column or row below a sample position and the one after it, wrapped (repeat):
/// positions in [−0.5, 0) blend the last and the first texel.
fn wrapped_pair(position_floor: f32, size: u32) -> UVec2 {
    let first = if position_floor < 0.0 {
        size - 1
    } else {
        (position_floor as u32).min(size - 1)
    };
    let second = if first + 1 >= size { 0 } else { first + 1 };
    UVec2::new(first, second)
}

/// Index `i` (−1 to 2·size) of a mirrored repeat: texels 0 … size−1, then size−1 … 0, and so
/// on.
fn mirrored(i: i32, size: u32) -> u32 {
    let period = 2 * size as i32;
    let j = ((i % period) + period) % period;
    if j < size as i32 {
        j as u32
    } else {
        (period - 1 - j) as u32
    }
}

/// Along one axis of `size` texels, at texture coordinate `coord` with wrap `mode`: the two
/// texels to blend and the second one's weight (0 when `nearest`). Repeat wraps `coord` into
/// [0, 1) first, mirrored repeat into [0, 2), clamp clamps it to [0, 1].
fn axis_texels(coord: f32, size: u32, mode: u32, nearest: bool) -> (UVec2, f32) {
    let half = if nearest { 0.0 } else { 0.5 };
    if mode == TEXTURE_WRAP_MIRROR {
        let position = (coord - 2.0 * (coord * 0.5).floor()) * size as f32 - half;
        let p = position.floor();
        let weight = if nearest { 0.0 } else { position - p };
        let i = p as i32;
        return (UVec2::new(mirrored(i, size), mirrored(i + 1, size)), weight);
    }
    if mode == TEXTURE_WRAP_CLAMP {
        let position = coord.clamp(0.0, 1.0) * size as f32 - half;
        let p = position.floor();
        let weight = if nearest { 0.0 } else { position - p };
        let first = p.max(0.0).min((size - 1) as f32) as u32;
        let second = (p + 1.0).max(0.0).min((size - 1) as f32) as u32;
        return (UVec2::new(first, second), weight);
    }
    let position = (coord - coord.floor()) * size as f32 - half;
    let p = position.floor();
    let weight = if nearest { 0.0 } else { position - p };
    (wrapped_pair(p, size), weight)
}

/// The texture coordinates a texture's lookup uses: its transform (the identity, exactly,
/// unless glTF's KHR_texture_transform set one) applied to `uv`.
pub fn transformed_uv(t: &Texture, uv: Vec2) -> Vec2 {
    let h = Vec3::new(uv.x, uv.y, 1.0);
    Vec2::new(
        Vec3::from(t.transform_u).dot(h),
        Vec3::from(t.transform_v).dot(h),
    )
}

/// Bilinear (or, with `TEXTURE_NEAREST`, nearest) filtering with the texture's wrap modes
/// (repeat unless a glTF sampler says otherwise); texel centres are at ((x + 0.5)/width,
/// (y + 0.5)/height), where the lookup returns the texel itself.
pub fn image_lookup(textures: &Textures, t: &Texture, uv: Vec2) -> Vec3 {
    let nearest = t.sampling & TEXTURE_NEAREST != 0;
    let (xs, fx) = axis_texels(uv.x, t.width, t.sampling & 0xff, nearest);
    let (ys, fy) = axis_texels(uv.y, t.height, (t.sampling >> 8) & 0xff, nearest);
    let bottom = texel(textures, t, xs.x, ys.x) * (1.0 - fx) + texel(textures, t, xs.y, ys.x) * fx;
    let top = texel(textures, t, xs.x, ys.y) * (1.0 - fx) + texel(textures, t, xs.y, ys.y) * fx;
    bottom * (1.0 - fy) + top * fy
}

/// The alpha (w) of [`image_lookup`]'s texels, filtered the same way. Kept apart from
/// `image_lookup` so that lookups which need no alpha cost no more.
pub fn image_alpha(textures: &Textures, t: &Texture, uv: Vec2) -> f32 {
    let nearest = t.sampling & TEXTURE_NEAREST != 0;
    let (xs, fx) = axis_texels(uv.x, t.width, t.sampling & 0xff, nearest);
    let (ys, fy) = axis_texels(uv.y, t.height, (t.sampling >> 8) & 0xff, nearest);
    let row0 = t.first_texel + ys.x * t.width;
    let row1 = t.first_texel + ys.y * t.width;
    let w = |i: u32| textures.texels[i as usize][3];
    let bottom = w(row0 + xs.x) * (1.0 - fx) + w(row0 + xs.y) * fx;
    let top = w(row1 + xs.x) * (1.0 - fx) + w(row1 + xs.y) * fx;
    bottom * (1.0 - fy) + top * fy
}

/// `color0` where ⌊u·scale⌋ + ⌊v·scale⌋ is even, `color1` where it is odd (unfiltered).
pub fn checker_lookup(t: &Texture, uv: Vec2) -> Vec3 {
    let half_sum = ((uv.x * t.scale).floor() + (uv.y * t.scale).floor()) * 0.5;
    if half_sum != half_sum.floor() {
        Vec3::from(t.color1)
    } else {
        Vec3::from(t.color0)
    }
}

/// The set of texture coordinates (`uvs`: set 0 in xy, set 1 in zw) texture `t` reads.
pub fn texture_set(t: &Texture, uvs: Vec4) -> Vec2 {
    if t.uv_set == 1 {
        Vec2::new(uvs.z, uvs.w)
    } else {
        Vec2::new(uvs.x, uvs.y)
    }
}

pub fn texture_lookup(textures: &Textures, index: u32, uvs: Vec4) -> Vec3 {
    let t = &textures.descriptors[index as usize];
    let uv = texture_set(t, uvs);
    if t.kind == TEXTURE_CHECKER {
        return checker_lookup(t, uv);
    }
    image_lookup(textures, t, transformed_uv(t, uv))
}

/// A colour texture's alpha at `uv`: its image's alpha channel; a checker is opaque.
pub fn texture_alpha(textures: &Textures, index: u32, uvs: Vec4) -> f32 {
    let t = &textures.descriptors[index as usize];
    let uv = texture_set(t, uvs);
    if t.kind == TEXTURE_CHECKER {
        return 1.0;
    }
    image_alpha(textures, t, transformed_uv(t, uv))
}

/// The material at a hit with texture coordinates `uv` (both sets, see [`both_sets`]): textures multiply the constants
/// (glTF's rule; a TOML texture's constant is 1), before any BSDF or AOV reads them. A
/// roughness texture holds the roughness in x and the metallic factor in y (1 where the
/// image gives none, `src/scene/texture.rs`).
pub fn material_at(textures: &Textures, m: &Material, uv: Vec4) -> Material {
    let mut out = *m;
    if m.color_texture != NO_TEXTURE {
        out.albedo = (Vec3::from(m.albedo) * texture_lookup(textures, m.color_texture, uv)).into();
    }
    if m.roughness_texture != NO_TEXTURE {
        let t = texture_lookup(textures, m.roughness_texture, uv);
        // alpha = (roughness · t.x)², roughness² being the constant's alpha.
        out.alpha = m.alpha * (t.x * t.x);
        out.metallic = m.metallic * t.y;
    }
    if m.transmission_texture != NO_TEXTURE {
        // glTF's transmissionTexture: its R channel multiplies the factor.
        out.transmission = m.transmission * texture_lookup(textures, m.transmission_texture, uv).x;
    }
    // KHR_materials_clearcoat's textures: R multiplies the factor, G the roughness (the loader
    // puts it in x, as a metallic-roughness texture's).
    if m.clearcoat_texture != NO_TEXTURE {
        out.clearcoat = m.clearcoat * texture_lookup(textures, m.clearcoat_texture, uv).x;
    }
    if m.clearcoat_roughness_texture != NO_TEXTURE {
        let r = texture_lookup(textures, m.clearcoat_roughness_texture, uv).x;
        out.clearcoat_alpha = m.clearcoat_alpha * (r * r);
    }
    // KHR_materials_sheen's: RGB multiplies the colour; the roughness (the image's alpha,
    // moved to x by the loader) the roughness.
    if m.sheen_color_texture != NO_TEXTURE {
        out.sheen_color = (Vec3::from(m.sheen_color)
            * texture_lookup(textures, m.sheen_color_texture, uv))
        .into();
    }
    if m.sheen_roughness_texture != NO_TEXTURE {
        out.sheen_roughness =
            m.sheen_roughness * texture_lookup(textures, m.sheen_roughness_texture, uv).x;
    }
    out.emission = emission_at(textures, m, uv).into();
    out
}

/// The radiance material `m` emits at texture coordinates `uv`: its emission times its
/// emission texture there (sRGB-decoded), if it has one. Light sampling calls it at the point
/// it samples.
pub fn emission_at(textures: &Textures, m: &Material, uv: Vec4) -> Vec3 {
    if m.emission_texture != NO_TEXTURE {
        return Vec3::from(m.emission) * texture_lookup(textures, m.emission_texture, uv);
    }
    Vec3::from(m.emission)
}
