//! Counter-based random numbers (WGSL side: `shaders/core/rng.wgsl`), bit for bit.
//! Stream 0 is the camera; each bounce has one stream per purpose, so a routine that draws
//! more or fewer numbers never shifts the numbers of another.
//!
//! Two samplers (`Params::sampler`): independent PCG numbers, or Owen-scrambled Sobol points
//! (Burley 2020, "Practical Hash-based Owen Scrambling"). With Sobol, draws 2k and 2k + 1 of a
//! stream are the two coordinates of a 2D Sobol point, its sample index shuffled and each
//! coordinate scrambled by hashes of (pixel, stream, k, seed): "padded" 2D Sobol, so every pair
//! is stratified over a pixel's samples and pairs are decorrelated from one another. Either
//! way a number depends only on (pixel, sample, stream, draw, seed), whatever device renders it.

pub const PURPOSE_BSDF: u32 = 0;
pub const PURPOSE_LIGHT: u32 = 1;
pub const PURPOSE_ROULETTE: u32 = 2;
/// Participating media (`src/cpu/media/`): a segment's free flight, a medium vertex's phase
/// sampling and its next-event estimation.
pub const PURPOSE_FREE_FLIGHT: u32 = 3;
pub const PURPOSE_PHASE: u32 = 4;
pub const PURPOSE_MEDIUM_LIGHT: u32 = 5;
/// Ratio tracking through grid media along a vertex's shadow ray (`src/cpu/media/grid.rs`).
pub const PURPOSE_TRACKING: u32 = 6;

/// `Params::sampler`: independent uniform numbers (a PCG stream per sample).
pub const SAMPLER_INDEPENDENT: u32 = 0;
/// `Params::sampler`: Owen-scrambled, shuffled 2D Sobol points per pair of draws.
pub const SAMPLER_SOBOL: u32 = 1;

pub fn stream_id(bounce: u32, purpose: u32) -> u32 {
    if purpose < 3 {
        return 1 + 3 * bounce + purpose;
    }
    // Later purposes get a range of their own (above any 1 + 3 · bounce), so that the first
    // three keep their streams and media-free images their pixels.
    0x8000_0000 + 8 * bounce + purpose
}

pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// The draws of one (pixel, sample, stream, seed).
#[derive(Clone, Debug)]
pub struct Rng {
    /// Independent: the PCG state. Sobol: the stream's scrambling seed.
    state: u32,
    sample: u32,
    /// Draws so far (Sobol only).
    draw: u32,
    sobol: bool,
}

/// The first state of the stream (pixel, sample, stream, seed).
pub fn rng_init(pixel: u32, sample: u32, stream: u32, seed: u32) -> u32 {
    pcg_hash(pixel.wrapping_add(pcg_hash(
        sample.wrapping_add(pcg_hash(stream.wrapping_add(pcg_hash(seed)))),
    )))
}

/// A hash-based nested uniform (Owen) scramble of the bits of `x`, most significant first:
/// each bit is flipped by a hash of the bits above it. Laine–Karras style permutation of the
/// reversed bits with Vegdahl's constants (better avalanche than Burley's original ones); each
/// step only carries into higher bits of the reversed word, which is what makes it nested.
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    let mut x = x.reverse_bits();
    x ^= x.wrapping_mul(0x3d20adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x05526c56);
    x ^= x.wrapping_mul(0x53a22864);
    x.reverse_bits()
}

/// The second Sobol dimension (the first is the bit reversal of the index): the generator
/// matrix whose column k is the k-th row of Pascal's triangle mod 2. By Lucas' theorem
/// binomial(k, j) is odd iff the bits of j are a subset of k's, so digit j is the XOR of the
/// index bits k ⊇ j: a superset-sum transform, five shift-and-XOR steps instead of a loop
/// over 32 bits.
pub fn sobol_dimension1(index: u32) -> u32 {
    let mut x = index;
    x ^= (x >> 1) & 0x5555_5555;
    x ^= (x >> 2) & 0x3333_3333;
    x ^= (x >> 4) & 0x0f0f_0f0f;
    x ^= (x >> 8) & 0x00ff_00ff;
    x ^= x >> 16;
    x.reverse_bits()
}

/// Coordinate `dimension` (0 or 1) of the pair `pair` of a stream whose seed is `stream_seed`,
/// for sample `sample`, as 32 bits of a fraction.
pub fn sobol_bits(stream_seed: u32, pair: u32, dimension: u32, sample: u32) -> u32 {
    let pair_seed = pcg_hash(stream_seed ^ pcg_hash(pair));
    // Shuffling the index by an Owen scramble keeps every aligned block of 2^k samples an
    // aligned block, so the first 2^k samples of a pixel stay a (0, k, 2)-net.
    let index = owen_scramble(sample, pair_seed);
    let x = if dimension == 0 {
        index.reverse_bits()
    } else {
        sobol_dimension1(index)
    };
    owen_scramble(x, pcg_hash(pair_seed.wrapping_add(1 + dimension)))
}

