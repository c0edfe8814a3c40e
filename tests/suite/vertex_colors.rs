//! glTF's COLOR_0 (vertex colours) as glint reads it: interpolated across each triangle, it
//! multiplies the base colour and, for `mask` and `blend`, the alpha, on the CPU and on every
//! GPU traversal alike; accessors glTF does not allow are errors naming them. Each test writes
//! a generated glTF square of two triangles that share no vertex: A (lower right), coloured
//! the same at its three corners, and B (upper left), whose corners differ.

use crate::common;

use glam::{Vec3, Vec4};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::gpu::{GpuRenderer, Traversal};
use glint::image::output::Image;
use glint::kernel::KernelScene;
use glint::render::{render_image, Renderer};
use glint::scene::Scene;
use std::path::Path;

/// The square's corners: A is (−1, −1), (1, −1), (1, 1); B is (−1, −1), (1, 1), (−1, 1).
const POSITIONS: [[f32; 3]; 6] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// A's colour at all three corners (each a multiple of 1/255, so every encoding holds it), and
/// B's red, green and blue corners. A's alpha is under the cutoff (0.5); B's fades to 0 at its
/// third corner.
const COLORS: [[f32; 4]; 6] = [
    [0.8, 0.4, 0.2, 0.2],
    [0.8, 0.4, 0.2, 0.2],
    [0.8, 0.4, 0.2, 0.2],
    [1.0, 0.0, 0.0, 1.0],
    [0.0, 1.0, 0.0, 1.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// How the file stores COLOR_0: glTF's component type, whether it is normalized, and VEC3 or
/// VEC4.
#[derive(Clone, Copy)]
struct Encoding {
    component_type: u32,
    normalized: bool,
    rgba: bool,
}

const FLOAT_RGB: Encoding = Encoding {
    component_type: 5126,
    normalized: false,
    rgba: false,
};
const FLOAT_RGBA: Encoding = Encoding {
    component_type: 5126,
    normalized: false,
    rgba: true,
};
const BYTE_RGBA: Encoding = Encoding {
    component_type: 5121,
    normalized: true,
    rgba: true,
};
const SHORT_RGB: Encoding = Encoding {
    component_type: 5123,
    normalized: true,
    rgba: false,
};

/// The square's glTF (positions, then `colors` encoded as `encoding` says, in `square.bin`),
/// with `edit` applied to the COLOR_0 accessor's JSON.
fn write_square(
    dir: &Path,
    colors: &[[f32; 4]],
    encoding: Encoding,
    edit: impl FnOnce(&mut serde_json::Value),
) {
    let mut bin: Vec<u8> = POSITIONS
        .iter()
        .flatten()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let start = bin.len();
    let channels = if encoding.rgba { 4 } else { 3 };
    for c in colors {
        for &v in &c[..channels] {
            match encoding.component_type {
                5126 => bin.extend(v.to_le_bytes()),
                5121 => bin.push((v * 255.0).round() as u8),
                _ => bin.extend(((v * 65535.0).round() as u16).to_le_bytes()),
            }
        }
        // Elements of one- and two-byte components are padded to four bytes, as glTF wants.
        while !(bin.len() - start).is_multiple_of(4) {
            bin.push(0);
        }
    }
    let stride = (bin.len() - start) / colors.len();
    let mut accessor = serde_json::json!({
        "bufferView": 1, "componentType": encoding.component_type, "count": colors.len(),
        "type": if encoding.rgba { "VEC4" } else { "VEC3" }, "normalized": encoding.normalized
    });
    edit(&mut accessor);
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}}]}],
        "buffers": [{"uri": "square.bin", "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": start},
            {"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start,
             "byteStride": stride}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            accessor
        ]
    });
    std::fs::write(dir.join("square.bin"), &bin).unwrap();
    std::fs::write(dir.join("square.gltf"), serde_json::to_vec(&json).unwrap()).unwrap();
}

/// Image size: the square's ±1 spans 25.6 of its pixels.
const SIZE: u32 = 32;

/// The scene file: the square at z = 0 facing a camera at z = 5 that sees 2.5 units across, in
/// front of a background of radiance 1, with `material` (called "square") on it.
fn scene_text(material: &str, max_bounces: u32, spp: u32) -> String {
    let vfov = 2.0 * (1.25f32 / 5.0).atan().to_degrees();
    format!(
        "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         vfov = {vfov}\n\n[render]\nwidth = {SIZE}\nheight = {SIZE}\nspp = {spp}\n\
         max_bounces = {max_bounces}\nbackground = [1.0, 1.0, 1.0]\n\n[materials.square]\n\
         {material}\n\n[[meshes]]\nfile = \"square.gltf\"\nmaterial = \"square\"\n"
    )
}

fn load(dir: &Path, text: &str) -> Result<Scene, String> {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).map_err(|e| e.to_string())
}

