//! Khronos' glTF sample models as Debian's `assimp-testmodels` ships them, rendered and checked
//! against what each file says it should show. Each test is skipped, with a line saying so,
//! where the package is absent (`.ci/run` installs it).

use crate::common;

use glam::{Mat3, Vec2, Vec3};
use glint::image::output::Image;
use glint::scene::Scene;
use std::path::{Path, PathBuf};

const SAMPLES: &str = "/usr/share/assimp/models/glTF2";

/// The sample's path, or None (with a line on stderr) when the package is not installed.
fn sample(relative: &str) -> Option<PathBuf> {
    let path = Path::new(SAMPLES).join(relative);
    if path.exists() {
        Some(path)
    } else {
        eprintln!(
            "{} is absent (package assimp-testmodels): skipped",
            path.display()
        );
        None
    }
}

/// TextureTransformTest's layout: nine 1×1 quads in the z = 0 plane facing +z, within
/// x ∈ [−1.65, 1.65], y ∈ [−1.1, 1.1]. The camera sees x ∈ [−1.8, 1.8], y ∈ [−1.2, 1.2] at
/// z = 0 from z = 10, WIDTH × HEIGHT pixels, under a white sky.
const WIDTH: u32 = 360;
const HEIGHT: u32 = 240;
const DISTANCE: f32 = 10.0;
const HALF_HEIGHT: f32 = 1.2;

/// The point of the z = 0 plane pixel (x, y)'s centre looks at.
fn plane_point(x: u32, y: u32) -> Vec2 {
    let half_width = HALF_HEIGHT * WIDTH as f32 / HEIGHT as f32;
    Vec2::new(
        ((x as f32 + 0.5) / WIDTH as f32 * 2.0 - 1.0) * half_width,
        (1.0 - (y as f32 + 0.5) / HEIGHT as f32 * 2.0) * HALF_HEIGHT,
    )
}

fn render_texture_transform_test(path: &Path) -> Image {
    let dir = tempfile::tempdir().unwrap();
    let vfov = 2.0 * (HALF_HEIGHT / DISTANCE).atan().to_degrees();
    let text = format!(
        r#"[camera]
eye = [0.0, 0.0, {DISTANCE}]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = {vfov}
[render]
width = {WIDTH}
height = {HEIGHT}
spp = 16
max_bounces = 1
background = [1.0, 1.0, 1.0]
[[meshes]]
file = "{}"
"#,
        path.display()
    );
    let scene_path = dir.path().join("scene.toml");
    std::fs::write(&scene_path, text).unwrap();
    let scene = Scene::load(&scene_path).unwrap_or_else(|e| panic!("{e}"));
    let image = common::render_cpu(&scene.kernel_scene(), 16);
    if let Ok(out) = std::env::var("GLINT_TEST_OUTPUT") {
        image
            .write(&Path::new(&out).join("texture_transform_test.png"))
            .unwrap();
    }
    image
}

/// The mean colour of the pixels whose plane points lie within `half` of `centre`.
fn mean_colour(image: &Image, centre: Vec2, half: f32) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut n = 0;
    for y in 0..image.height {
        for x in 0..image.width {
            let d = (plane_point(x, y) - centre).abs();
            if d.x <= half && d.y <= half {
                sum += Vec3::from(image.pixels[(y * image.width + x) as usize]);
                n += 1;
            }
        }
    }
    sum / n as f32
}

