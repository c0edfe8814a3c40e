//! Alpha (WGSL side: `shaders/geometry/alpha.wgsl`): glTF's alphaMode on triangles. MASK cuts holes
//! where the alpha is below the material's cutoff (leaves, fences); BLEND is stochastic
//! transparency, a ray passing through with probability 1 − α; OPAQUE ignores alpha. The alpha
//! at a hit is the material's opacity times its colour texture's and its vertex colour's alpha
//! there. Every traversal
//! accepts a triangle hit only through [`hit_scene_triangle`], so camera, bounce and shadow
//! rays all see the same holes. Spheres and quads are always opaque.

use crate::cpu::core::rng::{pcg_hash, rng_init};
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::triangle::{hit_triangle, triangle_barycentrics, TriangleRay};
use crate::cpu::textures::texture::{texture_alpha, triangle_uv, Textures};
use crate::cpu::textures::vertex_color::vertex_color;
use crate::kernel::types::{
    Material, Params, Triangle, TriangleColors, TriangleUvs, ALPHA_MASK, ALPHA_OPAQUE, NO_TEXTURE,
};

/// The streams alpha decisions hash: above every stream id a path reaches (1 + 3·bounce +
/// purpose, for bounces far below 2²⁹), so they share nothing with the paths' own numbers and
/// draw none of them. One per ray segment: 0 the camera ray, b + 1 the rays that leave vertex b.
pub const ALPHA_STREAMS: u32 = 0x8000_0000;

/// What the alpha test reads: the kernel's materials, textures and texture coordinates, and its
/// private `alpha_key`.
#[derive(Clone, Copy, Debug, Default)]
pub struct AlphaTest<'a> {
    /// Whether any material is not opaque (the kernel's `HAS_ALPHA`); else nothing is read.
    pub enabled: bool,
    pub materials: &'a [Material],
    pub textures: Textures<'a>,
    pub triangle_uvs: &'a [TriangleUvs],
    /// The second set, where a texture reads it (else empty).
    pub triangle_uvs1: &'a [TriangleUvs],
    /// One per triangle when a mesh has vertex colours (the kernel's `HAS_VERTEX_COLORS`),
    /// else empty.
    pub triangle_colors: &'a [TriangleColors],
    /// The key of the segment being traced ([`alpha_segment_key`]).
    pub key: u32,
}

/// The key of segment `segment` (see [`ALPHA_STREAMS`]) of the path (`pixel`, `sample`).
pub fn alpha_segment_key(params: &Params, pixel: u32, sample: u32, segment: u32) -> u32 {
    rng_init(pixel, sample, ALPHA_STREAMS | segment, params.seed)
}

/// A number uniform in [0, 1) for (segment key, triangle), from the top 24 bits as
/// `Rng::next_f32`. A pure function, so a segment's shadow ray and its closest-hit ray (the
/// next bounce, which shares the key) decide the same for the same triangle, on either device.
pub fn alpha_uniform(key: u32, index: u32) -> f32 {
    let bits = pcg_hash(key ^ pcg_hash(index));
    (bits >> 8) as f32 * (1.0 / 16777216.0)
}

/// Whether `r`'s hit on triangle `index` (`tri`) is no hit: alpha below the cutoff (MASK), or
/// the segment's number at or above alpha (BLEND: it passes with probability 1 − α).
pub fn alpha_skips(alpha: &AlphaTest, index: u32, tri: &Triangle, r: &TriangleRay) -> bool {
    let m = &alpha.materials[tri.material as usize];
    if m.alpha_mode == ALPHA_OPAQUE {
        return false;
    }
    let mut a = m.opacity;
    if m.color_texture != NO_TEXTURE || !alpha.triangle_colors.is_empty() {
        // The barycentrics shading uses at this hit (`intersect_scene`), so the holes are where
        // the colour texture and the vertex colours show them.
        let b = triangle_barycentrics(tri, r);
        if m.color_texture != NO_TEXTURE {
            let uv = triangle_uv(alpha.triangle_uvs, alpha.triangle_uvs1, index, b);
            a *= texture_alpha(&alpha.textures, m.color_texture, uv);
        }
        if let Some(colors) = alpha.triangle_colors.get(index as usize) {
            a *= vertex_color(colors, b).w;
        }
    }
    if m.alpha_mode == ALPHA_MASK {
        return a < m.alpha_cutoff;
    }
    alpha_uniform(alpha.key, index) >= a
}

/// t of `r`'s hit on the scene's triangle `index` (`tri`), or `NO_HIT`, holes included.
pub fn hit_scene_triangle(alpha: &AlphaTest, index: u32, tri: &Triangle, r: &TriangleRay) -> f32 {
    let t = hit_triangle(tri, r);
    if alpha.enabled && t != NO_HIT && alpha_skips(alpha, index, tri, r) {
        return NO_HIT;
    }
    t
}
