// The splat film (mirror: src/cpu/integrator/splat.rs): light tracing's contributions, added
// into whichever pixel they land in, by every pixel's samples at once. WGSL has only 32-bit
// integer atomics, and a float sum would depend on the order of the adds; so each channel is a
// 64-bit fixed-point sum, two u32 words, to which every splat adds an integer: the sum is exact
// and the same in any order, on the GPU and on the CPU, and a render is reproducible byte for
// byte.
//
// A splat of value v adds floor(v * scale + 1/2) (Params.splat_scale), clamped to 2^62 so that
// none wraps alone. The 64-bit add is two 32-bit atomic adds: the low word's, whose old value
// tells whether it carried, then the high part and the carry into the high word. Each low add
// carries at most once, and the carries of all of them together are the low word's wraps,
// whatever their order: the pair ends as the 64-bit sum would, modulo 2^64, as the CPU's
// wrapping u64 add does. Compiled in only with bidirectional path tracing.

// Per pixel and channel (3 * pixel + c) the sum's low word at 2 (3 * pixel + c) and its high
// word after it: the little-endian u64s of the CPU's film, read back as they are.
@group(0) @binding(14) var<storage, read_write> splats: array<atomic<u32>>;

// The largest integer one splat adds (per channel): 2^62.
const MAX_SPLAT: f32 = 4.611686e18;

// The fixed-point words (low, high) of a splat of value v at `scale`, in f32 throughout as the
// CPU computes them: x < 2^32 converts directly; above, x is a multiple of 2^8, and its high
// and low words split exactly. Only v > 0 adds anything: tested by its bits (positive, not
// zero, not NaN; +infinity clamps to 2^62), since a compiler may assume floats are never NaN.
fn fixed_point_words(v: f32, scale: f32) -> vec2<u32> {
    let bits = bitcast<u32>(v);
    if !(bits > 0u && bits <= 0x7f800000u) {
        return vec2<u32>(0u);
    }
    let x = min(floor(v * scale + 0.5), MAX_SPLAT);
    if x < 4294967296.0 {
        return vec2<u32>(u32(x), 0u);
    }
    let high = floor(x * (1.0 / 4294967296.0));
    let low = (x * (1.0 / 4294967296.0) - high) * 4294967296.0;
    return vec2<u32>(u32(low), u32(high));
}

// Adds the 64-bit integer (words.x low, words.y high) to sum `index`.
fn splat_add_words(index: u32, words: vec2<u32>) {
    let old = atomicAdd(&splats[2u * index], words.x);
    // The low word wrapped: carry one into the high word.
    let carry = select(0u, 1u, old + words.x < old);
    let high = words.y + carry;
    if high != 0u {
        atomicAdd(&splats[2u * index + 1u], high);
    }
}

// Adds one channel's value v to sum `index` at Params.splat_scale.
fn splat_add_value(index: u32, v: f32) {
    let words = fixed_point_words(v, params.splat_scale);
    if any(words != vec2<u32>(0u)) {
        splat_add_words(index, words);
    }
}

// Adds `radiance` to `pixel` (written out per channel: no loop for lavapipe's loop limit,
// src/gpu/loop_budget.rs, to count).
fn splat_add(pixel: u32, radiance: vec3<f32>) {
    splat_add_value(3u * pixel, radiance.x);
    splat_add_value(3u * pixel + 1u, radiance.y);
    splat_add_value(3u * pixel + 2u, radiance.z);
}
