//! Textures: lookups at texel centres (exact) and edges (blended by repeat wrapping) on the CPU
//! and, through the probe kernel, in the WGSL; sRGB decoding against data read linearly; a checker
//! quad rendering exactly its checker on both devices; the textured Cornell box tracing the same
//! paths on GPU and CPU; sphere coordinates and the polynomial atan2; OBJ `vt` and `map_Kd`, glTF
//! TEXCOORD_0 and baseColorTexture; every class of bad texture input (exit 2, nothing written);
//! a texture set over lavapipe's binding limit rendering on the GPU.

use crate::common;

use common::probe::{run_probe, ProbeParams};
use glam::{Vec2, Vec3};
use glint::cpu::textures::texture::{both_sets, texture_lookup, Textures};
use glint::kernel::types::TriangleUvs;
use glint::kernel::KernelScene;
use glint::scene::image::srgb_to_linear;
use glint::scene::Scene;
use std::path::Path;

/// An 8-bit RGB PNG, rows top first.
fn write_png(path: &Path, width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 3]) {
    let image = image::RgbImage::from_fn(width, height, |x, y| image::Rgb(texel(x, y)));
    image.save(path).unwrap();
}

/// A scene in `dir` whose first material is `material` (TOML lines after `[materials.m]`),
/// on a quad facing the camera, with `size`² pixels.
fn scene_with(dir: &Path, material: &str, size: u32) -> Result<Scene, String> {
    let text = format!(
        r#"[camera]
eye = [0.0, 0.0, -10.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 11.421186
[render]
width = {size}
height = {size}
spp = 1
max_bounces = 1
background = [1.0, 1.0, 1.0]
[materials.m]
{material}
# Seen from the camera, u runs to the right and v up; the quad fills the view exactly
# (tan(vfov / 2) = 0.1 at distance 10).
[[quads]]
corner = [1.0, -1.0, 0.0]
u = [-2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "m"
"#
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).map_err(|e| e.to_string())
}

/// Distinct texel values: channel c of texel (x, y) (from the top left) is 10·x + 60·y + 3·c + 1.
fn distinct(x: u32, y: u32) -> [u8; 3] {
    [0, 1, 2].map(|c| (10 * x + 60 * y + 3 * c + 1) as u8)
}

/// The lookups of `texture` at `uvs`: on the CPU, and on the GPU where there is one.
fn lookups(scene: &KernelScene, texture: u32, uvs: &[Vec2]) -> Vec<(&'static str, Vec<Vec3>)> {
    let textures = Textures {
        descriptors: &scene.textures,
        texels: &scene.texels,
    };
    let cpu = uvs
        .iter()
        .map(|&uv| texture_lookup(&textures, texture, both_sets(uv)))
        .collect();
    let mut out = vec![("cpu", cpu)];
    if let Some(ctx) = common::gpu() {
        let mut probed = scene.clone();
        probed.triangle_uvs = uvs
            .iter()
            .map(|uv| TriangleUvs {
                uv0: uv.to_array(),
                ..Default::default()
            })
            .collect();
        let params = ProbeParams {
            count: uvs.len() as u32,
            seed: texture,
            ..Default::default()
        };
        let gpu = run_probe(ctx, "probe_texture", params, &probed)
            .iter()
            .map(|v| Vec3::new(v[0], v[1], v[2]))
            .collect();
        out.push(("gpu", gpu));
    }
    out
}

/// At texel centres ((x + 0.5)/w, (y + 0.5)/h) the bilinear weights are exactly 0 and 1 when
/// the sizes are powers of two (the coordinates are exact binary fractions), so the stored
/// texel comes back bit for bit; on other sizes the coordinates round, and the weight of the
/// neighbour is a few ulps. Texels are stored bottom row first (v up).
#[test]
fn texel_centres_read_back_exactly() {
    let dir = tempfile::tempdir().unwrap();
    for (width, height, exact) in [(8, 4, true), (3, 5, false)] {
        write_png(&dir.path().join("t.png"), width, height, distinct);
        let material = "type = \"diffuse\"\ncolor = { texture = \"t.png\" }";
        let scene = scene_with(dir.path(), material, 4).unwrap().kernel_scene();
        assert_eq!(scene.texels.len(), (width * height) as usize);
        let mut uvs = Vec::new();
        let mut expected = Vec::new();
        for y in 0..height {
            for x in 0..width {
                uvs.push(Vec2::new(
                    (x as f32 + 0.5) / width as f32,
                    (y as f32 + 0.5) / height as f32,
                ));
                let stored = scene.texels[(y * width + x) as usize];
                // Row y from the bottom is the file's row height − 1 − y, decoded from sRGB.
                let file = distinct(x, height - 1 - y).map(|c| srgb_to_linear(c as f32 / 255.0));
                assert_eq!(stored[..3], file[..], "texel ({x}, {y}) as stored");
                expected.push(Vec3::new(stored[0], stored[1], stored[2]));
            }
        }
        for (device, values) in lookups(&scene, 0, &uvs) {
            for (i, (got, want)) in values.iter().zip(&expected).enumerate() {
                if exact {
                    assert_eq!(got, want, "{device}: texel {i} of {width}×{height}");
                } else {
                    assert!(
                        (*got - *want).abs().max_element() <= 4.0 * f32::EPSILON,
                        "{device}: texel {i} of {width}×{height}: {got} against {want}"
                    );
                }
            }
        }
    }
}

/// Repeat wrapping: u = 0 and u = 1 lie on the edge between the last and the first column, so
/// they read the mean of the two; v = 0 likewise blends the top and bottom rows; whole-number
/// shifts of u and v (negative ones too) read the same as the unshifted point.
#[test]
fn bilinear_filtering_wraps_at_the_edges() {
    let dir = tempfile::tempdir().unwrap();
    let (width, height) = (4u32, 2u32);
    write_png(&dir.path().join("t.png"), width, height, distinct);
    // Read linearly (a metal's roughness), so the texels are the bytes / 255.
    let material = "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = { texture = \"t.png\" }";
    let scene = scene_with(dir.path(), material, 4).unwrap().kernel_scene();
    let texel = |x: u32, y: u32| Vec3::from_slice(&scene.texels[(y * width + x) as usize][..3]);
    let row_centre = 0.25; // v of the bottom row's centre
    let cases = [
        (
            Vec2::new(0.0, row_centre),
            (texel(0, 0) + texel(3, 0)) * 0.5,
        ),
        (
            Vec2::new(1.0, row_centre),
            (texel(0, 0) + texel(3, 0)) * 0.5,
        ),
        (Vec2::new(0.125, 0.0), (texel(0, 0) + texel(0, 1)) * 0.5),
        (
            Vec2::new(0.0, 0.0),
            (texel(0, 0) + texel(3, 0) + texel(0, 1) + texel(3, 1)) * 0.25,
        ),
        // A quarter of the way from column 1's centre to column 2's.
        (
            Vec2::new(0.375 + 0.0625, row_centre),
            texel(1, 0) * 0.75 + texel(2, 0) * 0.25,
        ),
        (Vec2::new(-2.875, 3.25), texel(0, 0)),
    ];
    let uvs: Vec<Vec2> = cases.iter().map(|c| c.0).collect();
    for (device, values) in lookups(&scene, 0, &uvs) {
        for ((uv, want), got) in cases.iter().zip(&values) {
            assert!(
                (*got - *want).abs().max_element() <= 1e-6,
                "{device}: at {uv}: {got} against {want}"
            );
        }
    }
}

/// A colour texture is sRGB-decoded: the byte 128 reads 0.2158605 (IEC 61966-2-1), where the
/// same file read as data (a roughness texture) reads 128/255 = 0.5019608.
#[test]
fn srgb_textures_are_linearised_and_data_textures_are_not() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("grey.png"), 2, 2, |_, _| [128; 3]);
    let both = "type = \"metal\"\ncolor = { texture = \"grey.png\" }\nroughness = { texture = \"grey.png\" }";
    let scene = scene_with(dir.path(), both, 4).unwrap().kernel_scene();
    // The same file is loaded once per use: as colour, and as data.
    assert_eq!(scene.textures.len(), 2);
    let m = &scene.materials[0];
    let at = Vec2::new(0.3, 0.6);
    for (device, values) in lookups(&scene, m.color_texture, &[at]) {
        assert!(
            (values[0] - Vec3::splat(0.215_860_5)).abs().max_element() < 1e-6,
            "{device}"
        );
    }
    // A roughness texture holds the roughness in x and the metallic factor, 1, in y.
    for (device, values) in lookups(&scene, m.roughness_texture, &[at]) {
        assert!(
            (values[0] - Vec3::new(128.0 / 255.0, 1.0, 1.0))
                .abs()
                .max_element()
                < 1e-7,
            "{device}"
        );
    }
}

