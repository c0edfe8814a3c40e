// Counter-based random numbers (mirror: src/cpu/core/rng.rs). Every (pixel, sample, stream, seed)
// gets its own stream, so a sample's numbers do not depend on batch size or on the device.
// Stream 0 is the camera; each bounce has one stream per purpose, so a routine that draws more
// or fewer numbers never shifts the numbers of another. Params.sampler picks independent PCG
// numbers or padded, Owen-scrambled 2D Sobol points (draws 2k and 2k + 1 of a stream are one
// point; Burley 2020).

const PURPOSE_BSDF: u32 = 0u;
const PURPOSE_LIGHT: u32 = 1u;
const PURPOSE_ROULETTE: u32 = 2u;
// Participating media (media/): a segment's free flight, a medium vertex's phase sampling and
// its next-event estimation.
const PURPOSE_FREE_FLIGHT: u32 = 3u;
const PURPOSE_PHASE: u32 = 4u;
const PURPOSE_MEDIUM_LIGHT: u32 = 5u;
const PURPOSE_TRACKING: u32 = 6u;

const SAMPLER_INDEPENDENT: u32 = 0u;
const SAMPLER_SOBOL: u32 = 1u;

fn stream_id(bounce: u32, purpose: u32) -> u32 {
    if purpose < 3u {
        return 1u + 3u * bounce + purpose;
    }
    // Later purposes get a range of their own (above any 1 + 3 bounce), so that the first
    // three keep their streams and media-free images their pixels.
    return 0x80000000u + 8u * bounce + purpose;
}

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_init(pixel: u32, sample: u32, stream: u32, seed: u32) -> u32 {
    return pcg_hash(pixel + pcg_hash(sample + pcg_hash(stream + pcg_hash(seed))));
}

// The draws of one (pixel, sample, stream, seed). state: the PCG state (independent) or the
// stream's scrambling seed (Sobol); draw: draws so far (Sobol only).
struct Rng {
    state: u32,
    sample: u32,
    draw: u32,
    sobol: u32,
}

// Nested uniform (Owen) scramble, hash-based: Laine-Karras style on the reversed bits, with
// Vegdahl's constants; every step only carries upwards in the reversed word.
fn owen_scramble(x_in: u32, seed: u32) -> u32 {
    var x = reverseBits(x_in);
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return reverseBits(x);
}

// The second Sobol dimension: column k of its matrix is row k of Pascal's triangle mod 2, so
// digit j is the XOR of the index bits k whose bits contain j's (Lucas): a superset-sum
// transform in five steps.
fn sobol_dimension1(index: u32) -> u32 {
    var x = index;
    x ^= (x >> 1u) & 0x55555555u;
    x ^= (x >> 2u) & 0x33333333u;
    x ^= (x >> 4u) & 0x0f0f0f0fu;
    x ^= (x >> 8u) & 0x00ff00ffu;
    x ^= x >> 16u;
    return reverseBits(x);
}

fn sobol_bits(stream_seed: u32, pair: u32, dimension: u32, sample: u32) -> u32 {
    let pair_seed = pcg_hash(stream_seed ^ pcg_hash(pair));
    // An Owen-scrambled index keeps aligned blocks of 2^k samples aligned blocks (nets).
    let index = owen_scramble(sample, pair_seed);
    var x = reverseBits(index);
    if dimension != 0u {
        x = sobol_dimension1(index);
    }
    return owen_scramble(x, pcg_hash(pair_seed + 1u + dimension));
}

fn sobol_stream_seed(pixel: u32, stream: u32, seed: u32) -> u32 {
    return pcg_hash(pixel + pcg_hash(stream + pcg_hash(seed ^ 0x5b0b0f11u)));
}

fn rng_stream(pixel: u32, sample: u32, stream: u32, seed: u32, sampler: u32) -> Rng {
    if sampler == SAMPLER_SOBOL {
        return Rng(sobol_stream_seed(pixel, stream, seed), sample, 0u, 1u);
    }
    return Rng(rng_init(pixel, sample, stream, seed), sample, 0u, 0u);
}

// Uniform in [0, 1): the top 24 bits, so the conversion to f32 is exact on every device.
fn rng_next(rng: ptr<function, Rng>) -> f32 {
    var bits: u32;
    if (*rng).sobol != 0u {
        let draw = (*rng).draw;
        (*rng).draw = draw + 1u;
        bits = sobol_bits((*rng).state, draw >> 1u, draw & 1u, (*rng).sample);
    } else {
        (*rng).state = (*rng).state * 747796405u + 2891336453u;
        let s = (*rng).state;
        let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
        bits = (word >> 22u) ^ word;
    }
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}
