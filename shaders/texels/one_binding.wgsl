// The texel fetch when all images' texels fit one storage binding (`texels`, binding 21 in
// shaders/texture.wgsl): every scene within the device's max_storage_buffer_binding_size.
// shaders/texels/windows.wgsl replaces it for larger ones (src/texel_windows.rs).

fn texel_at(i: u32) -> vec4<f32> {
    return texels[i];
}
