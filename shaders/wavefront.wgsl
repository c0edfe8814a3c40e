// The wavefront layout (host side: src/gpu/wavefront.rs): the megakernel's path loop split
// into stages, each its own dispatch over a queue of the paths that need it, so every SIMD
// group runs one stage's code with all lanes busy. A wave traces `wave.samples_per_pixel`
// samples of every pixel: generate, then per bounce extend (intersect and shade, the
// megakernel's path_step without its shadow ray) and shadow, then accumulate. Each path draws
// the same random numbers and does the same arithmetic as in the megakernel, so the images
// are the same.

// A path between stages (PathState with its pixel and sample).
struct WavePath {
    origin: vec3<f32>,
    pixel: u32,
    dir: vec3<f32>,
    sample: u32,
    throughput: vec3<f32>,
    bsdf_pdf_of_ray: f32,
    radiance: vec3<f32>,
    bounce: u32,
    ray_start: vec3<f32>,
    came_from_delta: u32,
}

// A shadow ray waiting to be traced, for path `path`.
struct WaveShadow {
    origin: vec3<f32>,
    path: u32,
    dir: vec3<f32>,
    light_primitive: u32,
    contribution: vec3<f32>,
    light_index: u32,
}

// Queue lengths. The stages append with atomics; `wave_setup` turns the appended counts into
// the next stages' lengths and dispatch sizes.
struct WaveControl {
    // Entries appended to the path queue (APPENDED_PATHS) and the shadow queue.
    appended: array<atomic<u32>, 2>,
    // Paths in the queue the next extend stage reads.
    live_paths: u32,
    // Shadow rays the next shadow stage reads.
    shadows: u32,
}

struct WaveParams {
    // Global index of this wave's first sample, and samples per pixel in it.
    sample_first: u32,
    samples_per_pixel: u32,
    // Samples of this batch traced before this wave.
    batch_done: u32,
    // 1 on the batch's last wave: merge the batch into the accumulators.
    last_wave: u32,
}

const WAVE_WORKGROUP: u32 = 64u;
const APPENDED_PATHS: u32 = 0u;
const APPENDED_SHADOWS: u32 = 1u;

@group(1) @binding(0) var<storage, read_write> wave_paths: array<WavePath>;
@group(1) @binding(1) var<storage, read> queue_in: array<u32>;
@group(1) @binding(2) var<storage, read_write> queue_out: array<u32>;
@group(1) @binding(3) var<storage, read_write> shadow_queue: array<WaveShadow>;
@group(1) @binding(4) var<storage, read_write> control: WaveControl;
@group(1) @binding(5) var<uniform> wave: WaveParams;
// This batch's running mean and M2 per pixel, until its last wave merges them.
@group(1) @binding(6) var<storage, read_write> batch_mean: array<vec4<f32>>;
@group(1) @binding(7) var<storage, read_write> batch_m2: array<vec4<f32>>;
// Indirect dispatch sizes: [0..3] the extend stage, [4..7] the shadow stage.
@group(2) @binding(0) var<storage, read_write> dispatch_sizes: array<u32, 8>;

fn load_path(i: u32) -> PathState {
    let w = wave_paths[i];
    return PathState(Ray(w.origin, w.dir), w.throughput, w.radiance, w.ray_start, w.bsdf_pdf_of_ray, w.bounce, w.came_from_delta != 0u);
}

fn store_path(i: u32, path: PathState, pixel: u32, sample: u32) {
    wave_paths[i] = WavePath(path.ray.origin, pixel, path.ray.dir, sample, path.throughput, path.bsdf_pdf_of_ray, path.radiance, path.bounce, path.ray_start, u32(path.came_from_delta));
}

fn wave_path_count() -> u32 {
    return params.width * params.height * wave.samples_per_pixel;
}