/// A colour texture is filtered after its sRGB decoding, as glTF asks ("the transfer function
/// should be decoded before performing linear interpolation"; Khronos' sample
/// TextureLinearInterpolationTest): halfway between a black and a white texel reads 0.5, not
/// the decoded midpoint byte (0.2140). Blender's Cycles interpolates 8-bit sRGB images before
/// decoding them, which darkens a checker's edges (docs/src/performance/validation.md).
#[test]
fn colour_textures_are_filtered_after_decoding() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("bw.png"), 2, 1, |x, _| [255 * x as u8; 3]);
    let material = "type = \"diffuse\"\ncolor = { texture = \"bw.png\" }";
    let scene = scene_with(dir.path(), material, 4).unwrap().kernel_scene();
    let m = &scene.materials[0];
    // Texel centres at u = 0.25 and 0.75; u = 0.5 is halfway, u = 0.375 a quarter of the way.
    let uvs = [Vec2::new(0.5, 0.5), Vec2::new(0.375, 0.5)];
    for (device, values) in lookups(&scene, m.color_texture, &uvs) {
        assert!(
            (values[0] - Vec3::splat(0.5)).abs().max_element() < 1e-6,
            "{device}: {}",
            values[0]
        );
        assert!(
            (values[1] - Vec3::splat(0.25)).abs().max_element() < 1e-6,
            "{device}: {}",
            values[1]
        );
    }
}

