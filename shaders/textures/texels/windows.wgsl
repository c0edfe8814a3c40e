// The texel fetch when the images' texels exceed one storage binding (src/kernel/texels.rs):
// they are split into up to four windows of TEXELS_PER_WINDOW texels (a power of two), window 0
// at `texels` (binding 21, shaders/textures/texture.wgsl) and the others here; unused windows hold one
// placeholder texel. Texel i is texel i % TEXELS_PER_WINDOW of window i / TEXELS_PER_WINDOW.
// Only such scenes compile this in, so the others' kernels keep one plain load.

@group(0) @binding(29) var<storage, read> texels_1: array<vec4<f32>>;
@group(0) @binding(30) var<storage, read> texels_2: array<vec4<f32>>;
@group(0) @binding(31) var<storage, read> texels_3: array<vec4<f32>>;

fn texel_at(i: u32) -> vec4<f32> {
    let window = i / TEXELS_PER_WINDOW;
    let j = i % TEXELS_PER_WINDOW;
    switch window {
        case 0u: {
            return texels[j];
        }
        case 1u: {
            return texels_1[j];
        }
        case 2u: {
            return texels_2[j];
        }
        default: {
            return texels_3[j];
        }
    }
}
