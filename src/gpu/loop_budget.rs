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

use crate::shader_types::Params;

/// Loop iterations after which llvmpipe ends an invocation's loops.
pub const LAVAPIPE_LOOP_LIMIT: u64 = 65535;

/// The loop limit of the device, if it has one: lavapipe (a CPU device, llvmpipe).
pub fn device_loop_limit(info: &wgpu::AdapterInfo) -> Option<u64> {
    let llvmpipe =
        info.device_type == wgpu::DeviceType::Cpu || info.name.to_lowercase().contains("llvmpipe");
    llvmpipe.then_some(LAVAPIPE_LOOP_LIMIT)
}

/// The most loop iterations one sample can take: for the camera ray and each scattering event,
/// a ray and a shadow ray loop over every sphere and quad, light sampling loops over the
/// emitters, and the path loop makes one more.
pub fn loop_iterations_per_sample(params: &Params) -> u64 {
    let primitives = params.sphere_count as u64 + params.quad_count as u64;
    let segments = params.max_bounces as u64 + 1;
    segments * (2 * primitives + params.emitter_count as u64 + 1)
}

/// Samples per pixel one dispatch may take on a device with this loop limit (at least 1:
/// when one sample can exceed the limit, the kernel reports the invocations it cut short).
pub fn max_samples_per_dispatch(params: &Params, limit: Option<u64>) -> u32 {
    match limit {
        None => u32::MAX,
        Some(limit) => {
            (limit / loop_iterations_per_sample(params).max(1)).clamp(1, u32::MAX as u64) as u32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_scenes_get_one_sample_per_dispatch() {
        let params = |spheres, quads, bounces| Params {
            sphere_count: spheres,
            quad_count: quads,
            emitter_count: 1,
            max_bounces: bounces,
            ..Default::default()
        };
        // The Cornell box: 9 segments of 2 × 10 primitives + 2.
        assert_eq!(
            max_samples_per_dispatch(&params(2, 8, 8), Some(65535)),
            65535 / 198
        );
        assert_eq!(
            max_samples_per_dispatch(&params(5000, 7, 4), Some(65535)),
            1
        );
        assert_eq!(
            max_samples_per_dispatch(&params(100_000, 7, 4), Some(65535)),
            1
        );
        assert_eq!(
            max_samples_per_dispatch(&params(5000, 7, 4), None),
            u32::MAX
        );
    }
}
