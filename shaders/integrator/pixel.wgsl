// What every integrator's entry point does around its samples (mirror:
// src/cpu/integrator/pixel.rs): which pixel an invocation renders, and the merge and writes of
// its statistics once its samples are done. The entry points themselves are path.wgsl's
// render and bdpt/mod.wgsl's render_bdpt.

// invocation_pixel's answer for an invocation with nothing to do.
const NO_PIXEL: u32 = 0xffffffffu;

// The pixel index of the invocation at `id` in this dispatch's tile, or NO_PIXEL when it lies
// outside the image, the batch has no samples, or adaptive sampling has stopped the pixel
// (accumulate.wgsl's pixel_stopped).
fn invocation_pixel(id: vec3<u32>) -> u32 {
    let px = id.x + tile_origin.x;
    let py = id.y + tile_origin.y;
    if px >= params.width || py >= params.height || params.sample_count == 0u {
        return NO_PIXEL;
    }
    let pixel = py * params.width + px;
    if pixel_stopped(pixel) {
        return NO_PIXEL;
    }
    return pixel;
}

// Writes the pixel's statistics after its params.sample_count samples: the block in progress
// merged (a batch the host ends inside a block keeps the statistics right), the AOV means,
// and the invocation's counts of segments and dropped samples.
fn finish_pixel(pixel: u32, acc: ptr<function, Accumulator>, aov_mean: AovMean) {
    merge_block(acc);
    accum_mean[pixel] = vec4<f32>((*acc).mean, 0.0);
    accum_m2[pixel] = vec4<f32>((*acc).m2, 0.0);
    if aovs_on() {
        aov_merge(pixel, aov_mean, f32(params.accumulated_samples), f32(params.sample_count));
    }
    atomicAdd(&segments_traced, segments);
    if (*acc).nonfinite > 0u {
        atomicAdd(&accumulate_counters[0], (*acc).nonfinite);
    }
}
