//! The viewer's display pass: naga validates shaders/viewer/display.wgsl (with tonemap.wgsl), the Rust
//! uniform matches the WGSL struct, and on the GPU the pass shows mean × 2^exposure through each
//! tone curve, sRGB-encoded, the bytes a PNG of the same mean holds (±1), for sRGB and plain
//! surface formats (src/image/tonemap.rs is the CPU side); with a splat film bound, the mean plus
//! the fixed-point sums times the splat weight.

use crate::common;
use glint::image::output::srgb_byte;
use glint::image::tonemap::{DisplayTransform, Tonemap};
use glint::viewer::display::{
    DisplayPass, DisplayUniform, DISPLAY_SHADER, FRAGMENT_ENTRY_POINT, VERTEX_ENTRY_POINT,
};
use naga::proc::Layouter;
use std::mem::{offset_of, size_of};
use wgpu::util::DeviceExt;

fn parse_and_validate() -> naga::Module {
    let module = naga::front::wgsl::parse_str(DISPLAY_SHADER)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(DISPLAY_SHADER)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(DISPLAY_SHADER)));
    module
}

#[test]
fn display_shader_validates_and_has_its_entry_points() {
    let module = parse_and_validate();
    let stage = |name: &str| {
        module
            .entry_points
            .iter()
            .find(|e| e.name == name)
            .unwrap_or_else(|| panic!("no entry point {name}"))
            .stage
    };
    assert_eq!(stage(VERTEX_ENTRY_POINT), naga::ShaderStage::Vertex);
    assert_eq!(stage(FRAGMENT_ENTRY_POINT), naga::ShaderStage::Fragment);
}

#[test]
fn display_uniform_matches_wgsl_layout() {
    let module = parse_and_validate();
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("Display"))
        .expect("WGSL struct Display");
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("Display is not a struct");
    };
    let wgsl: Vec<(String, u32)> = members
        .iter()
        .map(|m| (m.name.clone().unwrap(), m.offset))
        .collect();
    let rust: Vec<(String, u32)> = vec![
        (
            "image_size".into(),
            offset_of!(DisplayUniform, image_size) as u32,
        ),
        (
            "target_size".into(),
            offset_of!(DisplayUniform, target_size) as u32,
        ),
        ("scale".into(), offset_of!(DisplayUniform, scale) as u32),
        (
            "encode_srgb".into(),
            offset_of!(DisplayUniform, encode_srgb) as u32,
        ),
        ("tonemap".into(), offset_of!(DisplayUniform, tonemap) as u32),
        (
            "splat_weight".into(),
            offset_of!(DisplayUniform, splat_weight) as u32,
        ),
    ];
    assert_eq!(rust, wgsl);
    assert_eq!(size_of::<DisplayUniform>() as u32, layouter[handle].size);
}

/// Draws a 4×2 mean image into a `format` texture of the same size and reads it back (RGBA).
fn draw(
    format: wgpu::TextureFormat,
    mean: &[[f32; 4]],
    transform: &DisplayTransform,
) -> Vec<[u8; 4]> {
    draw_with_splats(format, mean, None, transform)
}

/// [`draw`], with a splat film (per pixel and channel a u64 as two u32 words) and its weight.
fn draw_with_splats(
    format: wgpu::TextureFormat,
    mean: &[[f32; 4]],
    splats: Option<(&[u64], f32)>,
    transform: &DisplayTransform,
) -> Vec<[u8; 4]> {
    let ctx = common::gpu().unwrap();
    let splat_buffer = splats.map(|(sums, _)| {
        ctx.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::cast_slice(sums),
                usage: wgpu::BufferUsages::STORAGE,
            })
    });
    let splat_weight = splats.map_or(0.0, |(_, weight)| weight);
    let (w, h) = (4u32, 2u32);
    let mean_buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(mean),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    // Rows of a texture copy are 256-byte aligned.
    let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 256 * h as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut pass = DisplayPass::new(&ctx.device, format);
    pass.bind(&ctx.device, &mean_buffer, splat_buffer.as_ref());
    let view = texture.create_view(&Default::default());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    pass.draw(
        &ctx.queue,
        &mut encoder,
        &view,
        (w, h),
        (w, h),
        transform,
        splat_weight,
    );
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(256),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    ctx.wait_idle().unwrap();
    let bytes = readback.slice(..).get_mapped_range().unwrap().to_vec();
    (0..h as usize)
        .flat_map(|y| {
            let bytes = &bytes;
            (0..w as usize).map(move |x| {
                let i = y * 256 + x * 4;
                [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]
            })
        })
        .collect()
}

