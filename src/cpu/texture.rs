//! Textures (WGSL side: `shaders/texture.wgsl`): texture coordinates at a hit, image lookups
//! with bilinear filtering and repeat wrapping, procedural checkers, and the material at a hit.
//! The filtering is written out by hand on both sides, in the same f32 operations, because a
//! hardware sampler's filtering precision is implementation-defined.

use crate::shader_types::{Material, Texture, TriangleUvs, NO_TEXTURE, TEXTURE_CHECKER};
use glam::{UVec2, Vec2, Vec3};

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
pub fn triangle_uv(t: &TriangleUvs, b: Vec3) -> Vec2 {
    b.x * Vec2::from(t.uv0) + b.y * Vec2::from(t.uv1) + b.z * Vec2::from(t.uv2)
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

/// Bilinear filtering with repeat wrapping; texel centres are at ((x + 0.5)/width,
/// (y + 0.5)/height), where the lookup returns the texel itself.
pub fn image_lookup(textures: &Textures, t: &Texture, uv: Vec2) -> Vec3 {
    let x = (uv.x - uv.x.floor()) * t.width as f32 - 0.5;
    let y = (uv.y - uv.y.floor()) * t.height as f32 - 0.5;
    let x_floor = x.floor();
    let y_floor = y.floor();
    let fx = x - x_floor;
    let fy = y - y_floor;
    let xs = wrapped_pair(x_floor, t.width);
    let ys = wrapped_pair(y_floor, t.height);
    let bottom = texel(textures, t, xs.x, ys.x) * (1.0 - fx) + texel(textures, t, xs.y, ys.x) * fx;
    let top = texel(textures, t, xs.x, ys.y) * (1.0 - fx) + texel(textures, t, xs.y, ys.y) * fx;
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

pub fn texture_lookup(textures: &Textures, index: u32, uv: Vec2) -> Vec3 {
    let t = &textures.descriptors[index as usize];
    if t.kind == TEXTURE_CHECKER {
        return checker_lookup(t, uv);
    }
    image_lookup(textures, t, uv)
}

/// The material at a hit with texture coordinates `uv`: textures multiply the constants
/// (glTF's rule; a TOML texture's constant is 1), before any BSDF or AOV reads them. A
/// roughness texture holds the roughness in x and the metallic factor in y (1 where the
/// image gives none, `src/scene/texture.rs`).
pub fn material_at(textures: &Textures, m: &Material, uv: Vec2) -> Material {
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
    out
}
