// Textures (mirror: src/cpu/textures/texture.rs): texture coordinates at a hit, image lookups with
// bilinear or nearest filtering and repeat, clamped or mirrored wrapping, procedural checkers,
// and the material at a hit.
//
// Textures live in storage buffers and are filtered by hand, not by a sampler: a hardware
// sampler's filtering precision is implementation-defined (weights may be 8-bit fixed point),
// so it would break "GPU and CPU trace the same paths". Compiled in only when a material uses
// a texture (HAS_TEXTURES, src/kernel/variant.rs).

// Every texture's descriptor, and all images' texels (linear RGB; w a colour texture's alpha,
// 1 where its file has none, and unused in the others) one after another, read through
// texel_at (shaders/textures/texels/: one binding, or windows over several).
@group(0) @binding(20) var<storage, read> textures: array<Texture>;
@group(0) @binding(21) var<storage, read> texels: array<vec4<f32>>;
// One per triangle when the scene has textures (a placeholder otherwise).
@group(0) @binding(22) var<storage, read> triangle_uvs: array<TriangleUvs>;
// glTF's TEXCOORD_1, one per triangle when a texture reads it (HAS_TEXCOORD_1; a placeholder
// otherwise).
@group(0) @binding(35) var<storage, read> triangle_uvs1: array<TriangleUvs>;

const PI_INV: f32 = 0.318309886183791;

// atan2(y, x) in (-pi, pi] from a polynomial (Abramowitz and Stegun 4.4.49, |error| <= 2e-8
// rad, below an f32 ulp of pi): Vulkan lets atan and acos be off by 4096 ulps, which would make
// the GPU's texture coordinates, and colours, differ from the CPU's.
fn polynomial_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    let big = max(ax, ay);
    let t = select(min(ax, ay) / big, 0.0, big == 0.0);
    let t2 = t * t;
    var r = (((((((-0.0040540580 * t2 + 0.0218612288) * t2 - 0.0559098861) * t2 + 0.0964200441)
        * t2 - 0.1390853351) * t2 + 0.1994653599) * t2 - 0.3332985605) * t2 + 0.9999993329) * t;
    r = select(r, 1.57079632679490 - r, ay > ax);
    r = select(r, 3.14159265358979 - r, x < 0.0);
    return select(r, -r, y < 0.0);
}

// A sphere's (longitude, latitude) at the unit outward normal n: u = 0.5 + atan2(-z, x) / 2pi
// (the seam faces -x; u grows counterclockwise seen from +y, so images are not mirrored seen
// from outside), v = 0.5 + latitude / pi (v = 1 at the top pole, +y; 0 at the bottom one).
fn sphere_uv(n: vec3<f32>) -> vec2<f32> {
    let u = 0.5 + polynomial_atan2(-n.z, n.x) * (0.5 * PI_INV);
    let v = 0.5 + polynomial_atan2(n.y, sqrt(n.x * n.x + n.z * n.z)) * PI_INV;
    return vec2<f32>(u, v);
}

// Interpolated vertex texture coordinates at barycentrics b (b.x for uv0).
fn interpolated_uv(t: TriangleUvs, b: vec3<f32>) -> vec2<f32> {
    return b.x * t.uv0 + b.y * t.uv1 + b.z * t.uv2;
}

// A hit's texture coordinates: set 0 in xy, set 1 (glTF's TEXCOORD_1) in zw. Spheres, quads
// and scenes without a texture on set 1 have one set, in both.
fn both_sets(uv: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(uv, uv);
}

// Triangle `index`'s texture coordinates (both sets) at barycentrics b.
fn triangle_uv(index: u32, b: vec3<f32>) -> vec4<f32> {
    let uv = interpolated_uv(triangle_uvs[index], b);
    if HAS_TEXCOORD_1 {
        return vec4<f32>(uv, interpolated_uv(triangle_uvs1[index], b));
    }
    return both_sets(uv);
}

// Texel (x, y) of an image, counted from its bottom-left corner.
fn texel(t: Texture, x: u32, y: u32) -> vec3<f32> {
    return texel_at(t.first_texel + y * t.width + x).xyz;
}

