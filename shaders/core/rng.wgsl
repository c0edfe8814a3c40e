// Counter-based random numbers (mirror: src/cpu/core/rng.rs). Every (pixel, sample, stream, seed)
// gets its own PCG stream, so a sample's numbers do not depend on batch size or on the device.
// Stream 0 is the camera; each bounce has one stream per purpose, so a routine that draws more
// or fewer numbers never shifts the numbers of another.

const PURPOSE_BSDF: u32 = 0u;
const PURPOSE_LIGHT: u32 = 1u;
const PURPOSE_ROULETTE: u32 = 2u;

fn stream_id(bounce: u32, purpose: u32) -> u32 {
    return 1u + 3u * bounce + purpose;
}

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_init(pixel: u32, sample: u32, stream: u32, seed: u32) -> u32 {
    return pcg_hash(pixel + pcg_hash(sample + pcg_hash(stream + pcg_hash(seed))));
}

// Uniform in [0, 1): the top 24 bits, so the conversion to f32 is exact on every device.
fn rng_next(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    let bits = (word >> 22u) ^ word;
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}