/// The kernel scene of the square with `colors` stored as `encoding`.
fn square_scene(encoding: Encoding, material: &str, max_bounces: u32, spp: u32) -> KernelScene {
    let dir = tempfile::tempdir().unwrap();
    write_square(dir.path(), &COLORS, encoding, |_| {});
    load(dir.path(), &scene_text(material, max_bounces, spp))
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene()
}

fn render(renderer: &mut dyn Renderer, spp: u32) -> Image {
    render_image(renderer, spp, spp).unwrap()
}

/// `scene` rendered on the CPU and on every GPU traversal there is.
fn render_everywhere(scene: &KernelScene, spp: u32) -> Vec<(&'static str, Image)> {
    let mut out = vec![("cpu", render(&mut CpuRenderer::new(scene), spp))];
    if let Some(ctx) = common::gpu() {
        let mut software = GpuRenderer::with_traversal(ctx, scene, Traversal::Software).unwrap();
        out.push(("gpu software", render(&mut software, spp)));
    }
    if let Some(ctx) = common::gpu_with_ray_queries() {
        let mut hardware = GpuRenderer::with_traversal(ctx, scene, Traversal::Hardware).unwrap();
        out.push(("gpu hardware", render(&mut hardware, spp)));
    }
    out
}

/// Pixel (column, row from the top).
fn pixel(image: &Image, (x, y): (u32, u32)) -> Vec3 {
    let p = image.pixels[(y * image.width + x) as usize];
    Vec3::new(p[0], p[1], p[2])
}

/// Where pixel (x, y)'s centre lies on the square's plane.
fn on_square((x, y): (u32, u32)) -> (f32, f32) {
    let step = 2.5 / SIZE as f32;
    (
        -1.25 + (x as f32 + 0.5) * step,
        1.25 - (y as f32 + 0.5) * step,
    )
}

/// B's vertex colour at the point (x, y) inside it: its corners weighted by barycentrics.
fn color_in_b((x, y): (f32, f32)) -> Vec4 {
    // (x, y) = v0 + s (v1 − v0) + t (v2 − v0) with v0 = (−1, −1), v1 = (1, 1), v2 = (−1, 1).
    let s = (x + 1.0) / 2.0;
    let t = (y + 1.0) / 2.0 - s;
    let [c0, c1, c2] = [3, 4, 5].map(|i| Vec4::from(COLORS[i]));
    (1.0 - s - t) * c0 + s * c1 + t * c2
}

/// Pixels well inside A, and inside B near its centroid.
const IN_A: (u32, u32) = (22, 22);
const IN_B: (u32, u32) = (11, 11);

/// A white diffuse square under a sky of radiance 1, one bounce: each sample is the albedo
/// times the sky (the bounce ray escapes), so a pixel is its vertex colour. A is its corners'
/// colour wherever it is sampled; B's pixel near its centroid is the colour interpolated at the
/// pixel's centre (within the pixel's spread); on every device, for float, byte and short
/// encodings, VEC3 and VEC4 alike, and the devices agree.
#[test]
fn vertex_colors_multiply_the_albedo_on_every_device() {
    let material = "type = \"diffuse\"\ncolor = [1.0, 1.0, 1.0]";
    let spp = 16;
    let mut reference: Option<Image> = None;
    for encoding in [FLOAT_RGB, FLOAT_RGBA, BYTE_RGBA, SHORT_RGB] {
        let scene = square_scene(encoding, material, 1, spp);
        assert_eq!(scene.triangle_colors.len(), 2);
        for (device, image) in render_everywhere(&scene, spp) {
            let a = pixel(&image, IN_A);
            assert!(
                (a - Vec3::new(0.8, 0.4, 0.2)).abs().max_element() < 1e-4,
                "{device}: A's pixel is {a}"
            );
            let b = pixel(&image, IN_B);
            let want = color_in_b(on_square(IN_B)).truncate();
            assert!(
                (b - want).abs().max_element() < 0.02,
                "{device}: B's pixel is {b}, want about {want}"
            );
            match &reference {
                None => reference = Some(image),
                Some(r) => {
                    let worst = r
                        .pixels
                        .iter()
                        .flatten()
                        .zip(image.pixels.iter().flatten())
                        .map(|(p, q)| (p - q).abs())
                        .fold(0.0, f32::max);
                    assert!(worst < 1e-4, "{device}: differs from the CPU by {worst}");
                }
            }
        }
    }
}