/// KHR_texture_transform as Khronos' TextureTransformTest.gltf checks it.
///
/// The top row's tiles show a quarter of UV.png chosen by an offset: the green "U" quarter,
/// the blue "V" quarter and the cyan "UV" quarter when the offsets are applied, the yellow
/// "not supported" quarter when they are not (the v offset moves down the image, so a
/// wrongly flipped v shows the wrong quarter). Each tile's mean colour must be the expected
/// quarter's hue.
///
/// The bottom row's tiles show Arrow.png (a black arrow on white) rotated, scaled, and all
/// three with an offset; the arrow should point at a small marker the file places beside it
/// ("correct" where it should point, "not supported" where an untransformed arrow points,
/// "error" elsewhere; all three markers are always in view, by the file's design). Here each
/// tile is compared pixel by pixel with Arrow.png looked up (nearest texel, clamped as the
/// file's sampler says) at the texture coordinates the extension gives (T·R·S in glTF's own
/// v-down coordinates, the rotation counterclockwise as drawn there, written out independently
/// of glint; the GLSL snippet in the extension's README rotates the other way, which points
/// the arrow at the "error" marker): the dark pixels of the render and of the
/// expectation, away from the markers and the tile's edges, must overlap by 80% of their union
/// at least (anti-aliased edges and noise account for the rest); the untransformed arrow's must
/// overlap the render's by under 50% (the test can tell the two apart).
/// BoxTexcoords (assimp's test model) puts its base colour on TEXCOORD_0 and its
/// metallic-roughness texture on TEXCOORD_1, which differ: both are read, each texture's
/// descriptor naming its set, with no warning about either.
#[test]
fn box_texcoords_reads_each_texture_on_its_own_set() {
    let Some(path) = sample("BoxTexcoords-glTF/boxTexcoords.gltf") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("scene.toml");
    let text = format!(
        "[camera]\neye = [2.0, 2.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         vfov = 40.0\n[render]\nwidth = 16\nheight = 16\nspp = 1\nmax_bounces = 1\n[[meshes]]\nfile = \"{}\"\n",
        path.display()
    );
    std::fs::write(&scene_path, text).unwrap();
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &scene_path, &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("TEXCOORD"), "{stderr}");
    let scene = Scene::load(&scene_path).unwrap_or_else(|e| panic!("{e}"));
    let material = scene.triangles[0].material as usize;
    let scene = scene.kernel_scene();
    let m = scene.materials[material];
    assert_eq!(scene.textures[m.color_texture as usize].uv_set, 0);
    assert_eq!(scene.textures[m.roughness_texture as usize].uv_set, 1);
    assert_eq!(scene.triangle_uvs1.len(), scene.triangles.len());
    assert_ne!(scene.triangle_uvs1, scene.triangle_uvs);
}

#[test]
fn the_texture_transform_test_shows_what_it_should() {
    let Some(path) = sample("textureTransform/TextureTransformTest.gltf") else {
        return;
    };
    let image = render_texture_transform_test(&path);

    // Top row: U at x = −1.1, V at 0, UV at 1.1 (y = 0.55). Away from the white check marks:
    // the quarter of the tile by its top-left corner shows the background colour only.
    for (x, name, want) in [
        (-1.1, "Offset U", Vec3::new(0.0, 1.0, 0.0)),
        (0.0, "Offset V", Vec3::new(0.0, 0.0, 1.0)),
        (1.1, "Offset UV", Vec3::new(0.0, 1.0, 1.0)),
    ] {
        let c = mean_colour(&image, Vec2::new(x - 0.35, 0.55 + 0.35), 0.1);
        let hue = c / c.max_element();
        assert!(
            (hue - want).abs().max_element() < 0.25,
            "{name}: mean colour {c} (hue {hue}), expected the hue {want}"
        );
    }

    // Bottom row: the arrow texture with its transforms, and the markers each tile carries
    // (offset from the tile's centre, half size), which hide the tile where they are.
    let arrow = image::open(path.with_file_name("Arrow.png"))
        .unwrap()
        .to_luma8();
    // The file's sampler clamps (the images have a grey border for it).
    let arrow_dark = |s: f32, t: f32| {
        let (w, h) = arrow.dimensions();
        let x = (s.clamp(0.0, 1.0) * w as f32) as u32;
        let y = (t.clamp(0.0, 1.0) * h as f32) as u32;
        arrow.get_pixel(x.min(w - 1), y.min(h - 1))[0] < 128
    };
    let transform = |offset: [f32; 2], rotation: f32, scale: [f32; 2]| {
        let (s, c) = rotation.sin_cos();
        Mat3::from_cols_array(&[1., 0., 0., 0., 1., 0., offset[0], offset[1], 1.])
            * Mat3::from_cols_array(&[c, -s, 0., s, c, 0., 0., 0., 1.])
            * Mat3::from_cols_array(&[scale[0], 0., 0., 0., scale[1], 0., 0., 0., 1.])
    };
    let tiles = [
        (
            "Rotation",
            -1.1,
            transform([0.0, 0.0], std::f32::consts::FRAC_PI_8, [1.0, 1.0]),
            vec![
                (Vec2::new(-0.079, -0.516), 0.075),
                (Vec2::new(0.278, -0.278), 0.075),
                (Vec2::new(0.516, 0.079), 0.075),
            ],
        ),
        (
            "Scale",
            0.0,
            transform([0.0, 0.0], 0.0, [1.5, 1.5]),
            vec![
                (Vec2::new(0.019, -0.019), 0.05),
                (Vec2::new(0.278, -0.278), 0.075),
            ],
        ),
        (
            "All",
            1.1,
            transform([-0.2, -0.1], 0.3, [1.5, 1.5]),
            vec![(Vec2::new(-0.07, -0.25), 0.05)],
        ),
    ];
    for (name, centre_x, matrix, markers) in tiles {
        let centre = Vec2::new(centre_x, -0.55);
        // Dark pixels: in both the render and the expectation, in either; the same against the
        // untransformed arrow.
        let (mut both, mut either, mut both_untransformed, mut either_untransformed) = (0, 0, 0, 0);
        for y in 0..image.height {
            for x in 0..image.width {
                let p = plane_point(x, y) - centre;
                // Inside the tile, a pixel and a half from its edges, off the markers.
                let margin = 1.5 * 2.0 * HALF_HEIGHT / HEIGHT as f32;
                if p.abs().max_element() > 0.5 - margin
                    || markers
                        .iter()
                        .any(|(m, half)| (p - *m).abs().max_element() < half + margin)
                {
                    continue;
                }
                // The quad's TEXCOORD_0 (glTF's, v down): (x + 0.5, 0.5 − y).
                let uv = Vec3::new(p.x + 0.5, 0.5 - p.y, 1.0);
                let t = matrix * uv;
                let expected_dark = arrow_dark(t.x, t.y);
                let untransformed_dark = arrow_dark(uv.x, uv.y);
                let c = Vec3::from(image.pixels[(y * image.width + x) as usize]);
                let dark = c.max_element() < 0.5;
                both += (dark && expected_dark) as u32;
                either += (dark || expected_dark) as u32;
                both_untransformed += (dark && untransformed_dark) as u32;
                either_untransformed += (dark || untransformed_dark) as u32;
            }
        }
        let overlap = both as f64 / either as f64;
        let overlap_untransformed = both_untransformed as f64 / either_untransformed as f64;
        eprintln!("{name}: overlap {overlap:.3}, untransformed {overlap_untransformed:.3}");
        assert!(
            overlap >= 0.8,
            "{name}: the dark pixels overlap the transformed arrow's by {:.1}% only",
            100.0 * overlap
        );
        assert!(
            overlap_untransformed < 0.5,
            "{name}: the untransformed arrow overlaps the render as well ({:.1}%)",
            100.0 * overlap_untransformed
        );
    }
}

