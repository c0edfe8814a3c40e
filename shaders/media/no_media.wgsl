// Participating media compiled out: in every kernel variant without media (HAS_MEDIA false)
// this part stands in for media/phase.wgsl, media/medium.wgsl and integrator/path_media.wgsl
// (src/kernel/source.rs), with what path.wgsl and bidirectional's walks and joins
// (integrator/bdpt/) name. They call these only behind HAS_MEDIA, but a branch on a constant
// false still reaches the driver, which translates and inlines everything it calls before
// removing it: with the real parts (a shadow ray's walk through interfaces and a medium
// vertex's light sample, two more traversals), lavapipe spent about 0.2 s of CPU time and
// 45 MiB more on every kernel it built, for nothing in the compiled code
// (docs/src/performance/history/2026-12-04-media-free-cost.md).

// No medium to track: the path state and bidirectional's vertices keep their field, empty.
struct MediumStack {
    depth: u32,
}

fn medium_start() -> MediumStack {
    return MediumStack(0u);
}

fn medium_crossed(stack: MediumStack, material: u32, front_face: bool) -> MediumStack {
    return stack;
}

fn is_interface(m: Material) -> bool {
    return false;
}

fn current_medium(stack: MediumStack) -> u32 {
    return NO_MEDIUM;
}

fn transmittance(sigma_t: vec3<f32>, d: f32) -> vec3<f32> {
    return vec3<f32>(1.0);
}

fn hg_phase(g: f32, cos_theta: f32) -> f32 {
    return 0.0;
}

fn sample_hg(g: f32, dir: vec3<f32>, u1: f32, u2: f32) -> vec3<f32> {
    return dir;
}

struct FreeFlight {
    t: f32,
    weight: vec3<f32>,
    scattered: bool,
}

fn sample_flight(slot: u32, ray: Ray, t_hit: f32, rng: ptr<function, Rng>) -> FreeFlight {
    return FreeFlight(t_hit, vec3<f32>(1.0), false);
}

fn free_flight(path: ptr<function, PathState>, t_hit: f32, pixel: u32, sample: u32) -> FreeFlight {
    return FreeFlight(t_hit, vec3<f32>(1.0), false);
}

struct RayEnd {
    primitive: u32,
    index: u32,
    point: vec3<f32>,
    slack: f32,
}

const RAY_END_POINT: u32 = 0xffffffffu;

// medium.wgsl's bound (bidirectional's walks name it in every kernel).
fn segment_limit(max_vertices: u32) -> u32 {
    return 4u * max_vertices + 8u;
}

fn media_around(p: vec3<f32>) -> MediumStack {
    return MediumStack(0u);
}

fn transmittance_along(shadow: Ray, stack: MediumStack, end: RayEnd, pixel: u32, sample: u32, bounce: u32, count_segments: bool) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn shadow_transmittance(shadow: Ray, light: LightSample, stack: MediumStack, pixel: u32, sample: u32, bounce: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn medium_vertex(path: ptr<function, PathState>, position: vec3<f32>, light_sampling: bool, pixel: u32, sample: u32) -> bool {
    return true;
}

fn cross_interface(path: ptr<function, PathState>, hit: Hit) -> bool {
    return true;
}
