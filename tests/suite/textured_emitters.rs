//! Textured emitters (glTF's emissiveFactor × emissiveTexture × KHR_materials_emissive_strength):
//! light sampling's choice by the texture's mean (black regions are no emitters), a floor's
//! radiance under a half-black emitter against its closed form with light sampling on and off
//! (the two routes of multiple importance sampling agree) and with bidirectional path tracing
//! (light subpaths starting on the texture), on the CPU and the GPU, and the GPU tracing the
//! CPU's paths.

use crate::common;

use base64::Engine as _;
use common::{render_with_variance, renderers, PathAgreement};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::gpu::GpuRenderer;
use glint::kernel::types::PRIMITIVE_TRIANGLE;
use glint::render::Renderer;
use glint::scene::Scene;
use std::f64::consts::PI;

const STRENGTH: f64 = 4.0;

/// A 2 × 2 emitter at y = 1 facing the floor, two quads of two triangles each: the left one
/// (x ∈ [−1, 0]) on u ∈ [0, 0.5], the right one on [0.5, 1], of a 4 × 1 emission texture whose
/// left half is white and right half black, read with nearest filtering and clamped (so u = 1
/// reads the last texel, not the first). Its base colour is black: it only emits.
fn emitter_gltf() -> String {
    let positions: [[f32; 3]; 8] = [
        [-1.0, 1.0, -1.0],
        [0.0, 1.0, -1.0],
        [0.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
        [0.0, 1.0, -1.0],
        [1.0, 1.0, -1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let uvs: [[f32; 2]; 8] = [
        [0.0, 0.0],
        [0.5, 0.0],
        [0.5, 1.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.5, 1.0],
    ];
    let indices: [u16; 12] = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    bin.extend(uvs.iter().flatten().flat_map(|f| f.to_le_bytes()));
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let image = image::RgbImage::from_fn(4, 1, |x, _| {
        image::Rgb(if x < 2 { [255; 3] } else { [0; 3] })
    });
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let b64 = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "TEXCOORD_0": 1},
            "indices": 2,
            "material": 0
        }]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]},
            "emissiveFactor": [1.0, 1.0, 1.0],
            "emissiveTexture": {"index": 0},
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": STRENGTH}}
        }],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"uri": format!("data:image/png;base64,{}", b64(&png))}],
        "buffers": [{
            "uri": format!("data:application/octet-stream;base64,{}", b64(&bin)),
            "byteLength": bin.len()
        }],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96},
            {"buffer": 0, "byteOffset": 96, "byteLength": 64},
            {"buffer": 0, "byteOffset": 160, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
             "min": [-1, 1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5126, "count": 8, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 12, "type": "SCALAR"}
        ]
    })
    .to_string()
}

