//! lavapipe's loop limit. llvmpipe's shader compiler (gallivm) gives every shader invocation
//! one loop counter shared by all its loops, and silently ends every loop once they have made
//! 65535 iterations in all (`LP_MAX_TGSI_LOOP_ITERATIONS`, "shared between every loop in a
//! shader"), to keep a runaway loop from hanging the machine. The render kernel loops over every
//! sphere and quad for each ray, and over the samples of its batch, so a batch of a large scene
//! used to stop mid-path: wrong, dark or black images with no error (issue 15, item 16).
//!
//! The renderer therefore splits a batch into dispatches of at most
//! [`max_samples_per_dispatch`] samples, from a worst-case count of the loop iterations of one
//! sample; and the kernel reports any invocation whose path loop still ended early (when a
//! single sample needs more than the limit), which the renderer turns into an error.

use crate::kernel::types::Params;
use crate::kernel::KernelScene;

/// Loop iterations after which llvmpipe ends an invocation's loops.
pub const LAVAPIPE_LOOP_LIMIT: u64 = 65535;

/// The loop limit of the device, if it has one: lavapipe (a CPU device, llvmpipe).
pub fn device_loop_limit(info: &wgpu::AdapterInfo) -> Option<u64> {
    let llvmpipe =
        info.device_type == wgpu::DeviceType::Cpu || info.name.to_lowercase().contains("llvmpipe");
    llvmpipe.then_some(LAVAPIPE_LOOP_LIMIT)
}

/// The most loop iterations one ray's intersection test can take. The linear scan loops over
/// every sphere, quad and triangle. The BVH traversal (`shaders/traverse/bvh.wgsl`) makes one outer
/// iteration per node it visits (each node at most once), one leaf-loop iteration per
/// primitive reference it tests (each at most once), and one pop-loop iteration per stack entry
/// (at most one push per inner node): a true worst case, far above a typical ray's few dozen.
pub fn loop_iterations_per_ray(scene: &KernelScene) -> u64 {
    let params = &scene.params;
    if scene.bvh_nodes.is_empty() {
        return params.sphere_count as u64
            + params.quad_count as u64
            + params.triangle_count as u64;
    }
    let inner_nodes = scene.bvh_nodes.iter().filter(|n| n.count == 0).count() as u64;
    let one_walk = scene.bvh_nodes.len() as u64 + scene.bvh_primitives.len() as u64 + inner_nodes;
    // Each instance's leaf walks its mesh's tree (shaders/traverse/blas.wgsl), which the one
    // walk above bounds, once per instance at most.
    let binary = one_walk * (1 + scene.instances.len() as u64);
    // The wide traversal (shaders/traverse/wide.wgsl), where the scene has the wide tree: one
    // iteration per stack entry (the root and each child, each pushed at most once), four
    // per inner node to push its children, one per primitive reference tested.
    let children = scene
        .bvh_wide_nodes
        .iter()
        .flat_map(|n| n.count)
        .filter(|&c| c != crate::kernel::types::WIDE_EMPTY_CHILD)
        .count() as u64;
    let wide =
        1 + children + 4 * scene.bvh_wide_nodes.len() as u64 + scene.bvh_primitives.len() as u64;
    binary.max(wide)
}

/// The most loop iterations one sample can take: for the camera ray and each scattering event,
/// a ray and a shadow ray each make at most [`loop_iterations_per_ray`], a ray that escapes
/// looks for sun disks among the lights, and the path loop makes one more (light sampling
/// picks its emitter from the alias table, without a loop).
pub fn loop_iterations_per_sample(scene: &KernelScene) -> u64 {
    let per_ray = loop_iterations_per_ray(scene);
    sample_iterations(&scene.params, path_segments(scene), per_ray) + grid_iterations(scene)
}

/// What grid media add to a sample (`src/cpu/media/grid.rs`): each segment's free flight and
/// each shadow segment's ratio tracking take at most `MAX_TRACKING_STEPS` iterations, plus
/// the three of each lookup's clip and walk set-up.
fn grid_iterations(scene: &KernelScene) -> u64 {
    if scene.grids.is_empty() || scene.params.medium_count == 0 {
        return 0;
    }
    let segments = path_segments(scene);
    let crossings = crate::cpu::media::medium::MAX_SHADOW_CROSSINGS as u64;
    let per_track = crate::cpu::media::grid::MAX_TRACKING_STEPS as u64 + 6;
    segments * (1 + crossings) * per_track
}

/// [`loop_iterations_per_sample`] for the hardware traversal (shaders/traverse/hardware.wgsl),
/// whose candidate loop runs once per primitive proposed (each at most once) and whose
/// driver, on lavapipe, walks its own tree in loops of the same shader: per ray, three per
/// primitive, a bound on a tree's nodes and candidates for any tree of at least two children
/// per node.
pub fn hardware_loop_iterations_per_sample(scene: &KernelScene) -> u64 {
    let per_ray = hardware_loop_iterations_per_ray(scene);
    sample_iterations(&scene.params, path_segments(scene), per_ray) + grid_iterations(scene)
}

/// [`loop_iterations_per_ray`] for the hardware traversal (see
/// [`hardware_loop_iterations_per_sample`]).
pub fn hardware_loop_iterations_per_ray(scene: &KernelScene) -> u64 {
    let params = &scene.params;
    let primitives =
        params.sphere_count as u64 + params.quad_count as u64 + params.triangle_count as u64;
    3 * primitives + 1
}