/// MASK with the vertex alpha: camera rays pass through A (alpha 0.2 < 0.5) and through B
/// where its alpha, 1 − (its third corner's weight), falls under the cutoff, and stop
/// elsewhere (no scattering: a pixel is the sky's 1 where the ray passes, 0 where it stops).
/// VEC3 colours have alpha 1: nothing passes.
#[test]
fn a_vec4s_alpha_multiplies_the_alpha_on_every_device() {
    let material = "type = \"pbr\"\nbase_color = [1.0, 1.0, 1.0]\nalpha_mode = \"mask\"";
    let near_third_corner = (5, 5);
    let near_diagonal = (13, 13);
    assert!(color_in_b(on_square(near_third_corner)).w < 0.4);
    assert!(color_in_b(on_square(near_diagonal)).w > 0.6);
    for (encoding, passes) in [
        (FLOAT_RGBA, [true, true, false]),
        (BYTE_RGBA, [true, true, false]),
        (FLOAT_RGB, [false, false, false]),
    ] {
        let scene = square_scene(encoding, material, 0, 4);
        for (device, image) in render_everywhere(&scene, 4) {
            for (p, passes) in [IN_A, near_third_corner, near_diagonal].iter().zip(passes) {
                let want = if passes { 1.0 } else { 0.0 };
                assert_eq!(
                    pixel(&image, *p),
                    Vec3::splat(want),
                    "{device}: pixel {p:?}"
                );
            }
        }
    }
}