/// The same file used twice for colour is loaded once.
#[test]
fn a_file_used_twice_is_loaded_once() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("t.png"), 2, 2, distinct);
    let material = "type = \"diffuse\"\ncolor = { texture = \"t.png\" }\n\
                    [materials.n]\ntype = \"specular\"\ncolor = { texture = \"./t.png\" }";
    let scene = scene_with(dir.path(), material, 4).unwrap().kernel_scene();
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(scene.texels.len(), 4);
    assert_eq!(
        scene.materials[0].color_texture,
        scene.materials[1].color_texture
    );
}

/// A diffuse checker quad filling the view under a white sky, one bounce: every path's
/// radiance is exactly the albedo where it hits (cosine sampling's weight is the albedo and
/// every bounced ray escapes), so the image is the checker itself. At 32² and scale 4 each
/// square is 8×8 pixels and square edges fall on pixel edges, so no pixel straddles two
/// squares. CPU and GPU must both render it, and so trace the same paths.
#[test]
fn a_checker_quad_renders_its_checker_on_both_devices() {
    let dir = tempfile::tempdir().unwrap();
    let material =
        "type = \"diffuse\"\ncolor = { checker = [[0.9, 0.8, 0.7], [0.1, 0.2, 0.3]], scale = 4 }";
    let scene = scene_with(dir.path(), material, 32).unwrap().kernel_scene();
    let colors = [Vec3::new(0.9, 0.8, 0.7), Vec3::new(0.1, 0.2, 0.3)];
    let mut images = Vec::new();
    for (device, image) in common::render_both(&scene, 1) {
        for py in 0..32u32 {
            for px in 0..32u32 {
                // u grows to the right, v up: square (px / 8, 3 − py / 8).
                let parity = (px / 8 + (3 - py / 8)) % 2;
                let want = colors[parity as usize];
                let got = Vec3::from(image.pixels[(py * 32 + px) as usize]);
                assert!(
                    (got - want).abs().max_element() <= 1e-6,
                    "{device}: pixel ({px}, {py}) is {got}, the checker's {want}"
                );
            }
        }
        images.push(image);
    }
    if images.len() == 2 {
        let mut agreement = common::PathAgreement::default();
        agreement.add(&images[0], &images[1]);
        agreement.check(0.99);
    }
}

/// An image texture on the shipped textured Cornell box: GPU and CPU trace the same paths
/// (the criterion of tests/suite/gpu_vs_cpu.rs), through image lookups on a quad and a sphere, a
/// checker floor and a roughness texture.
#[test]
fn the_textured_cornell_box_traces_the_same_paths_on_both_devices() {
    let Some(ctx) = common::gpu() else { return };
    let mut agreement = common::PathAgreement::default();
    for seed in [3, 4] {
        let scene = common::sized(common::shipped_scene("cornell-textured.toml"), 48, seed);
        assert!(glint::kernel::variant::KernelFeatures::of(&scene).textures);
        agreement.add(
            &common::render_cpu(&scene, 1),
            &common::render_gpu(ctx, &scene, 1),
        );
    }
    agreement.check(0.99);
}