// Camera rays for every (pixel, sample) of the wave; path i is sample i % spp of pixel i / spp,
// so neighbouring lanes trace similar rays. Writes the queue the first extend stage reads.
@compute @workgroup_size(64, 1, 1)
fn wave_generate(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let count = wave_path_count();
    if i == 0u {
        control.live_paths = count;
    }
    if i >= count {
        return;
    }
    let pixel = i / wave.samples_per_pixel;
    let sample = wave.sample_first + i % wave.samples_per_pixel;
    let path = start_path(pixel, pixel % params.width, pixel / params.width, sample);
    store_path(i, path, pixel, sample);
    queue_out[i] = i;
}

// One segment of every live path: intersect, shade, queue the shadow ray and the path if it
// goes on.
@compute @workgroup_size(64, 1, 1)
fn wave_extend(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= control.live_paths {
        return;
    }
    let i = queue_in[id.x];
    let pixel = wave_paths[i].pixel;
    let sample = wave_paths[i].sample;
    var path = load_path(i);
    let hit = intersect_scene(path.ray);
    var shadow = no_shadow_ray();
    let ended = shade(&path, hit, pixel, sample, &shadow);
    if LIGHT_SAMPLING && shadow.pending {
        let slot = atomicAdd(&control.appended[APPENDED_SHADOWS], 1u);
        shadow_queue[slot] = WaveShadow(shadow.ray.origin, i, shadow.ray.dir, shadow.light_primitive, shadow.contribution, shadow.light_index);
    }
    store_path(i, path, pixel, sample);
    if !ended {
        queue_out[atomicAdd(&control.appended[APPENDED_PATHS], 1u)] = i;
    }
}

// The shadow rays queued by the last extend stage; a path has at most one, so no two lanes
// write the same path.
@compute @workgroup_size(64, 1, 1)
fn wave_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= control.shadows {
        return;
    }
    let s = shadow_queue[id.x];
    if reaches_light(Ray(s.origin, s.dir), s.light_primitive, s.light_index) {
        wave_paths[s.path].radiance += s.contribution;
    }
}

// Between extend and shadow (one invocation): the appended counts become the queue lengths
// and dispatch sizes, the counters restart, and the segments traced are counted.
@compute @workgroup_size(1, 1, 1)
fn wave_setup() {
    let shadows = atomicExchange(&control.appended[APPENDED_SHADOWS], 0u);
    let live = atomicExchange(&control.appended[APPENDED_PATHS], 0u);
    atomicAdd(&segments_traced, control.live_paths + shadows);
    control.shadows = shadows;
    control.live_paths = live;
    dispatch_sizes = array<u32, 8>((live + WAVE_WORKGROUP - 1u) / WAVE_WORKGROUP, 1u, 1u, 0u, (shadows + WAVE_WORKGROUP - 1u) / WAVE_WORKGROUP, 1u, 1u, 0u);
}

// Folds the wave's samples into the batch's Welford sums in sample order, as the megakernel
// does, and on the batch's last wave merges the batch into the accumulators.
@compute @workgroup_size(64, 1, 1)
fn wave_accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = id.x;
    if pixel >= params.width * params.height {
        return;
    }
    var mean = vec3<f32>(0.0);
    var m2 = vec3<f32>(0.0);
    if wave.batch_done > 0u {
        mean = batch_mean[pixel].xyz;
        m2 = batch_m2[pixel].xyz;
    }
    for (var j = 0u; j < wave.samples_per_pixel; j++) {
        let x = wave_paths[pixel * wave.samples_per_pixel + j].radiance;
        let delta = x - mean;
        mean += delta / f32(wave.batch_done + j + 1u);
        m2 += delta * (x - mean);
    }
    if wave.last_wave == 0u {
        batch_mean[pixel] = vec4<f32>(mean, 0.0);
        batch_m2[pixel] = vec4<f32>(m2, 0.0);
        return;
    }
    let n_old = f32(params.sample_start);
    let n_new = f32(params.sample_count);
    let n = n_old + n_new;
    let old_mean = accum_mean[pixel].xyz;
    let delta = mean - old_mean;
    accum_mean[pixel] = vec4<f32>(old_mean + delta * (n_new / n), 0.0);
    accum_m2[pixel] = vec4<f32>(accum_m2[pixel].xyz + m2 + delta * delta * (n_old * n_new / n), 0.0);
}
