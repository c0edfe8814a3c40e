//! Which structure the GPU kernel traces rays through, chosen once per render from
//! `--traversal` and the device: the software BVH (or the scan, for small scenes), which the
//! CPU reference mirrors, or the device's ray queries against an acceleration structure
//! (src/gpu/acceleration.rs). Both find the same closest hit by the closest-hit rule.

use super::context::GpuContext;
use anyhow::{anyhow, Result};

/// `--traversal`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TraversalChoice {
    /// Hardware where the device has ray queries and they are faster there: not on lavapipe,
    /// where they measured no faster than glint's own BVH (BENCHMARKS.md).
    #[default]
    Auto,
    /// Ray queries, or an error on a device without them.
    Hardware,
    /// glint's own BVH (or the scan), on every device.
    Software,
}

/// The traversal a renderer runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Traversal {
    Software,
    Hardware,
}

impl Traversal {
    /// As `--json` reports it.
    pub fn name(&self) -> &'static str {
        match self {
            Traversal::Software => "software",
            Traversal::Hardware => "hardware",
        }
    }
}

/// Whether the device is lavapipe (llvmpipe): a CPU running Vulkan, whose ray queries walk a
/// BVH in software no faster than glint's own.
fn is_lavapipe(ctx: &GpuContext) -> bool {
    ctx.adapter_info.device_type == wgpu::DeviceType::Cpu
        || ctx.adapter_info.name.to_lowercase().contains("llvmpipe")
}

impl TraversalChoice {
    /// The traversal to run on `ctx`'s device.
    pub fn resolve(self, ctx: &GpuContext) -> Result<Traversal> {
        match self {
            TraversalChoice::Software => Ok(Traversal::Software),
            TraversalChoice::Hardware if ctx.has_ray_queries() => Ok(Traversal::Hardware),
            TraversalChoice::Hardware => Err(anyhow!(
                "--traversal hardware: {} has no ray queries (Vulkan's VK_KHR_ray_query, wgpu's \
                 EXPERIMENTAL_RAY_QUERY); use --traversal software or auto",
                ctx.device_name()
            )),
            TraversalChoice::Auto if ctx.has_ray_queries() && !is_lavapipe(ctx) => {
                Ok(Traversal::Hardware)
            }
            TraversalChoice::Auto => Ok(Traversal::Software),
        }
    }
}
