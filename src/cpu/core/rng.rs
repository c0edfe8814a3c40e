//! Counter-based random numbers (WGSL side: `shaders/core/rng.wgsl`), bit for bit.
//! Stream 0 is the camera; each bounce has one stream per purpose, so a routine that draws
//! more or fewer numbers never shifts the numbers of another.

pub const PURPOSE_BSDF: u32 = 0;
pub const PURPOSE_LIGHT: u32 = 1;
pub const PURPOSE_ROULETTE: u32 = 2;

pub fn stream_id(bounce: u32, purpose: u32) -> u32 {
    1 + 3 * bounce + purpose
}

pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// A PCG stream for one (pixel, sample, stream, seed).
#[derive(Clone, Debug)]
pub struct Rng {
    state: u32,
}

/// The first state of the stream (pixel, sample, stream, seed).
pub fn rng_init(pixel: u32, sample: u32, stream: u32, seed: u32) -> u32 {
    pcg_hash(pixel.wrapping_add(pcg_hash(
        sample.wrapping_add(pcg_hash(stream.wrapping_add(pcg_hash(seed)))),
    )))
}

impl Rng {
    pub fn new(pixel: u32, sample: u32, stream: u32, seed: u32) -> Self {
        Rng {
            state: rng_init(pixel, sample, stream, seed),
        }
    }

    /// Uniform in [0, 1), from the top 24 bits so the conversion to f32 is exact.
    pub fn next_f32(&mut self) -> f32 {
        self.state = self.state.wrapping_mul(747796405).wrapping_add(2891336453);
        let s = self.state;
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
        let bits = (word >> 22) ^ word;
        (bits >> 8) as f32 * (1.0 / 16777216.0)
    }
}
