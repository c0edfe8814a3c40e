// The pixel rectangle's origin of one dispatch: the host splits each batch into tiles so that
// no single GPU submission runs long, whatever the scene (src/gpu/tiles.rs). No CPU mirror:
// the CPU reference renders every pixel of a batch at once.
@group(0) @binding(17) var<uniform> tile_origin: vec4<u32>;
