// Alpha (mirror: src/cpu/geometry/alpha.rs): glTF's alphaMode on triangles. MASK cuts holes where the
// alpha is below the material's cutoff (leaves, fences); BLEND is stochastic transparency, a
// ray passing through with probability 1 - alpha; OPAQUE ignores alpha. The alpha at a hit is
// the material's opacity times its colour texture's alpha and its vertex colour's alpha there. Every traversal (the scan,
// the BVH, the ray queries) accepts a triangle hit only through hit_scene_triangle, so camera,
// bounce and shadow rays all see the same holes. Spheres and quads are always opaque.
// Compiled in only when a material is not opaque (HAS_ALPHA, src/kernel/variant.rs).

// The streams alpha decisions hash: above every stream_id a path reaches (1 + 3 bounce +
// purpose, for bounces far below 2^29), so they share nothing with the paths' own numbers and
// draw none of them. One per ray segment: 0 the camera ray, b + 1 the rays that leave vertex b.
const ALPHA_STREAMS: u32 = 0x80000000u;

// The key of the segment being traced, set by path.wgsl before each traversal when HAS_ALPHA.
// A private variable (per invocation, like the path) rather than an argument threaded through
// every traversal.
var<private> alpha_key: u32 = 0u;

// The key of segment `segment` (see ALPHA_STREAMS) of the path (pixel, sample).
fn alpha_segment_key(pixel: u32, sample: u32, segment: u32) -> u32 {
    return rng_init(pixel, sample, ALPHA_STREAMS | segment, params.seed);
}

// A number uniform in [0, 1) for (segment key, triangle), from the top 24 bits as rng_next.
// A pure function, so a segment's shadow ray and its closest-hit ray (the next bounce, which
// shares the key) decide the same for the same triangle, on either device.
fn alpha_uniform(key: u32, index: u32) -> f32 {
    let bits = pcg_hash(key ^ pcg_hash(index));
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}

// Whether r's hit on triangle `index` (tri) is no hit: alpha below the cutoff (MASK), or the
// segment's number at or above alpha (BLEND: it passes with probability 1 - alpha).
fn alpha_skips(index: u32, tri: Triangle, r: TriangleRay) -> bool {
    let m = materials[tri.material];
    if m.alpha_mode == ALPHA_OPAQUE {
        return false;
    }
    var alpha = m.opacity;
    if (HAS_TEXTURES && m.color_texture != NO_TEXTURE) || HAS_VERTEX_COLORS {
        // The barycentrics shading uses at this hit (intersect_scene), so the holes are where
        // the colour texture and the vertex colours show them.
        let b = triangle_barycentrics(tri, r);
        if HAS_TEXTURES && m.color_texture != NO_TEXTURE {
            alpha *= texture_alpha(m.color_texture, triangle_uv(index, b));
        }
        if HAS_VERTEX_COLORS {
            alpha *= vertex_color(index, b).w;
        }
    }
    if m.alpha_mode == ALPHA_MASK {
        return alpha < m.alpha_cutoff;
    }
    return alpha_uniform(alpha_key, index) >= alpha;
}

// t of r's hit on the scene's triangle `index`, or NO_HIT, holes included.
fn hit_scene_triangle(index: u32, r: TriangleRay) -> f32 {
    let tri = triangles[index];
    let t = hit_triangle(tri, r);
    if HAS_ALPHA && t != NO_HIT && alpha_skips(index, tri, r) {
        return NO_HIT;
    }
    return t;
}
