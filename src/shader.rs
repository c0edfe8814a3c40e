//! The WGSL kernel, assembled from one file per concept in `shaders/` (WGSL has no includes).

/// The kernel's parts in dependency order, with their file names, for error messages and tests.
pub const SHADER_PARTS: [(&str, &str); 7] = [
    ("types.wgsl", include_str!("../shaders/types.wgsl")),
    ("rng.wgsl", include_str!("../shaders/rng.wgsl")),
    ("camera.wgsl", include_str!("../shaders/camera.wgsl")),
    ("intersect.wgsl", include_str!("../shaders/intersect.wgsl")),
    ("material.wgsl", include_str!("../shaders/material.wgsl")),
    ("lights.wgsl", include_str!("../shaders/lights.wgsl")),
    ("trace.wgsl", include_str!("../shaders/trace.wgsl")),
];

/// Name of the compute entry point in `shaders/trace.wgsl`.
pub const RENDER_ENTRY_POINT: &str = "render";

/// Workgroup size of the render kernel, as declared in `shaders/trace.wgsl`.
pub const WORKGROUP_SIZE: (u32, u32) = (8, 8);

/// The whole kernel as one WGSL module.
pub fn render_kernel_source() -> String {
    SHADER_PARTS
        .iter()
        .map(|(name, text)| format!("// ---- {name}\n{text}\n"))
        .collect()
}