/// The folder of real test assets made by others (`GLINT_ASSETS`, which `.ci/run` sets to
/// `../shared/assets`), or None (with a line on stderr) where it is not set.
fn asset(name: &str) -> Option<PathBuf> {
    let Some(dir) = std::env::var_os("GLINT_ASSETS") else {
        eprintln!("GLINT_ASSETS is not set: {name} skipped");
        return None;
    };
    let path = Path::new(&dir).join(name);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("{} is absent: skipped", path.display());
        None
    }
}

/// The helmet seen from the front (the glTF's +z), `size`² pixels, with `lighting` (TOML
/// lines) and `material` (a `[[meshes]]` line, or none for the file's own materials).
fn render_helmet(helmet: &Path, size: u32, spp: u32, lighting: &str, material: &str) -> Image {
    let scene = helmet_scene(helmet, size, spp, lighting, material);
    common::render_cpu(&scene.kernel_scene(), spp)
}

/// The scene [`render_helmet`] renders.
fn helmet_scene(helmet: &Path, size: u32, spp: u32, lighting: &str, material: &str) -> Scene {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        r#"[camera]
eye = [0.0, 0.0, 3.2]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
[render]
width = {size}
height = {size}
spp = {spp}
{lighting}
{material}
[[meshes]]
file = "{}"
{}
"#,
        helmet.display(),
        if material.is_empty() {
            ""
        } else {
            "material = \"white\""
        }
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Khronos' DamagedHelmet.glb as its author made it (embedded JPEG maps, emissiveFactor
/// [1, 1, 1] with an emissive texture). It used to render as a uniformly glowing white
/// silhouette. Now:
/// - in the dark (black background, no bounces: the camera sees emission only), the glowing
///   pixels are the emissive map's lamps and visor, a small part of the helmet: between 0.2%
///   and 10% of the image (the helmet covers about half of it), while at least one of them
///   glows brighter than 0.5;
/// - under the environment map, the helmet is not white: the mean of the image's central
///   square is under 70% of the same helmet's with a white diffuse material.
#[test]
fn the_damaged_helmet_glows_only_where_its_emissive_map_says() {
    let (Some(helmet), Some(sky)) = (asset("DamagedHelmet.glb"), asset("royal_esplanade_1k.hdr"))
    else {
        return;
    };
    let dark = render_helmet(
        &helmet,
        64,
        4,
        "max_bounces = 0\nbackground = [0.0, 0.0, 0.0]",
        "",
    );
    let glowing = dark
        .pixels
        .iter()
        .filter(|p| p.iter().any(|c| *c > 0.05))
        .count() as f64
        / dark.pixels.len() as f64;
    let brightest = dark.pixels.iter().flatten().fold(0.0f32, |m, c| m.max(*c));
    eprintln!("glowing fraction {glowing:.4}, brightest {brightest}");
    assert!(
        (0.002..0.1).contains(&glowing) && brightest > 0.5,
        "{:.2}% of the pixels glow, the brightest at {brightest}",
        100.0 * glowing
    );
    let lit = format!(
        "max_bounces = 4\n[environment]\nfile = \"{}\"",
        sky.display()
    );
    let centre_mean = |image: &Image| {
        let (n, mut sum) = (image.width, 0.0);
        let mut count = 0;
        for y in n / 4..3 * n / 4 {
            for x in n / 4..3 * n / 4 {
                sum += Vec3::from(image.pixels[(y * n + x) as usize]).element_sum() / 3.0;
                count += 1;
            }
        }
        sum / count as f32
    };
    let authored = centre_mean(&render_helmet(&helmet, 48, 16, &lit, ""));
    let white = centre_mean(&render_helmet(
        &helmet,
        48,
        16,
        &lit,
        "[materials.white]\ntype = \"diffuse\"\ncolor = [1.0, 1.0, 1.0]",
    ));
    eprintln!("centre mean {authored} against {white} for a white helmet");
    assert!(
        authored < 0.7 * white,
        "the helmet's centre averages {authored}, a white one's {white}"
    );
}

/// The helmet's five 2048² maps take 256 MiB as texels, twice lavapipe's 128 MiB storage
/// binding: the GPU splits them over bindings (src/kernel/texels.rs) and traces the CPU's
/// paths, by the criterion of tests/suite/gpu_vs_cpu.rs, at 64² under the environment map: four
/// seeds at one path per pixel (four samples per pixel in all).
#[test]
fn the_damaged_helmet_renders_on_the_gpu_as_on_the_cpu() {
    let (Some(helmet), Some(sky)) = (asset("DamagedHelmet.glb"), asset("royal_esplanade_1k.hdr"))
    else {
        return;
    };
    let Some(ctx) = common::gpu() else { return };
    let lit = format!(
        "max_bounces = 8\n[environment]\nfile = \"{}\"",
        sky.display()
    );
    let mut scene = helmet_scene(&helmet, 64, 1, &lit, "").kernel_scene();
    let mut gpu = glint::gpu::GpuRenderer::new(ctx, &scene).unwrap();
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let bytes = scene.texels.len() as u64 * 16;
    eprintln!(
        "{bytes} bytes of texels, a binding holds {limit}: {:?}",
        gpu.texel_binding()
    );
    assert_eq!(gpu.texel_binding().is_split(), bytes > limit);
    let mut agreement = common::PathAgreement::default();
    for seed in [1, 2, 3, 4] {
        scene.params.seed = seed;
        gpu.set_params(scene.params).unwrap();
        let gpu_image = glint::render::render_image(&mut gpu, 1, 1).unwrap();
        agreement.add(&common::render_cpu(&scene, 1), &gpu_image);
    }
    agreement.check(0.99);
}

/// Khronos' ClearCoatTest (KHR_materials_clearcoat: spheres without a coat, with one, with a
/// partial, rough or normal-mapped one) loads without the unsupported-extension warning (nor
/// one about the coat's normal map, which is rendered) and renders a finite, lit image; its
/// coated materials carry their coat into the kernel, the last row's its own normal map.
#[test]
fn the_clear_coat_test_loads_and_renders() {
    let Some(path) = sample("ClearCoat-glTF/ClearCoatTest.gltf") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("clearcoat.png");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(["render", "--cpu", "--spp", "2", "--width", "96"])
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run glint");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("reads in part or not at all"), "{stderr}");
    assert!(!stderr.contains("clearcoatNormalTexture"), "{stderr}");
    let image = image::open(&out).unwrap().to_rgb8();
    let mean = image.pixels().map(|p| p.0[1] as f64).sum::<f64>() / image.len() as f64 * 3.0;
    assert!(mean > 10.0, "the render is black: mean {mean}");
    let scene = glint::scene::model::load_model(&path, &Default::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .scene;
    let coated = scene
        .kernel_scene()
        .materials
        .iter()
        .filter(|m| m.clearcoat == 1.0)
        .count();
    assert_eq!(coated, 6, "the six *_Coated materials");
    let coat_mapped = scene
        .kernel_scene()
        .materials
        .iter()
        .filter(|m| {
            m.clearcoat > 0.0 && m.clearcoat_normal_texture != glint::kernel::types::NO_TEXTURE
        })
        .count();
    assert!(coat_mapped >= 1, "no material has the coat's normal map");
}