/// A PNG header claiming 0×0 texels (the encoders refuse to write one), with valid CRCs.
fn zero_by_zero_png() -> Vec<u8> {
    fn chunk(kind: &[u8], data: &[u8]) -> Vec<u8> {
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        let mut out = (data.len() as u32).to_be_bytes().to_vec();
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc32(&body).to_be_bytes());
        out
    }
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= b as u32;
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &[0, 0, 0, 0, 0, 0, 0, 0, 8, 2, 0, 0, 0]));
    png.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    png.extend(chunk(b"IEND", &[]));
    png
}

/// Loads a scene whose material `m` is `material`, with `files` beside it, and checks the error
/// names the scene file, the line of the offending value, the field, and every needle.
fn assert_error(material: &str, files: &[(&str, Vec<u8>)], field: &str, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let message = scene_with(dir.path(), material, 4).expect_err("the scene should be rejected");
    // [materials.m] is on line 12; the material's lines follow it.
    let line = 13 + material.lines().position(|l| l.starts_with(field)).unwrap();
    assert!(
        message.contains(&format!("scene.toml:{line}:")),
        "{message}"
    );
    assert!(
        message.contains(&format!("materials.m.{field}")),
        "{message}"
    );
    for needle in needles {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
    assert_eq!(message.lines().count(), 1, "{message}");
}

fn png_bytes(width: u32, height: u32) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.png");
    write_png(&path, width, height, distinct);
    std::fs::read(path).unwrap()
}

#[test]
fn missing_and_unreadable_images() {
    let diffuse = |file: &str| format!("type = \"diffuse\"\ncolor = {{ texture = \"{file}\" }}");
    assert_error(&diffuse("nope.png"), &[], "color", &["nope.png"]);
    assert_error(
        &diffuse("bad.png"),
        &[("bad.png", b"not an image at all".to_vec())],
        "color",
        &["bad.png", "not a PNG, JPEG, EXR or Radiance HDR image"],
    );
    let mut truncated = png_bytes(16, 16);
    truncated.truncate(truncated.len() / 2);
    assert_error(
        &diffuse("cut.png"),
        &[("cut.png", truncated)],
        "color",
        &["cut.png", "cannot decode"],
    );
    assert_error(
        &diffuse("empty.png"),
        &[("empty.png", zero_by_zero_png())],
        "color",
        &["empty.png"],
    );
}

#[test]
fn textures_on_fields_that_take_none() {
    let png = || vec![("t.png", png_bytes(2, 2))];
    assert_error(
        "type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\nemission = { texture = \"t.png\" }",
        &png(),
        "emission",
        &["takes no texture"],
    );
    assert_error(
        "type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\nroughness = { texture = \"t.png\" }",
        &png(),
        "roughness",
        &["does not apply to a diffuse material"],
    );
    assert_error(
        "type = \"diffuse\"\ncolor = { texture = \"t.png\", scale = 2 }",
        &png(),
        "color",
        &["unknown keys", "scale"],
    );
    assert_error(
        "type = \"diffuse\"\ncolor = { checker = [[0.5, 0.5, 0.5]] }",
        &png(),
        "color",
        &["two colors"],
    );
    assert_error(
        "type = \"diffuse\"\ncolor = { checker = [[0.5, 0.5, 0.5], [1.5, 0, 0]] }",
        &png(),
        "color",
        &["[0, 1]"],
    );
    assert_error(
        "type = \"diffuse\"\ncolor = { checker = [[0.5, 0.5, 0.5], [0, 0, 0]], scale = -1 }",
        &png(),
        "color",
        &["scale", "got -1"],
    );
    assert_error(
        "type = \"metal\"\ncolor = [1, 1, 1]\nroughness = \"rough\"",
        &png(),
        "roughness",
        &["must be a constant"],
    );
}

