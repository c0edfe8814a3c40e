// Bidirectional path tracing (Veach 1997; mirror: src/cpu/integrator/bdpt/mod.rs), and its
// kernel entry point, render_bdpt (mirror: render_pixel's bidirectional branch in
// src/cpu/integrator/pixel.rs). Each pixel sample traces a camera subpath and a light subpath
// and joins every prefix of one to every prefix of the other (connect.wgsl), each join weighted
// by the power heuristic over every strategy that could have made its path. Joins that reach
// the camera from a light vertex (light tracing) land in other pixels: they go to the splat
// film (../splat.wgsl), which the host adds to the image divided by the samples per pixel.
//
// Shared with the path tracer: the camera, the BSDFs, the lights and their pdfs, the traversal,
// the accumulation; what is bidirectional's own is the vertices (vertex.wgsl), the two walks
// (walk.wgsl), the joins and their weights. Compiled in only where KernelFeatures::bdpt says
// (src/kernel/variant.rs): path tracing kernels neither hold nor run any of it.

// One bidirectional sample of pixel sample id: the radiance of its camera-side strategies, its
// light tracing splatted into the film. *aov records the camera subpath's first surface.
fn bdpt_sample(id: SampleId, aov: ptr<function, PathAov>) -> vec3<f32> {
    let counts = subpaths(id, aov);
    let camera_count = counts.x;
    let light_count = counts.y;
    var radiance = vec3<f32>(0.0);
    for (var t = 1u; t <= camera_count; t++) {
        // The CPU loops over every s up to light_count and skips the strategies of more than
        // max_bounces scatterings (s + t - 2 of them); here the loop stops at the last one
        // taken, so that lavapipe's loop counter does not count the skipped ones.
        let s_end = min(light_count, params.max_bounces + 2u - t);
        for (var s = 0u; s <= s_end; s++) {
            if t == 1u && s <= 1u {
                // (0, 1): the camera alone; (1, 1): not a strategy here.
                continue;
            }
            let scatterings = s + t - 2u;
            let c = connect(s, t, id, true);
            let contribution = firefly_clamp(c.radiance, scatterings);
            if t == 1u {
                if c.has_view {
                    splat_add(c.view.pixel_y * params.width + c.view.pixel_x, contribution);
                }
            } else {
                radiance += contribution;
            }
        }
    }
    return radiance;
}

// The kernel's entry point for bidirectional path tracing: one invocation per pixel adds
// params.sample_count samples, starting at global sample index params.sample_start, as
// path.wgsl's render does for path tracing. No path regeneration: a sample's length varies
// less (two subpaths and their joins), and its joins run in loops of their own.
@compute @workgroup_size(8, 8, 1)
fn render_bdpt(@builtin(global_invocation_id) gid: vec3<u32>) {
    let pixel = invocation_pixel(gid);
    if pixel == NO_PIXEL {
        return;
    }
    let px = pixel % params.width;
    let py = pixel / params.width;
    var acc = accumulator_start(params.accumulated_samples, accum_mean[pixel].xyz, accum_m2[pixel].xyz);
    var aov_mean = aov_mean_start();
    var done = 0u;
    loop {
        if done >= params.sample_count {
            break;
        }
        let sample = params.sample_start + done;
        var aov = aov_start();
        let radiance = bdpt_sample(SampleId(pixel, px, py, sample), &aov);
        add_sample(&acc, radiance, sample);
        if aovs_on() {
            aov_mean_add(&aov_mean, aov, done);
        }
        done += 1u;
    }
    // lavapipe ends every loop of an invocation once all its loops together have made 65535
    // iterations (src/gpu/loop_budget.rs): the sample loop then stops short, or, where the
    // limit struck in the last sample, this loop of two iterations makes one. Write nothing
    // and let the host report it. (Its end is opaque_count's, so that no compiler unrolls it.)
    var probe = 0u;
    loop {
        probe += 1u;
        if probe >= opaque_count(2u) {
            break;
        }
    }
    if done < params.sample_count || probe < 2u {
        atomicAdd(&accumulate_counters[1], 1u);
        return;
    }
    finish_pixel(pixel, &acc, aov_mean);
}