// The column or row below a sample position and the one after it, wrapped (repeat): positions
// in [-0.5, 0) blend the last and the first texel.
fn wrapped_pair(position_floor: f32, size: u32) -> vec2<u32> {
    let first = select(min(u32(position_floor), size - 1u), size - 1u, position_floor < 0.0);
    let second = select(first + 1u, 0u, first + 1u >= size);
    return vec2<u32>(first, second);
}

// Index i (-1 to 2 size) of a mirrored repeat: texels 0 ... size - 1, then size - 1 ... 0, and
// so on.
fn mirrored(i: i32, size: u32) -> u32 {
    let period = 2 * i32(size);
    let j = ((i % period) + period) % period;
    return u32(select(period - 1 - j, j, j < i32(size)));
}

// The two texels to blend along one axis and the second one's weight (see axis_texels in
// src/cpu/textures/texture.rs).
struct AxisTexels {
    pair: vec2<u32>,
    weight: f32,
}

// Along one axis of size texels, at texture coordinate coord with wrap mode: the two texels to
// blend and the second one's weight (0 when nearest). Repeat wraps coord into [0, 1) first,
// mirrored repeat into [0, 2), clamp clamps it to [0, 1].
fn axis_texels(coord: f32, size: u32, mode: u32, nearest: bool) -> AxisTexels {
    let half = select(0.5, 0.0, nearest);
    if mode == TEXTURE_WRAP_MIRROR {
        let position = (coord - 2.0 * floor(coord * 0.5)) * f32(size) - half;
        let p = floor(position);
        let weight = select(position - p, 0.0, nearest);
        let i = i32(p);
        return AxisTexels(vec2<u32>(mirrored(i, size), mirrored(i + 1, size)), weight);
    }
    if mode == TEXTURE_WRAP_CLAMP {
        let position = clamp(coord, 0.0, 1.0) * f32(size) - half;
        let p = floor(position);
        let weight = select(position - p, 0.0, nearest);
        let first = u32(min(max(p, 0.0), f32(size - 1u)));
        let second = u32(min(max(p + 1.0, 0.0), f32(size - 1u)));
        return AxisTexels(vec2<u32>(first, second), weight);
    }
    let position = (coord - floor(coord)) * f32(size) - half;
    let p = floor(position);
    let weight = select(position - p, 0.0, nearest);
    return AxisTexels(wrapped_pair(p, size), weight);
}

// The texture coordinates a texture's lookup uses: its transform (the identity, exactly,
// unless glTF's KHR_texture_transform set one) applied to uv.
fn transformed_uv(t: Texture, uv: vec2<f32>) -> vec2<f32> {
    let h = vec3<f32>(uv, 1.0);
    return vec2<f32>(dot(t.transform_u, h), dot(t.transform_v, h));
}

// Bilinear (or, with TEXTURE_NEAREST, nearest) filtering with the texture's wrap modes (repeat
// unless a glTF sampler says otherwise); texel centres are at ((x + 0.5) / width,
// (y + 0.5) / height), where the lookup returns the texel itself.
fn image_lookup(t: Texture, uv: vec2<f32>) -> vec3<f32> {
    let nearest = (t.sampling & TEXTURE_NEAREST) != 0u;
    let xs = axis_texels(uv.x, t.width, t.sampling & 0xffu, nearest);
    let ys = axis_texels(uv.y, t.height, (t.sampling >> 8u) & 0xffu, nearest);
    let fx = xs.weight;
    let fy = ys.weight;
    let bottom = texel(t, xs.pair.x, ys.pair.x) * (1.0 - fx) + texel(t, xs.pair.y, ys.pair.x) * fx;
    let top = texel(t, xs.pair.x, ys.pair.y) * (1.0 - fx) + texel(t, xs.pair.y, ys.pair.y) * fx;
    return bottom * (1.0 - fy) + top * fy;
}

// The alpha (w) of image_lookup's texels, filtered the same way. Kept apart from image_lookup
// so that lookups which need no alpha (every one in a scene without alpha) cost no more.
fn image_alpha(t: Texture, uv: vec2<f32>) -> f32 {
    let nearest = (t.sampling & TEXTURE_NEAREST) != 0u;
    let xs = axis_texels(uv.x, t.width, t.sampling & 0xffu, nearest);
    let ys = axis_texels(uv.y, t.height, (t.sampling >> 8u) & 0xffu, nearest);
    let fx = xs.weight;
    let fy = ys.weight;
    let row0 = t.first_texel + ys.pair.x * t.width;
    let row1 = t.first_texel + ys.pair.y * t.width;
    let bottom = texel_at(row0 + xs.pair.x).w * (1.0 - fx) + texel_at(row0 + xs.pair.y).w * fx;
    let top = texel_at(row1 + xs.pair.x).w * (1.0 - fx) + texel_at(row1 + xs.pair.y).w * fx;
    return bottom * (1.0 - fy) + top * fy;
}