/// A colour texture's texels are reflectances: an EXR texel above 1 would create energy.
#[test]
fn color_texels_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hot.exr");
    image::Rgb32FImage::from_fn(2, 2, |x, y| {
        image::Rgb([0.5, 0.5, if (x, y) == (1, 0) { 1.5 } else { 0.5 }])
    })
    .save(&path)
    .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_error(
        "type = \"diffuse\"\ncolor = { texture = \"hot.exr\" }",
        &[("hot.exr", bytes)],
        "color",
        &["hot.exr", "texel (1, 0)", "1.5", "[0, 1]"],
    );
}

/// Tiny negative texels (lossy EXR compression) are set to 0 with one warning, as in
/// environment maps; the texture loads.
#[test]
fn tiny_negative_color_texels_are_clamped_with_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    image::Rgb32FImage::from_fn(2, 2, |x, y| {
        image::Rgb([0.5, 0.5, if (x, y) == (1, 0) { -3e-6 } else { 0.5 }])
    })
    .save(dir.path().join("dark.exr"))
    .unwrap();
    let scene = scene_with(
        dir.path(),
        "type = \"diffuse\"\ncolor = { texture = \"dark.exr\" }",
        4,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.textures.texels.iter().all(|t| t[2] >= 0.0));
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    let warnings: Vec<_> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].contains("dark.exr: 1 negative value (the most negative -3e-6) set to 0"),
        "{stderr}"
    );
}

/// Runs `glint render` on a scene with a texture, expecting exit code 2, one line on stderr
/// holding every needle, and no output file.
fn assert_cli_refuses(png: Vec<u8>, device: &str, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.png"), png).unwrap();
    scene_with(
        dir.path(),
        "type = \"diffuse\"\ncolor = { texture = \"t.png\" }",
        4,
    )
    .ok();
    let out = dir.path().join("out.png");
    let run = common::run_render(device, &dir.path().join("scene.toml"), &out);
    common::assert_refused(&run, &out, needles);
}

#[test]
fn the_cli_exits_with_2_and_writes_nothing() {
    assert_cli_refuses(b"garbage".to_vec(), "--cpu", &["scene.toml:14:", "t.png"]);
}