/// The emitter over a white diffuse floor (y = 0), seen from y = 0.5 straight down through a
/// 1° field of view around the floor's origin, below the emitter's black-white edge. One
/// scattering event: the floor's radiance is what arrives from the emitter directly.
fn scene(size: u32, spp: u32, light_sampling: bool) -> (tempfile::TempDir, Scene) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("emitter.gltf"), emitter_gltf()).unwrap();
    let text = format!(
        r#"[camera]
eye = [0.0, 0.5, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
vfov = 1.0
[render]
width = {size}
height = {size}
spp = {spp}
max_bounces = 1
russian_roulette = false
light_sampling = {light_sampling}
background = [0.0, 0.0, 0.0]
[materials.floor]
type = "diffuse"
color = [1.0, 1.0, 1.0]
[[quads]]
corner = [-20.0, 0.0, -20.0]
u = [40.0, 0.0, 0.0]
v = [0.0, 0.0, 40.0]
material = "floor"
[[meshes]]
file = "emitter.gltf"
"#
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    (dir, scene)
}

/// Form factor from a point to a parallel a × b rectangle at height h, one of whose corners is
/// straight above it (the standard closed form, e.g. Howell's catalogue, case B-3).
fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// Light sampling picks only the triangles over the texture's white half, each with half of
/// the probability (equal areas, equal means), and never the black half's.
#[test]
fn black_texels_are_no_emitters() {
    let (_dir, scene) = scene(4, 1, true);
    let k = scene.kernel_scene();
    let triangles: Vec<_> = k
        .emitters
        .iter()
        .filter(|e| e.primitive == PRIMITIVE_TRIANGLE)
        .collect();
    assert_eq!(triangles.len(), 2, "{:?}", k.emitters);
    for e in triangles {
        let t = &k.triangles[e.index as usize];
        assert!(
            [t.v0, t.v1, t.v2].iter().all(|v| v[0] <= 0.0),
            "triangle {} on the black half is an emitter",
            e.index
        );
        assert!((e.probability - 0.5).abs() < 1e-6, "{e:?}");
    }
}

/// The floor point below the edge sees the white half as two 1 × 1 rectangles at height 1
/// with a corner above it: radiance ρ L · 2 F(1, 1, 1), ρ = 1, L = emissiveStrength, about
/// 1.108 (the 1° field of view sees ±0.0044 around it, where the radiance changes linearly
/// across the edge and the image mean cancels that to second order, far below the noise).
/// With light sampling on and off, on each device, the image mean lies within 5 standard
/// errors of it, the standard error being the square root of the summed per-pixel variances
/// of the means over the pixel count (pixels are independent).
#[test]
fn a_floor_under_a_half_black_emitter_matches_the_closed_form() {
    let expected = STRENGTH * 2.0 * corner_form_factor(1.0, 1.0, 1.0);
    for light_sampling in [true, false] {
        let (_dir, scene) = scene(16, 256, light_sampling);
        let k = scene.kernel_scene();
        for (device, mut renderer) in renderers(&k) {
            let (image, variance) = render_with_variance(renderer.as_mut(), 256);
            let n = image.pixels.len() as f64;
            let mean = image.pixels.iter().map(|p| p[0] as f64).sum::<f64>() / n;
            let sigma = variance
                .pixels
                .iter()
                .map(|v| v[0] as f64)
                .sum::<f64>()
                .sqrt()
                / n;
            eprintln!(
                "{device}, light sampling {light_sampling}: {mean} against {expected} ± {sigma}"
            );
            assert!(
                (mean - expected).abs() < 5.0 * sigma,
                "{device}, light sampling {light_sampling}: {mean} against {expected} ± {sigma}"
            );
        }
    }
}

/// At one sample per pixel the GPU traces the CPU's paths through the textured emitter.
#[test]
fn the_gpu_traces_the_cpus_paths() {
    let Some(ctx) = common::gpu() else {
        eprintln!("no GPU: skipped");
        return;
    };
    let (_dir, scene) = scene(64, 1, true);
    let k = scene.kernel_scene();
    let mut agreement = PathAgreement::default();
    agreement.add(&common::render_cpu(&k, 1), &common::render_gpu(ctx, &k, 1));
    agreement.check(0.99);
}

/// Bidirectional path tracing under the half-black textured emitter: light subpaths start on
/// its white triangles (chosen by the texture's mean, the point by area, the radiance read
/// from the texture there) and the floor's radiance still matches the closed form above, on
/// each device. Its variance comes from batch means, so the standard error here is the spread
/// of 8 independent renders' image means (different seeds) over √8, and the bound 5 of them:
/// with 7 degrees of freedom a |t| above 5 has a chance of about 0.2% (measured: |t| < 2.5).
#[test]
fn bdpt_under_a_half_black_emitter_matches_the_closed_form() {
    let expected = STRENGTH * 2.0 * corner_form_factor(1.0, 1.0, 1.0);
    let (_dir, scene) = scene(12, 32, true);
    let mut k = scene.kernel_scene();
    k.params.integrator = glint::kernel::types::INTEGRATOR_BDPT;
    let make = |device: &str, scene: &glint::kernel::KernelScene| -> Box<dyn Renderer> {
        match device {
            "cpu" => Box::new(CpuRenderer::new(scene)),
            _ => Box::new(GpuRenderer::new(common::gpu().unwrap(), scene).unwrap()),
        }
    };
    let devices = if common::gpu().is_some() {
        vec!["cpu", "gpu"]
    } else {
        vec!["cpu"]
    };
    for device in devices {
        let means: Vec<f64> = (0..8)
            .map(|seed| {
                let mut seeded = k.clone();
                seeded.params.seed = 100 + seed;
                let mut renderer = make(device, &seeded);
                renderer.add_samples(32).unwrap();
                let image = renderer.read_mean().unwrap();
                image.pixels.iter().map(|p| p[0] as f64).sum::<f64>() / image.pixels.len() as f64
            })
            .collect();
        let n = means.len() as f64;
        let mean = means.iter().sum::<f64>() / n;
        let spread = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let t = (mean - expected) / (spread / n.sqrt()).max(1e-12);
        eprintln!("{device}, bdpt: {mean} against {expected}, t = {t:.2}");
        assert!(
            t.abs() < 5.0,
            "{device}, bdpt: {mean} against {expected}, t = {t:.2}"
        );
    }
}
