// The texel fetch when all images' texels fit one storage binding (`texels`, binding 21 in
// shaders/textures/texture.wgsl): every scene within the device's max_storage_buffer_binding_size.
// shaders/textures/texels/windows.wgsl replaces it for larger ones (src/kernel/texels.rs).

fn texel_at(i: u32) -> vec4<f32> {
    return texels[i];
}
