// Display pass of the viewer (host: src/viewer/display.rs): one fullscreen triangle whose
// fragments read an image (the renderer's running mean, plus bidirectional path tracing's splat
// film where it has one, or the denoised image), scale it by
// 2^exposure, apply the tone curve (tonemap.wgsl, prepended by the host) and, when the surface
// format does not encode sRGB itself, the sRGB transfer function. The same steps as a PNG
// written by `glint render` (src/image/tonemap.rs, src/image/output.rs), so P saves what is shown.

struct Display {
    // Size of the rendered image, and of the surface it is shown on; the image is stretched
    // over the surface (nearest pixel) when they differ.
    image_size: vec2<u32>,
    target_size: vec2<u32>,
    // 2^exposure.
    scale: f32,
    // 1 when the shader must sRGB-encode (a *Unorm surface), 0 for an *UnormSrgb one.
    encode_srgb: u32,
    // TONEMAP_CLAMP, TONEMAP_ACES or TONEMAP_AGX.
    tonemap: u32,
    // What one unit of a splat sum adds to the mean: 1 / (splat scale × samples per pixel),
    // as src/render/accumulation.rs's mean_image adds it; 0 when nothing splats.
    splat_weight: f32,
}

@group(0) @binding(0) var<storage, read> display: Display;
// Per pixel vec4: linear radiance (xyz), row-major, row 0 at the top.
@group(0) @binding(1) var<storage, read> mean: array<vec4<f32>>;
// The splat film (shaders/integrator/splat.wgsl): per pixel and channel a 64-bit fixed-point sum
// as two u32 words, low first. Without one, any buffer: splat_weight 0 skips it.
@group(0) @binding(2) var<storage, read> splats: array<u32>;

// Pixel `index`'s splat sums in radiance.
fn splatted(index: u32) -> vec3<f32> {
    var rgb = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        let word = 2u * (3u * index + c);
        rgb[c] = (f32(splats[word + 1u]) * 4294967296.0 + f32(splats[word])) * display.splat_weight;
    }
    return rgb;
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // (-1,-1), (3,-1), (-1,3): one triangle that covers the whole viewport.
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

fn srgb_encode(linear: vec3<f32>) -> vec3<f32> {
    let low = linear * 12.92;
    let high = 1.055 * pow(linear, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, linear <= vec3<f32>(0.0031308));
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // Framebuffer coordinates have their origin at the top left, like the image's rows.
    let scaled = position.xy * vec2<f32>(display.image_size) / vec2<f32>(display.target_size);
    let pixel = min(vec2<u32>(scaled), display.image_size - vec2<u32>(1u));
    let index = pixel.y * display.image_size.x + pixel.x;
    var radiance = mean[index].xyz;
    if display.splat_weight != 0.0 {
        radiance += splatted(index);
    }
    var color = tonemap_apply(radiance, display.scale, display.tonemap);
    if display.encode_srgb != 0u {
        color = srgb_encode(color);
    }
    return vec4<f32>(color, 1.0);
}