/// The most loop iterations one bidirectional sample (shaders/integrator/bdpt/) can take, at
/// `per_ray` per ray. With B = `max_bounces`: the camera subpath traces at most B + 1 rays and
/// the light subpath B, and a ray that escapes looks for sun disks among the lights (twice:
/// radiance and density). The joins: for each of the camera subpath's at most B + 2 vertices,
/// a loop over the light vertices that make at most B scatterings with it, at most
/// (B + 2)(B + 3) / 2 joins in all; each traces at most one shadow ray, looks among the lights
/// for sun disks at most four times (densities at infinity), and weighs itself in two loops of
/// at most B + 2 iterations together. Then the splat and the sample loops and the end's probe.
///
/// In media a walk also crosses interfaces, segments without a vertex: each subpath traces at
/// most its segment limit (`media::medium::segment_limit`), each segment and join may look a medium up
/// (`MEDIA_LOOPS`), and a join casts one ray per interface it crosses, up to
/// `MAX_SHADOW_CROSSINGS`; the light subpath's start looks for the media around its emitter
/// (`media_around`: up to `MAX_SURROUNDING_SURFACES` rays, each crossing a boundary).
pub fn bdpt_loop_iterations_per_sample(params: &Params, per_ray: u64) -> u64 {
    use crate::cpu::media::medium::segment_limit;
    let b = params.max_bounces as u64;
    let lights = params.light_count as u64;
    let joins = (b + 2) * (b + 3) / 2;
    let weights = 4 * lights + (b + 2) + 1;
    let (walks, per_join) = if params.medium_count > 0 {
        let segments = segment_limit(b as u32 + 2) as u64 + segment_limit(b as u32 + 1) as u64;
        let crossings = crate::cpu::media::medium::MAX_SHADOW_CROSSINGS as u64;
        let surroundings = crate::cpu::media::medium::MAX_SURROUNDING_SURFACES as u64
            * (per_ray + MEDIA_LOOPS + 4);
        (
            surroundings + segments * (per_ray + 2 * lights + 1 + MEDIA_LOOPS),
            crossings * (per_ray + MEDIA_LOOPS) + MEDIA_LOOPS + weights,
        )
    } else {
        ((2 * b + 1) * (per_ray + 2 * lights + 1), per_ray + weights)
    };
    walks + (b + 2) + joins * per_join + 1 + 2
}

/// The most segments a path traces: one per scattering event and the camera's; where the scene
/// has media and interfaces, also the interfaces it crosses, which `max_bounces` does not
/// count, up to the path tracer's `segment_limit` (src/cpu/media/medium.rs). (Counting them in
/// a fog without interfaces made lavapipe's dispatches 5× smaller: `cornell-fog.toml` took 4%
/// more CPU time.)
fn path_segments(scene: &KernelScene) -> u64 {
    let params = &scene.params;
    let crosses = params.medium_count > 0
        && scene
            .materials
            .iter()
            .any(crate::cpu::media::medium::is_interface);
    if crosses {
        return crate::cpu::media::medium::segment_limit(params.max_bounces + 2) as u64;
    }
    params.max_bounces as u64 + 1
}

/// The loop iterations of crossing a medium boundary (shaders/media/medium.wgsl): the lookup
/// of its slot among the 8, and the stack's shift (4 × 4 at most).
const MEDIA_LOOPS: u64 = 8 + 4 * 4;

/// A sample's loop iterations, for paths of at most `segments` segments ([`path_segments`]).
fn sample_iterations(params: &Params, segments: u64, per_ray: u64) -> u64 {
    if params.medium_count > 0 {
        // Media (shaders/media/medium.wgsl): a shadow ray casts one ray per interface it
        // crosses, and each crossing looks its medium up among the slots and the stack.
        let crossings = crate::cpu::media::medium::MAX_SHADOW_CROSSINGS as u64;
        return segments
            * ((1 + crossings) * (per_ray + MEDIA_LOOPS) + params.light_count as u64 + 1);
    }
    segments * (2 * per_ray + params.light_count as u64 + 1)
}

/// Samples per pixel one dispatch may take on a device with this loop limit, from
/// [`loop_iterations_per_sample`] (at least 1: when one sample can exceed the limit, the
/// kernel reports the invocations it cut short).
pub fn max_samples_per_dispatch(iterations_per_sample: u64, limit: Option<u64>) -> u32 {
    match limit {
        None => u32::MAX,
        Some(limit) => (limit / iterations_per_sample.max(1)).clamp(1, u32::MAX as u64) as u32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_scenes_get_one_sample_per_dispatch() {
        let params = |spheres: u32, quads: u32, bounces| {
            let params = Params {
                emitter_count: 1,
                max_bounces: bounces,
                ..Default::default()
            };
            sample_iterations(&params, bounces as u64 + 1, spheres as u64 + quads as u64)
        };
        // The Cornell box: 9 segments of 2 × 10 primitives + 1.
        assert_eq!(
            max_samples_per_dispatch(params(2, 8, 8), Some(65535)),
            65535 / 189
        );
        assert_eq!(max_samples_per_dispatch(params(5000, 7, 4), Some(65535)), 1);
        assert_eq!(
            max_samples_per_dispatch(params(100_000, 7, 4), Some(65535)),
            1
        );
        assert_eq!(max_samples_per_dispatch(params(5000, 7, 4), None), u32::MAX);
    }
}