/// A texture set larger than the device's storage binding limit renders on the GPU, its
/// texels split over two bindings (src/kernel/texels.rs; tests/suite/texel_windows.rs checks the
/// image). lavapipe allows 128 MiB per binding: 4096×2049 texels of 16 bytes are just over it.
/// Devices with a larger limit skip this (the image cap of 2²⁴ texels per file keeps such a
/// test affordable only here). Texels beyond four bindings are refused: tests/suite/texel_windows.rs.
#[test]
fn a_texture_larger_than_one_binding_renders_on_the_gpu() {
    let Some(ctx) = common::gpu() else { return };
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let (width, height) = (4096u32, 2049u32);
    if (width * height) as u64 * 16 <= limit {
        eprintln!("the device binds {limit} bytes: a {width}×{height} texture fits; skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(width, height, image::Rgb([200, 100, 50]))
        .save(dir.path().join("big.png"))
        .unwrap();
    scene_with(
        dir.path(),
        "type = \"diffuse\"\ncolor = { texture = \"big.png\" }",
        4,
    )
    .unwrap();
    let out = dir.path().join("out.exr");
    let run = common::run_render("--gpu", &dir.path().join("scene.toml"), &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    // The quad fills the view under a white sky, one bounce: every pixel is the texel's
    // colour, sRGB-decoded, times the sky (1), the path's one bounce escaping.
    let image = glint::image::output::Image::read_exr(&out).unwrap();
    let want = [200u8, 100, 50].map(|c| srgb_to_linear(c as f32 / 255.0));
    for p in &image.pixels {
        for c in 0..3 {
            assert!(
                (p[c] - want[c]).abs() <= 1e-4,
                "pixel {p:?}, texel {want:?}"
            );
        }
    }
}

/// The polynomial atan2 behind sphere coordinates is within 1e-6 rad of the exact one over
/// every direction (its own error is 2e-8; the rest is f32 rounding), and the conventions hold:
/// u = 0.5 facing +x, 0.75 facing −z, 1 at the seam facing −x; v = 1 at the top pole.
#[test]
fn sphere_coordinates() {
    use glint::cpu::textures::texture::{polynomial_atan2, sphere_uv};
    let mut worst = 0.0f64;
    for i in 0..20_000 {
        let angle = i as f64 / 20_000.0 * std::f64::consts::TAU;
        for radius in [1e-3, 1.0, 1e3] {
            let (y, x) = ((angle.sin() * radius) as f32, (angle.cos() * radius) as f32);
            let exact = (y as f64).atan2(x as f64);
            worst = worst.max((polynomial_atan2(y, x) as f64 - exact).abs());
        }
    }
    assert!(worst < 1e-6, "largest error {worst:e} rad");
    assert_eq!(polynomial_atan2(0.0, 0.0), 0.0);
    let close = |a: Vec2, b: Vec2| (a - b).abs().max_element() < 1e-6;
    assert!(close(sphere_uv(Vec3::X), Vec2::new(0.5, 0.5)));
    assert!(close(sphere_uv(Vec3::NEG_Z), Vec2::new(0.75, 0.5)));
    assert!(close(sphere_uv(Vec3::Z), Vec2::new(0.25, 0.5)));
    assert!(close(sphere_uv(Vec3::NEG_X), Vec2::new(1.0, 0.5)));
    assert!(close(sphere_uv(Vec3::Y), Vec2::new(0.5, 1.0)));
    assert!(close(sphere_uv(Vec3::NEG_Y), Vec2::new(0.5, 0.0)));
}

/// An OBJ's `vt` coordinates reach the triangles and its `.mtl`'s `map_Kd` becomes the colour
/// texture of the file's material; the textured mesh under a white sky renders the texture's
/// colours on both devices (a 1-bounce diffuse surface there shows exactly its albedo).
#[test]
fn obj_texture_coordinates_and_map_kd() {
    let dir = tempfile::tempdir().unwrap();
    // Two texels: red on the left (u < 0.5), blue on the right.
    write_png(&dir.path().join("rb.png"), 2, 1, |x, _| {
        if x == 0 {
            [255, 0, 0]
        } else {
            [0, 0, 255]
        }
    });
    let obj = "mtllib q.mtl\nv 1 -1 0\nv -1 -1 0\nv -1 1 0\nv 1 1 0\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl painted\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    std::fs::write(dir.path().join("q.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("q.mtl"),
        "newmtl painted\nKd 1 1 1\nmap_Kd rb.png\n",
    )
    .unwrap();
    let text = std::fs::read_to_string({
        scene_with(dir.path(), "type = \"diffuse\"\ncolor = [1, 1, 1]", 16).unwrap();
        dir.path().join("scene.toml")
    })
    .unwrap()
    .replace("[[quads]]", "[[meshes]]\nfile = \"q.obj\"\n[[unused]]");
    // Keep only the mesh: drop the quad's lines after the marker.
    let text = text[..text.find("[[unused]]").unwrap()].to_string();
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    let scene = Scene::load(&dir.path().join("scene.toml")).unwrap();
    let painted = scene
        .materials
        .iter()
        .find(|m| m.name == "q.obj/painted")
        .unwrap();
    assert!(painted.color_texture.is_some());
    let scene = scene.kernel_scene();
    assert_eq!(scene.triangle_uvs.len(), 2);
    assert_eq!(scene.triangle_uvs[0].uv1, [1.0, 0.0]);
    assert_eq!(scene.triangle_uvs[1].uv2, [0.0, 1.0]);
    for (device, image) in common::render_both(&scene, 1) {
        // Pixel columns 3 and 12 are at u ≈ 0.22 and 0.78, within a quarter texel of the
        // texels' centres: mostly red, mostly blue.
        for py in [2, 8, 13] {
            let left = Vec3::from(image.pixels[py * 16 + 3]);
            let right = Vec3::from(image.pixels[py * 16 + 12]);
            assert!(
                left.x > 0.7 && left.z < 0.3 && left.y == 0.0,
                "{device}: {left}"
            );
            assert!(right.z > 0.7 && right.x < 0.3, "{device}: {right}");
        }
    }
}

/// A glTF's TEXCOORD_0 reaches the triangles with v flipped (glTF's v points down, glint's
/// up), and its material's baseColorTexture, an image by URI, becomes the colour texture.
#[test]
fn gltf_texcoords_and_base_color_texture() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("t.png"), 2, 2, distinct);
    let positions: [f32; 9] = [1.0, -1.0, 0.0, -1.0, -1.0, 0.0, -1.0, 1.0, 0.0];
    let texcoords: [f32; 6] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.25];
    let mut buffer: Vec<u8> = bytemuck::cast_slice(&positions).to_vec();
    buffer.extend_from_slice(bytemuck::cast_slice(&texcoords));
    std::fs::write(dir.path().join("buf.bin"), &buffer).unwrap();
    let gltf = r#"{
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
  "textures": [{"source": 0}],
  "images": [{"uri": "t.png"}],
  "buffers": [{"uri": "buf.bin", "byteLength": 60}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
  ]
}"#;
    std::fs::write(dir.path().join("t.gltf"), gltf).unwrap();
    scene_with(dir.path(), "type = \"diffuse\"\ncolor = [1, 1, 1]", 4).unwrap();
    let path = dir.path().join("scene.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text =
        text[..text.find("[[quads]]").unwrap()].to_string() + "[[meshes]]\nfile = \"t.gltf\"\n";
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let material = scene
        .materials
        .iter()
        .find(|m| m.name.starts_with("t.gltf/"))
        .unwrap();
    assert!(material.color_texture.is_some());
    let scene = scene.kernel_scene();
    assert_eq!(scene.texels.len(), 4);
    let uvs = scene.triangle_uvs[0];
    assert_eq!(
        [uvs.uv0, uvs.uv1, uvs.uv2],
        [[0.0, 0.0], [1.0, 0.0], [1.0, 0.75]]
    );
}