/// The scrambling seed of the Sobol stream (pixel, stream, seed): not of the sample, which
/// indexes the sequence instead.
pub fn sobol_stream_seed(pixel: u32, stream: u32, seed: u32) -> u32 {
    pcg_hash(pixel.wrapping_add(pcg_hash(stream.wrapping_add(pcg_hash(seed ^ 0x5b0b_0f11)))))
}

impl Rng {
    /// An independent (PCG) stream.
    pub fn new(pixel: u32, sample: u32, stream: u32, seed: u32) -> Self {
        Self::with_sampler(pixel, sample, stream, seed, SAMPLER_INDEPENDENT)
    }

    /// The stream of `Params::sampler` `sampler`.
    pub fn with_sampler(pixel: u32, sample: u32, stream: u32, seed: u32, sampler: u32) -> Self {
        let sobol = sampler == SAMPLER_SOBOL;
        Rng {
            state: if sobol {
                sobol_stream_seed(pixel, stream, seed)
            } else {
                rng_init(pixel, sample, stream, seed)
            },
            sample,
            draw: 0,
            sobol,
        }
    }

    /// Uniform in [0, 1), from the top 24 bits so the conversion to f32 is exact.
    pub fn next_f32(&mut self) -> f32 {
        let bits = if self.sobol {
            let draw = self.draw;
            self.draw += 1;
            sobol_bits(self.state, draw >> 1, draw & 1, self.sample)
        } else {
            self.state = self.state.wrapping_mul(747796405).wrapping_add(2891336453);
            let s = self.state;
            let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
            (word >> 22) ^ word
        };
        (bits >> 8) as f32 * (1.0 / 16777216.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first 2^k samples of a pixel put exactly one point of each pair in every
    /// elementary interval of area 2^-k (every 2^a × 2^(k-a) grid): a (0, k, 2)-net.
    #[test]
    fn sobol_pairs_are_nets() {
        for k in [2u32, 4, 6, 8] {
            let n = 1u32 << k;
            for (pixel, stream, pair) in [(0, 0, 0), (17, 3, 1), (12345, 7, 2), (999, 1, 5)] {
                let stream_seed = sobol_stream_seed(pixel, stream, 42);
                let points: Vec<(u32, u32)> = (0..n)
                    .map(|s| {
                        let x = sobol_bits(stream_seed, pair, 0, s) >> 8;
                        let y = sobol_bits(stream_seed, pair, 1, s) >> 8;
                        (x, y)
                    })
                    .collect();
                for a in 0..=k {
                    let mut seen = vec![false; n as usize];
                    for &(x, y) in &points {
                        let cell = ((x >> (24 - a)) << (k - a)) | (y >> (24 - (k - a)));
                        assert!(
                            !std::mem::replace(&mut seen[cell as usize], true),
                            "k {k}, a {a}, pixel {pixel}: two points in one interval"
                        );
                    }
                }
            }
        }
    }

    /// Samples 2^k..2^(k+1) form a net too (progressive rendering and shards add whole
    /// blocks), and different pixels get different points.
    #[test]
    fn sobol_later_blocks_and_pixels_differ() {
        let k = 5;
        let n = 1u32 << k;
        let stream_seed = sobol_stream_seed(3, 0, 0);
        let mut seen = vec![false; n as usize];
        for s in n..2 * n {
            let x = sobol_bits(stream_seed, 0, 0, s) >> (32 - k);
            assert!(!std::mem::replace(&mut seen[x as usize], true));
        }
        let other = sobol_stream_seed(4, 0, 0);
        assert_ne!(sobol_bits(stream_seed, 0, 0, 0), sobol_bits(other, 0, 0, 0));
    }

    /// The transform equals the matrix product it replaces (direction numbers
    /// v_{k+1} = v_k ^ (v_k >> 1)).
    #[test]
    fn sobol_dimension1_is_the_pascal_matrix() {
        let by_matrix = |index: u32| {
            let (mut result, mut v) = (0u32, 1u32 << 31);
            for k in 0..32 {
                if index >> k & 1 != 0 {
                    result ^= v;
                }
                v ^= v >> 1;
            }
            result
        };
        let mut x = 1u32;
        for i in 0..100_000u32 {
            x = pcg_hash(x ^ i);
            assert_eq!(sobol_dimension1(i), by_matrix(i), "{i}");
            assert_eq!(sobol_dimension1(x), by_matrix(x), "{x:#x}");
        }
    }

    #[test]
    fn sobol_dimension1_first_points() {
        let first: Vec<u32> = (0..4).map(|i| sobol_dimension1(i) >> 30).collect();
        // 0, 1/2, 3/4, 1/4 in units of 1/4.
        assert_eq!(first, vec![0, 2, 3, 1]);
    }
}