#[test]
fn display_pass_shows_what_a_png_holds() {
    if common::gpu().is_none() {
        return;
    }
    // Row 0 at the top; values below, inside and above [0, 1] after exposure, and a NaN.
    let mean = [
        [0.0, 0.001, 0.002, 0.0],
        [0.05, 0.1, 0.2, 0.0],
        [0.3, 0.45, 0.6, 0.0],
        [2.0, -1.0, f32::NAN, 0.0],
        [0.0125, 0.025, 0.0375, 0.0],
        [0.125, 0.25, 0.375, 0.0],
        [0.5, 0.75, 1.0, 0.0],
        [100.0, 0.01, 0.49, 0.0],
    ];
    for (tonemap, exposure) in [
        (Tonemap::Clamp, 0.0f32),
        (Tonemap::Clamp, 1.0),
        (Tonemap::Clamp, -1.5),
        (Tonemap::Aces, 0.0),
        (Tonemap::Aces, 2.0),
        (Tonemap::Agx, 0.0),
        (Tonemap::Agx, -1.0),
    ] {
        let transform = DisplayTransform { tonemap, exposure };
        let expected: Vec<[u8; 3]> = mean
            .iter()
            .map(|p| transform.apply([p[0], p[1], p[2]]).map(srgb_byte))
            .collect();
        if tonemap == Tonemap::Clamp {
            // The clamp curve is mean × 2^exposure, clamped: what PNGs always held.
            let plain: Vec<[u8; 3]> = mean
                .iter()
                .map(|p| [p[0], p[1], p[2]].map(|v| srgb_byte(v * exposure.exp2())))
                .collect();
            assert_eq!(expected, plain);
        }
        for format in [
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureFormat::Rgba8UnormSrgb,
        ] {
            let got = draw(format, &mean, &transform);
            for (i, (g, e)) in got.iter().zip(&expected).enumerate() {
                for c in 0..3 {
                    // The GPU's pow and the sRGB store may round a step differently.
                    assert!(
                        (g[c] as i32 - e[c] as i32).abs() <= 1,
                        "{format:?}, {tonemap:?}, exposure {exposure}, pixel {i}: got {g:?}, a PNG holds {e:?}"
                    );
                }
                assert_eq!(g[3], 255);
            }
        }
    }
}

#[test]
fn display_pass_adds_the_splat_film() {
    if common::gpu().is_none() {
        return;
    }
    // Sums above 2^32 exercise the high word; a weight of 2^-33 keeps them in [0, 1].
    let mean: Vec<[f32; 4]> = (0..8).map(|i| [0.05 * i as f32, 0.1, 0.0, 0.0]).collect();
    let sums: Vec<u64> = (0..24u64).map(|k| k * (1u64 << 29) + 12345).collect();
    let weight = 2f32.powi(-33);
    let transform = DisplayTransform {
        tonemap: Tonemap::Clamp,
        exposure: 0.0,
    };
    let expected: Vec<[u8; 3]> = mean
        .iter()
        .enumerate()
        .map(|(pixel, m)| {
            std::array::from_fn(|c| {
                let splat = sums[3 * pixel + c] as f64 * weight as f64;
                srgb_byte((m[c] as f64 + splat) as f32)
            })
        })
        .collect();
    let got = draw_with_splats(
        wgpu::TextureFormat::Rgba8Unorm,
        &mean,
        Some((&sums, weight)),
        &transform,
    );
    for (i, (g, e)) in got.iter().zip(&expected).enumerate() {
        for c in 0..3 {
            assert!(
                (g[c] as i32 - e[c] as i32).abs() <= 1,
                "pixel {i}: got {g:?}, mean plus splats is {e:?}"
            );
        }
    }
    // A zero weight leaves the mean alone.
    let plain = draw_with_splats(
        wgpu::TextureFormat::Rgba8Unorm,
        &mean,
        Some((&sums, 0.0)),
        &transform,
    );
    assert_eq!(
        plain,
        draw(wgpu::TextureFormat::Rgba8Unorm, &mean, &transform)
    );
}
