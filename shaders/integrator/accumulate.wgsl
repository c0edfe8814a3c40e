// Per-pixel statistics (mirror: src/cpu/integrator/accumulate.rs): each sample is checked, then added to
// a running mean and M2 (the sum of squared deviations from the mean) on a fixed schedule.
//
// Samples are grouped into blocks by their global index: a block ends after sample counts
// 1, 2, 4, ..., MERGE_BLOCK, and then after every multiple of MERGE_BLOCK. Within a block the
// samples are added by Welford's update; at the block's end the block is merged into the
// totals by Chan, Golub and LeVeque's pairwise update, which keeps the mean accurate in f32 at
// millions of samples. Since the host splits batches only at block ends, the floats depend on
// the sample indices alone: any batching gives the same bytes.

// Largest sample value (per channel) taken; its bit pattern, MAX_SAMPLE_BITS, is that of 1e14.
// With at most 2^30 samples, M2 stays below 2^30 * (2e14)^2 < 4.3e37, so it cannot overflow.
const MAX_SAMPLE_BITS: u32 = 0x56b5e621u;
// Block size of the merge schedule once the pixel has MERGE_BLOCK samples.
const MERGE_BLOCK: u32 = 64u;

// [0]: samples dropped because they were NaN, infinite or above 1e14 (added once per
// invocation). [1]: invocations whose loops the driver ended early, which write nothing (see
// render() in path.wgsl): the host reports them as an error.
@group(0) @binding(16) var<storage, read_write> accumulate_counters: array<atomic<u32>, 2>;

struct Accumulator {
    // Totals over the merged blocks.
    count: u32,
    mean: vec3<f32>,
    m2: vec3<f32>,
    // The block in progress.
    block_count: u32,
    block_mean: vec3<f32>,
    block_m2: vec3<f32>,
    // Samples this invocation dropped.
    nonfinite: u32,
}

// Whether adaptive sampling has stopped the pixel: the host marks it by a non-zero w in its M2
// (src/gpu/renderer.rs), which the kernel's own writes leave 0 (finish_pixel in pixel.wgsl).
fn pixel_stopped(pixel: u32) -> bool {
    return accum_m2[pixel].w != 0.0;
}

fn accumulator_start(count: u32, mean: vec3<f32>, m2: vec3<f32>) -> Accumulator {
    return Accumulator(count, mean, m2, 0u, vec3<f32>(0.0), vec3<f32>(0.0), 0u);
}

// Whether a block of the merge schedule ends once a pixel has `samples` samples (>= 1).
fn is_block_end(samples: u32) -> bool {
    if samples >= MERGE_BLOCK {
        return samples % MERGE_BLOCK == 0u;
    }
    return (samples & (samples - 1u)) == 0u;
}

// Whether every channel is finite and at most 1e14 in magnitude. Compared as bit patterns, which
// order like the magnitudes they encode, with infinity and NaN above every finite value: exact
// even where a compiler assumes floats are never NaN.
fn is_accepted_sample(x: vec3<f32>) -> bool {
    let magnitude_bits = bitcast<vec3<u32>>(x) & vec3<u32>(0x7fffffffu);
    return all(magnitude_bits <= vec3<u32>(MAX_SAMPLE_BITS));
}

// Adds the radiance of the sample with global index `sample`; a rejected one counts as black
// (and in `nonfinite`), so nothing non-finite ever reaches the accumulators.
fn add_sample(acc: ptr<function, Accumulator>, radiance: vec3<f32>, sample: u32) {
    var x = radiance;
    if !is_accepted_sample(x) {
        x = vec3<f32>(0.0);
        (*acc).nonfinite += 1u;
    }
    (*acc).block_count += 1u;
    let delta = x - (*acc).block_mean;
    (*acc).block_mean += delta / f32((*acc).block_count);
    (*acc).block_m2 += delta * (x - (*acc).block_mean);
    if is_block_end(sample + 1u) {
        merge_block(acc);
    }
}

// Merges the block in progress into the totals (Chan, Golub and LeVeque's pairwise update).
fn merge_block(acc: ptr<function, Accumulator>) {
    if (*acc).block_count == 0u {
        return;
    }
    let n_old = f32((*acc).count);
    let n_new = f32((*acc).block_count);
    let n = n_old + n_new;
    let delta = (*acc).block_mean - (*acc).mean;
    (*acc).mean = (*acc).mean + delta * (n_new / n);
    (*acc).m2 = (*acc).m2 + (*acc).block_m2 + delta * delta * (n_old * n_new / n);
    (*acc).count += (*acc).block_count;
    (*acc).block_count = 0u;
    (*acc).block_mean = vec3<f32>(0.0);
    (*acc).block_m2 = vec3<f32>(0.0);
}