/// Without COLOR_0 nothing is uploaded and the kernel compiles vertex colours out.
#[test]
fn meshes_without_vertex_colors_upload_none() {
    let dir = tempfile::tempdir().unwrap();
    write_square(dir.path(), &COLORS, FLOAT_RGB, |_| {});
    let gltf = dir.path().join("square.gltf");
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    json["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .unwrap()
        .remove("COLOR_0");
    std::fs::write(&gltf, serde_json::to_vec(&json).unwrap()).unwrap();
    let scene = load(
        dir.path(),
        &scene_text("type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]", 1, 1),
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .kernel_scene();
    assert!(scene.triangle_colors.is_empty());
    assert!(!glint::kernel::variant::KernelFeatures::of(&scene).vertex_colors);
}

/// COLOR_0 accessors glTF does not allow, and colours outside [0, 1], are errors naming the
/// scene file's field, the glTF file, the attribute, the accessor and what is wrong.
#[test]
fn bad_color_accessors_are_named_errors() {
    let refused = |colors: &[[f32; 4]],
                   encoding: Encoding,
                   edit: &dyn Fn(&mut serde_json::Value),
                   needles: &[&str]| {
        let dir = tempfile::tempdir().unwrap();
        write_square(dir.path(), colors, encoding, edit);
        let message = load(
            dir.path(),
            &scene_text("type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]", 1, 1),
        )
        .expect_err("the file should be refused");
        for needle in [
            "meshes[0].file",
            "square.gltf: ",
            "meshes[0].primitives[0].attributes.COLOR_0",
            "accessors[1]",
        ]
        .iter()
        .chain(needles)
        {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    };
    refused(
        &COLORS,
        FLOAT_RGB,
        &|a| a["type"] = "VEC2".into(),
        &["VEC2", "VEC3 or VEC4"],
    );
    refused(
        &COLORS,
        BYTE_RGBA,
        &|a| a["normalized"] = false.into(),
        &["UNSIGNED_BYTE", "normalized"],
    );
    refused(
        &COLORS,
        FLOAT_RGB,
        &|a| a["componentType"] = 5120.into(),
        &["BYTE"],
    );
    refused(
        &COLORS[..5],
        FLOAT_RGB,
        &|_| {},
        &["5 elements", "POSITION"],
    );
    let mut bright = COLORS;
    bright[2][1] = 1.5;
    refused(
        &bright,
        FLOAT_RGB,
        &|_| {},
        &["element 2", "outside [0, 1]"],
    );
    let mut nan = COLORS;
    nan[4][0] = f32::NAN;
    refused(&nan, FLOAT_RGBA, &|_| {}, &["element 4", "outside [0, 1]"]);
}

/// A PLY file's `red green blue` (and `alpha`) uchar vertex properties become vertex colours:
/// display colours, so sRGB-decoded; alpha linear (1 where absent).
#[test]
fn ply_vertex_colors_are_read_srgb_decoded() {
    let dir = tempfile::tempdir().unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
               property uchar alpha\nelement face 1\nproperty list uchar int vertex_indices\n\
               end_header\n-1 -1 0 255 0 0 255\n1 -1 0 0 128 0 51\n0 1 0 0 0 255 0\n3 0 1 2\n";
    std::fs::write(dir.path().join("t.ply"), ply).unwrap();
    let text = scene_text("type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]", 1, 1)
        .replace("square.gltf", "t.ply");
    let scene = load(dir.path(), &text).unwrap_or_else(|e| panic!("{e}"));
    let srgb = glint::scene::image::srgb_to_linear;
    assert_eq!(
        scene.triangles[0].colors,
        Some([
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec4::new(0.0, srgb(128.0 / 255.0), 0.0, 0.2),
            Vec4::new(0.0, 0.0, 1.0, 0.0),
        ])
    );
}

/// The square with its own glTF material, KHR_materials_unlit of base colour (0.5, 1, 1), as
/// `square_scene` writes it otherwise (float RGB colours).
fn unlit_square(dir: &Path) {
    write_square(dir, &COLORS, FLOAT_RGB, |_| {});
    let path = dir.join("square.gltf");
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    json["materials"] = serde_json::json!([{
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1.0, 1.0, 1.0]},
        "extensions": {"KHR_materials_unlit": {}}
    }]);
    json["extensionsUsed"] = serde_json::json!(["KHR_materials_unlit"]);
    json["meshes"][0]["primitives"][0]["material"] = 0.into();
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
}

/// KHR_materials_unlit shows the base colour, and COLOR_0 multiplies the base colour: an
/// unlit square's pixels are the base colour times the vertex colour (camera rays only, on a
/// black background), on every device.
#[test]
fn vertex_colors_multiply_an_unlit_materials_colour_on_every_device() {
    let dir = tempfile::tempdir().unwrap();
    unlit_square(dir.path());
    let text = scene_text("", 0, 4)
        .replace(
            "background = [1.0, 1.0, 1.0]",
            "background = [0.0, 0.0, 0.0]",
        )
        .replace("[materials.square]\n", "")
        .replace("material = \"square\"\n", "");
    let scene = load(dir.path(), &text)
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene();
    let base = Vec3::new(0.5, 1.0, 1.0);
    for (device, image) in render_everywhere(&scene, 4) {
        let a = pixel(&image, IN_A);
        let want_a = base * Vec3::new(0.8, 0.4, 0.2);
        assert!(
            (a - want_a).abs().max_element() < 1e-4,
            "{device}: A's pixel is {a}, want {want_a}"
        );
        let b = pixel(&image, IN_B);
        let want_b = base * color_in_b(on_square(IN_B)).truncate();
        assert!(
            (b - want_b).abs().max_element() < 0.02,
            "{device}: B's pixel is {b}, want about {want_b}"
        );
    }
}

/// The unlit square lights a white floor in front of it as a lamp of its colours: light
/// sampling (which looks the emission up at the sampled point, the vertex colour included)
/// and BSDF sampling alone (which finds it at hits) agree, within 5 standard errors of the
/// difference of the image means (from the variance images), on the CPU and the GPU.
#[test]
fn an_unlit_vertex_colored_lamp_lights_the_same_with_light_sampling() {
    let dir = tempfile::tempdir().unwrap();
    unlit_square(dir.path());
    let text = "[camera]\neye = [0.0, 3.0, 6.0]\ntarget = [0.0, -1.0, 1.5]\n\
                up = [0.0, 1.0, 0.0]\nvfov = 30.0\n\n[render]\nwidth = 24\nheight = 24\n\
                spp = 64\nmax_bounces = 1\n\n[materials.floor]\ntype = \"diffuse\"\n\
                color = [1.0, 1.0, 1.0]\n\n[[quads]]\ncorner = [-3.0, -1.0, 4.0]\n\
                u = [6.0, 0.0, 0.0]\nv = [0.0, 0.0, -4.0]\nmaterial = \"floor\"\n\n\
                [[meshes]]\nfile = \"square.gltf\"\n";
    let scene = load(dir.path(), text).unwrap_or_else(|e| panic!("{e}"));
    let spp = 64;
    let on = common::with_light_sampling(&scene, true, 5);
    let off = common::with_light_sampling(&scene, false, 5);
    assert!(!on.emitters.is_empty(), "the unlit square is an emitter");
    let mean = |r: &mut dyn Renderer| {
        let (image, variance) = common::render_with_variance(r, spp);
        let n = (image.pixels.len() * 3) as f64;
        let m = image
            .pixels
            .iter()
            .flatten()
            .map(|&v| v as f64)
            .sum::<f64>()
            / n;
        let v = variance
            .pixels
            .iter()
            .flatten()
            .map(|&v| v as f64)
            .sum::<f64>()
            / (n * n);
        (m, v)
    };
    // The CPU and, where there is one, the GPU.
    for ((device, mut with), (_, mut without)) in common::renderers(&on)
        .into_iter()
        .zip(common::renderers(&off))
    {
        let (a, va) = mean(with.as_mut());
        let (b, vb) = mean(without.as_mut());
        let z = (a - b) / (va + vb).sqrt();
        eprintln!("{device}: light sampling on {a:.5}, off {b:.5}, z {z:.2}");
        assert!(a > 0.01, "{device}: the floor is lit ({a})");
        assert!(
            z.abs() < 5.0,
            "{device}: on {a} ± {}, off {b} ± {}",
            va.sqrt(),
            vb.sqrt()
        );
    }
}
