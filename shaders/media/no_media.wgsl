// Participating media compiled out: in every kernel variant without media (HAS_MEDIA false)
// this part stands in for media/phase.wgsl, media/medium.wgsl and integrator/path_media.wgsl
// (src/kernel/source.rs), with what path.wgsl names. path.wgsl calls these only behind
// HAS_MEDIA, but a branch on a constant false still reaches the driver, which translates and
// inlines everything it calls before removing it: with the real parts (a shadow ray's walk
// through interfaces and a medium vertex's light sample, two more traversals), lavapipe spent
// about 0.2 s of CPU time and 45 MiB more on every kernel it built, for nothing in the
// compiled code (docs/src/performance/history/2026-12-04-media-free-cost.md).

// No medium to track: the path state keeps its field, empty.
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

struct FreeFlight {
    t: f32,
    weight: vec3<f32>,
    scattered: bool,
}

fn free_flight(path: ptr<function, PathState>, t_hit: f32, pixel: u32, sample: u32) -> FreeFlight {
    return FreeFlight(t_hit, vec3<f32>(1.0), false);
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