/// The glTF sampler's wrap modes, nearest filtering and KHR_texture_transform's affine map, on
/// a 4×2 data texture with distinct texels, at coordinates whose bilinear weights are exact
/// binary fractions (so both devices return the texels, or their exact means, to 1e-6):
/// - clamp on u: far outside [0, 1] reads the edge column, never the opposite one;
/// - mirrored repeat on v: 1.25 reads row 1 (the mirror image of 0.75), −0.25 row 0, and
///   v = 1 reads row 1 alone (repeat would blend it with row 0, the test above);
/// - nearest: (0.49, 0.26) reads texel (1, 0) alone, where bilinear would blend four;
/// - a transform that swaps u and v: (0.75, 0.375) reads what (0.375, 0.75) reads untransformed.
#[test]
fn wrap_modes_nearest_filtering_and_transforms() {
    use glint::kernel::types::{TEXTURE_NEAREST, TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR};
    let dir = tempfile::tempdir().unwrap();
    let (width, height) = (4u32, 2u32);
    write_png(&dir.path().join("t.png"), width, height, distinct);
    let material = "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = { texture = \"t.png\" }";
    let mut scene = scene_with(dir.path(), material, 4).unwrap().kernel_scene();
    let texel = |x: u32, y: u32| Vec3::from_slice(&scene.texels[(y * width + x) as usize][..3]);
    let base = scene.textures[0];
    let mut variant = |sampling: u32, transform: Option<([f32; 3], [f32; 3])>| {
        let mut t = base;
        t.sampling = sampling;
        if let Some((u, v)) = transform {
            t.transform_u = u;
            t.transform_v = v;
        }
        scene.textures.push(t);
        scene.textures.len() as u32 - 1
    };
    let clamp_mirror = variant(TEXTURE_WRAP_CLAMP | (TEXTURE_WRAP_MIRROR << 8), None);
    let nearest = variant(TEXTURE_NEAREST, None);
    let swapped = variant(0, Some(([0.0, 1.0, 0.0], [1.0, 0.0, 0.0])));
    let row_centre = 0.25;
    let cases = [
        (clamp_mirror, Vec2::new(-0.3, row_centre), texel(0, 0)),
        (clamp_mirror, Vec2::new(1.7, row_centre), texel(3, 0)),
        (clamp_mirror, Vec2::new(0.125, 1.25), texel(0, 1)),
        (clamp_mirror, Vec2::new(0.125, -0.25), texel(0, 0)),
        (clamp_mirror, Vec2::new(0.875, 1.0), texel(3, 1)),
        (nearest, Vec2::new(0.49, 0.26), texel(1, 0)),
        (nearest, Vec2::new(0.99, 0.99), texel(3, 1)),
        (swapped, Vec2::new(0.75, 0.375), texel(1, 1)),
        (0, Vec2::new(0.375, 0.75), texel(1, 1)),
    ];
    for (texture, uv, want) in cases {
        for (device, values) in lookups(&scene, texture, &[uv]) {
            assert!(
                (values[0] - want).abs().max_element() <= 1e-6,
                "{device}: texture {texture} at {uv}: {} against {want}",
                values[0]
            );
        }
    }
}
