//! Which BVH each device traverses, chosen here once: the binary tree (`src/kernel/bvh/mod.rs`) or
//! the 4-wide one collapsed from it (`src/kernel/bvh/wide.rs`). Both find the same closest hit
//! (the closest-hit rule), so the choice is only one of speed, measured per device
//! (BENCHMARKS.md, "A wide BVH"). `GLINT_BVH_LAYOUT=binary|wide` overrides it for both
//! devices, for measuring one against the other.

use std::sync::OnceLock;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhLayout {
    Binary,
    Wide,
}

impl BvhLayout {
    /// The GPU kernel's: wide, 1.14–1.8× the binary tree's paths/s on lavapipe at 10³ to 10⁶
    /// triangles (medians of two series of three interleaved rounds, on a loaded machine).
    pub fn for_gpu() -> BvhLayout {
        overridden().unwrap_or(BvhLayout::Wide)
    }

    /// The CPU reference's: wide, walked with SSE2 box and triangle tests
    /// (src/cpu/traverse/wide.rs): 0.71× the binary walk's instructions per path on the bunny
    /// and 0.74× its CPU time, 0.63× the instructions on 10⁶ triangles
    /// (docs/src/performance/history/2026-12-04.md).
    pub fn for_cpu() -> BvhLayout {
        overridden().unwrap_or(BvhLayout::Wide)
    }

    pub fn name(&self) -> &'static str {
        match self {
            BvhLayout::Binary => "binary",
            BvhLayout::Wide => "wide",
        }
    }
}

/// `GLINT_BVH_LAYOUT`, read once; anything but `binary` or `wide` is ignored with a warning.
fn overridden() -> Option<BvhLayout> {
    static LAYOUT: OnceLock<Option<BvhLayout>> = OnceLock::new();
    *LAYOUT.get_or_init(|| match std::env::var("GLINT_BVH_LAYOUT").ok()?.as_str() {
        "binary" => Some(BvhLayout::Binary),
        "wide" => Some(BvhLayout::Wide),
        other => {
            crate::errln!("glint: GLINT_BVH_LAYOUT={other} is neither binary nor wide; ignored");
            None
        }
    })
}