// color0 where floor(u scale) + floor(v scale) is even, color1 where it is odd (unfiltered).
fn checker_lookup(t: Texture, uv: vec2<f32>) -> vec3<f32> {
    let half_sum = (floor(uv.x * t.scale) + floor(uv.y * t.scale)) * 0.5;
    return select(t.color0, t.color1, half_sum != floor(half_sum));
}

// The set of texture coordinates (uvs: set 0 in xy, set 1 in zw) texture t reads.
fn texture_set(t: Texture, uvs: vec4<f32>) -> vec2<f32> {
    return select(uvs.xy, uvs.zw, t.uv_set == 1u);
}

fn texture_lookup(index: u32, uvs: vec4<f32>) -> vec3<f32> {
    let t = textures[index];
    let uv = texture_set(t, uvs);
    if t.kind == TEXTURE_CHECKER {
        return checker_lookup(t, uv);
    }
    return image_lookup(t, transformed_uv(t, uv));
}

// A colour texture's alpha at uv: its image's alpha channel; a checker is opaque.
fn texture_alpha(index: u32, uvs: vec4<f32>) -> f32 {
    let t = textures[index];
    let uv = texture_set(t, uvs);
    if t.kind == TEXTURE_CHECKER {
        return 1.0;
    }
    return image_alpha(t, transformed_uv(t, uv));
}

// The material at a hit with texture coordinates uv (both sets, see both_sets): textures multiply the constants (glTF's
// rule; a TOML texture's constant is 1), before any BSDF or AOV reads them. A roughness
// texture holds the roughness in x and the metallic factor in y (1 where the image gives none,
// src/scene/texture.rs).
fn material_at(m: Material, uv: vec4<f32>) -> Material {
    var out = m;
    if HAS_TEXTURES {
        if m.color_texture != NO_TEXTURE {
            out.albedo = m.albedo * texture_lookup(m.color_texture, uv);
        }
        if m.roughness_texture != NO_TEXTURE {
            let t = texture_lookup(m.roughness_texture, uv);
            // alpha = (roughness t.x)^2, roughness^2 being the constant's alpha.
            out.alpha = m.alpha * (t.x * t.x);
            out.metallic = m.metallic * t.y;
        }
        if m.transmission_texture != NO_TEXTURE {
            // glTF's transmissionTexture: its R channel multiplies the factor.
            out.transmission = m.transmission * texture_lookup(m.transmission_texture, uv).x;
        }
        // KHR_materials_clearcoat's textures: R multiplies the factor, G the roughness (the
        // loader puts it in x).
        if m.clearcoat_texture != NO_TEXTURE {
            out.clearcoat = m.clearcoat * texture_lookup(m.clearcoat_texture, uv).x;
        }
        if m.clearcoat_roughness_texture != NO_TEXTURE {
            let r = texture_lookup(m.clearcoat_roughness_texture, uv).x;
            out.clearcoat_alpha = m.clearcoat_alpha * (r * r);
        }
        // KHR_materials_sheen's: RGB multiplies the colour, the roughness (moved to x) the
        // roughness.
        if m.sheen_color_texture != NO_TEXTURE {
            out.sheen_color = m.sheen_color * texture_lookup(m.sheen_color_texture, uv);
        }
        if m.sheen_roughness_texture != NO_TEXTURE {
            out.sheen_roughness = m.sheen_roughness * texture_lookup(m.sheen_roughness_texture, uv).x;
        }
        out.emission = emission_at(m, uv);
    }
    return out;
}

// The radiance material m emits at texture coordinates uv: its emission times its emission
// texture there (sRGB-decoded), if it has one. Light sampling calls it at the point it samples.
fn emission_at(m: Material, uv: vec4<f32>) -> vec3<f32> {
    if HAS_TEXTURES && m.emission_texture != NO_TEXTURE {
        return m.emission * texture_lookup(m.emission_texture, uv);
    }
    return m.emission;
}
