//! The merge schedule of the per-pixel statistics: where a block of samples ends, so where a
//! batch may end. The kernel merges blocks on it (`shaders/integrator/accumulate.wgsl`, mirror
//! `src/cpu/integrator/accumulate.rs`) and the render driver splits batches on it
//! (`src/render/mod.rs`), which is why both read it from here: any batching then gives the
//! same bytes.

/// Block size of the merge schedule once a pixel has this many samples.
pub const MERGE_BLOCK: u32 = 64;

/// Whether a block of the merge schedule ends once a pixel has `samples` samples (≥ 1).
pub fn is_block_end(samples: u32) -> bool {
    if samples >= MERGE_BLOCK {
        return samples.is_multiple_of(MERGE_BLOCK);
    }
    samples & (samples - 1) == 0
}

/// The first block end after `samples` that is at least `samples + wanted` (at most
/// [`MERGE_BLOCK`] − 1 more), or `limit` if that comes first: where a batch may end.
pub fn next_block_end(samples: u32, wanted: u32, limit: u32) -> u32 {
    let mut end = samples.saturating_add(wanted.max(1)).min(limit);
    while end < limit && !is_block_end(end) {
        end += 1;
    }
    end
}
