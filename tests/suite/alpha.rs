//! Alpha on meshes (shaders/geometry/alpha.wgsl ↔ src/cpu/geometry/alpha.rs): MASK cuts holes where a colour
//! texture's alpha says, for camera and shadow rays; BLEND lets rays through with probability
//! 1 − α, for camera and shadow rays; on the CPU (through the BVH and the scan) and on the GPU
//! (through glint's BVH and through ray queries), which trace the same paths.

use crate::common;

use common::{gpu, gpu_with_ray_queries, PathAgreement};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::gpu::{GpuRenderer, Traversal};
use glint::image::output::Image;
use glint::kernel::KernelScene;
use glint::render::{render_image, Renderer};
use glint::scene::Scene;
use std::f32::consts::PI;
use std::path::Path;

/// Image side in pixels. The square mesh's 4×4 texture cells are 8 pixels wide in both
/// views (the camera sees 2.5 units across, the square is 2 units, centred).
const SIZE: u32 = 40;

/// Which cells of the 4×4 alpha texture are solid, top row first: a checker, with the
/// top-left cell cut as well, so a mirrored or turned texture shows as a different pattern.
fn solid(cell_x: u32, cell_y: u32) -> bool {
    (cell_x + cell_y).is_multiple_of(2) && (cell_x, cell_y) != (0, 0)
}

/// A 4×4 RGBA PNG: solid cells alpha 200/255 (0.78), holes 60/255 (0.24), so the cutoff,
/// 0.5, decides them (not only 0 against 1). The colour is irrelevant here.
fn alpha_png(path: &Path) {
    let image = image::RgbaImage::from_fn(4, 4, |x, y| {
        image::Rgba([200, 120, 40, if solid(x, y) { 200 } else { 60 }])
    });
    image.save(path).unwrap();
}

/// A square of two triangles, ±1 around `centre` in the plane spanned by `right` and `up`, its
/// texture's u along `right` and v along `up`: the texture shows upright, unmirrored, to a
/// camera whose image axes are `right` and `up`.
fn square_obj(path: &Path, centre: [f32; 3], right: [f32; 3], up: [f32; 3]) {
    let corner = |a: f32, b: f32| {
        let p: Vec<String> = (0..3)
            .map(|k| format!("{}", centre[k] + a * right[k] + b * up[k]))
            .collect();
        format!("v {}\n", p.join(" "))
    };
    let text = format!(
        "{}{}{}{}vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0)
    );
    std::fs::write(path, text).unwrap();
}

/// The square's material: `alpha` lines (mode, constant, cutoff) on a pbr material whose
/// base colour is the alpha texture, or a constant when `textured` is false.
fn material(alpha: &str, textured: bool) -> String {
    let color = if textured {
        "{ texture = \"alpha.png\" }"
    } else {
        "[0.8, 0.5, 0.2]"
    };
    format!("[materials.leaf]\ntype = \"pbr\"\nbase_color = {color}\n{alpha}\n")
}

/// The camera's view: the square at z = 0 facing a camera at z = 5 that sees 2.5 units across
/// (the square's cells are then 8 pixels), in front of a background of radiance 1, with no
/// scattering (max_bounces = 0): a pixel is 1 where its ray passes, 0 where the square stops it.
fn camera_view(dir: &Path, alpha: &str, textured: bool, spp: u32) -> KernelScene {
    alpha_png(&dir.join("alpha.png"));
    square_obj(
        &dir.join("square.obj"),
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    );
    let vfov = 2.0 * (1.25f32 / 5.0).atan().to_degrees();
    let text = format!(
        "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         vfov = {vfov}\n\n[render]\nwidth = {SIZE}\nheight = {SIZE}\nspp = {spp}\nmax_bounces = 0\n\
         background = [1.0, 1.0, 1.0]\n\n{}\n[[meshes]]\nfile = \"square.obj\"\nmaterial = \"leaf\"\n",
        material(alpha, textured)
    );
    load(dir, &text)
}

/// Albedo of the floor in the shadow view.
const FLOOR_ALBEDO: f32 = 0.5;
/// Irradiance of its directional light.
const SUN: f32 = 2.0;

/// The shadow view: a camera 2 above a floor looking straight down, seeing 2.5 units across;
/// the square 3 above the floor, above and behind the camera (which never sees it), under a
/// directional light shining straight down, with a black background. A floor pixel is
/// ρ E / π where the light passes the square, 0 where the square's shadow falls; the square's
/// texture is upright in the image (u along +x, v along −z, the image's up).
fn shadow_view(dir: &Path, alpha: &str, textured: bool, spp: u32) -> KernelScene {
    alpha_png(&dir.join("alpha.png"));
    square_obj(
        &dir.join("square.obj"),
        [0.0, 3.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
    );
    let vfov = 2.0 * (1.25f32 / 2.0).atan().to_degrees();
    let text = format!(
        "[camera]\neye = [0.0, 2.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
         vfov = {vfov}\n\n[render]\nwidth = {SIZE}\nheight = {SIZE}\nspp = {spp}\nmax_bounces = 1\n\
         background = [0.0, 0.0, 0.0]\n\n{}\n[materials.floor]\ntype = \"diffuse\"\n\
         color = [{FLOOR_ALBEDO}, {FLOOR_ALBEDO}, {FLOOR_ALBEDO}]\n\n\
         [[quads]]\ncorner = [-5.0, 0.0, -5.0]\nu = [0.0, 0.0, 10.0]\nv = [10.0, 0.0, 0.0]\n\
         material = \"floor\"\n\n[[meshes]]\nfile = \"square.obj\"\nmaterial = \"leaf\"\n\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nintensity = {SUN}\n",
        material(alpha, textured)
    );
    load(dir, &text)
}

fn load(dir: &Path, text: &str) -> KernelScene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene()
}

/// `scene` rendered by every traversal there is: the CPU through the BVH and through the scan
/// (the scene's BVH removed), and on the GPU through glint's BVH and through ray queries.
fn render_everywhere(scene: &KernelScene, spp: u32) -> Vec<(&'static str, Image)> {
    assert!(
        !scene.bvh_nodes.is_empty(),
        "meshes are traced through a BVH"
    );
    let mut scan = scene.clone();
    scan.bvh_nodes.clear();
    scan.bvh_primitives.clear();
    let mut out = vec![
        ("cpu bvh", render(&mut CpuRenderer::new(scene), spp)),
        ("cpu scan", render(&mut CpuRenderer::new(&scan), spp)),
    ];
    if let Some(ctx) = gpu() {
        let mut software = GpuRenderer::with_traversal(ctx, scene, Traversal::Software).unwrap();
        out.push(("gpu software", render(&mut software, spp)));
    }
    if let Some(ctx) = gpu_with_ray_queries() {
        let mut hardware = GpuRenderer::with_traversal(ctx, scene, Traversal::Hardware).unwrap();
        out.push(("gpu hardware", render(&mut hardware, spp)));
    }
    out
}

fn render(renderer: &mut dyn Renderer, spp: u32) -> Image {
    render_image(renderer, spp, spp).unwrap()
}

/// The pixel (column, row from the top) at the centre of texture cell (x, y), top row first,
/// and one at the image's corner, outside the square.
fn cell_pixel(x: u32, y: u32) -> (u32, u32) {
    (4 + 8 * x + 4, 4 + 8 * y + 4)
}

fn pixel(image: &Image, (x, y): (u32, u32)) -> f32 {
    image.pixels[(y * image.width + x) as usize][0]
}

/// MASK: camera rays pass exactly through the texture's holes. A pixel at the centre of each
/// cell (4 pixels from its edges: no sample reaches another cell) is the background's 1 in a
/// hole and 0 where the square is solid, on every traversal and device; outside the square it
/// is 1.
#[test]
fn mask_cuts_the_textures_holes_for_camera_rays() {
    let dir = tempfile::tempdir().unwrap();
    let scene = camera_view(
        dir.path(),
        "alpha_mode = \"mask\"\nalpha_cutoff = 0.5",
        true,
        4,
    );
    for (device, image) in render_everywhere(&scene, 4) {
        for y in 0..4 {
            for x in 0..4 {
                let expected = if solid(x, y) { 0.0 } else { 1.0 };
                let got = pixel(&image, cell_pixel(x, y));
                assert_eq!(got, expected, "{device}: cell ({x}, {y}) is {got}");
            }
        }
        assert_eq!(pixel(&image, (1, 1)), 1.0, "{device}: outside the square");
    }
}

/// MASK on shadow rays: the floor under the square is lit exactly through its holes, ρ E / π
/// (no variance: a delta light, one bounce, a black sky), and dark under its solid cells.
#[test]
fn mask_cuts_the_textures_holes_for_shadow_rays() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shadow_view(dir.path(), "alpha_mode = \"mask\"", true, 4);
    let lit = FLOOR_ALBEDO * SUN / PI;
    for (device, image) in render_everywhere(&scene, 4) {
        for y in 0..4 {
            for x in 0..4 {
                let expected = if solid(x, y) { 0.0 } else { lit };
                let got = pixel(&image, cell_pixel(x, y));
                assert!(
                    (got - expected).abs() <= 1e-4 * lit,
                    "{device}: floor under cell ({x}, {y}) is {got}, expected {expected}"
                );
            }
        }
        let outside = pixel(&image, (1, 1));
        assert!((outside - lit).abs() <= 1e-4 * lit, "{device}: {outside}");
    }
}

/// The constant alpha multiplies the texture's and the cutoff decides: with alpha = 0.5 the
/// solid cells' 0.78 becomes 0.39, below a cutoff of 0.5 (every cell a hole) and above one of
/// 0.3 (the pattern again). OPAQUE ignores both: no holes at all.
#[test]
fn constant_alpha_and_cutoff_decide_with_the_texture_and_opaque_ignores_them() {
    let cases = [
        ("alpha_mode = \"mask\"\nalpha = 0.5", 0),
        ("alpha_mode = \"mask\"\nalpha = 0.5\nalpha_cutoff = 0.3", 1),
        ("alpha_mode = \"opaque\"", 2),
    ];
    for (alpha, case) in cases {
        let dir = tempfile::tempdir().unwrap();
        let scene = camera_view(dir.path(), alpha, true, 1);
        let image = render(&mut CpuRenderer::new(&scene), 1);
        for y in 0..4 {
            for x in 0..4 {
                let hole = match case {
                    0 => true,
                    1 => !solid(x, y),
                    _ => false,
                };
                let got = pixel(&image, cell_pixel(x, y));
                assert_eq!(got, hole as u32 as f32, "{alpha:?}: cell ({x}, {y})");
            }
        }
    }
}

/// The fraction of paths a BLEND square of α = 0.3 lets through, in the square's central
/// 24×24 pixels, `spp` samples each: each path passes with probability 0.7, independently
/// (each decision hashes its own pixel, sample and segment), so the count of passes is
/// binomial and the fraction has standard error √(0.7 · 0.3 / n), n = 576 · spp. |Z| < 4.5
/// fails a correct renderer once in 1.5·10⁵ runs of one check; a BLEND read as MASK or
/// OPAQUE gives 0 or 1, and a decision that ignored α (or used α for 1 − α) 0.5 or 0.3, far
/// beyond it (Z > 50 at n = 36864).
fn assert_passes_seven_tenths(device: &str, image: &Image, spp: u32, lit: f32) {
    let mut sum = 0.0f64;
    for y in 8..32 {
        for x in 8..32 {
            sum += (pixel(image, (x, y)) / lit) as f64;
        }
    }
    let n = (24 * 24 * spp) as f64;
    let fraction = sum / (24.0 * 24.0);
    let z = (fraction - 0.7) / (0.7 * 0.3 / n).sqrt();
    eprintln!("{device}: passed {fraction:.4} of {n} paths (Z = {z:.2})");
    assert!(z.abs() < 4.5, "{device}: {fraction} passed, Z = {z}");
}

/// BLEND, α = 0.3, camera rays: 0.7 of them reach the background behind the square.
#[test]
fn blend_lets_seven_tenths_of_camera_rays_through() {
    let spp = 64;
    let dir = tempfile::tempdir().unwrap();
    let scene = camera_view(
        dir.path(),
        "alpha_mode = \"blend\"\nalpha = 0.3",
        false,
        spp,
    );
    for (device, image) in render_everywhere(&scene, spp) {
        assert_passes_seven_tenths(device, &image, spp, 1.0);
    }
}

/// BLEND, α = 0.3, shadow rays: the floor under the square gets 0.7 of the light.
#[test]
fn blend_lets_seven_tenths_of_shadow_rays_through() {
    let spp = 64;
    let dir = tempfile::tempdir().unwrap();
    let scene = shadow_view(
        dir.path(),
        "alpha_mode = \"blend\"\nalpha = 0.3",
        false,
        spp,
    );
    for (device, image) in render_everywhere(&scene, spp) {
        assert_passes_seven_tenths(device, &image, spp, FLOOR_ALBEDO * SUN / PI);
    }
}

/// A scene with both modes and light bouncing between them: a masked square (textured) and a
/// blended one (α = 0.4, textured: its alpha times the texture's) over a floor, lit by a
/// quad emitter, a directional light and a point light (the three kinds of shadow test:
/// first_hit_is, escapes and a bounded search), 4 bounces, seen at an angle.
fn mixed_scene(dir: &Path, seed: u32) -> KernelScene {
    alpha_png(&dir.join("alpha.png"));
    square_obj(
        &dir.join("mask.obj"),
        [-0.6, 1.0, 0.0],
        [0.8, 0.0, 0.0],
        [0.0, 0.0, -0.8],
    );
    square_obj(
        &dir.join("blend.obj"),
        [0.6, 0.8, 0.3],
        [0.7, 0.3, 0.0],
        [0.0, 0.5, -0.7],
    );
    let text = format!(
        "[camera]\neye = [0.5, 3.0, 4.0]\ntarget = [0.0, 0.5, 0.0]\nup = [0.0, 1.0, 0.0]\nvfov = 45.0\n\n\
         [render]\nwidth = 48\nheight = 48\nspp = 1\nmax_bounces = 4\nseed = {seed}\n\
         background = [0.2, 0.25, 0.3]\n\n\
         [materials.mask]\ntype = \"pbr\"\nbase_color = {{ texture = \"alpha.png\" }}\nroughness = 0.6\n\
         alpha_mode = \"mask\"\n\n\
         [materials.blend]\ntype = \"diffuse\"\ncolor = {{ texture = \"alpha.png\" }}\n\
         alpha_mode = \"blend\"\nalpha = 0.4\n\n\
         [materials.floor]\ntype = \"diffuse\"\ncolor = [0.6, 0.6, 0.6]\n\n\
         [materials.lamp]\ntype = \"diffuse\"\ncolor = [0.0, 0.0, 0.0]\nemission = [4.0, 4.0, 4.0]\n\n\
         [[quads]]\ncorner = [-4.0, 0.0, -4.0]\nu = [0.0, 0.0, 8.0]\nv = [8.0, 0.0, 0.0]\nmaterial = \"floor\"\n\n\
         [[quads]]\ncorner = [-0.5, 3.0, -0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 0.0, 1.0]\nmaterial = \"lamp\"\n\n\
         [[meshes]]\nfile = \"mask.obj\"\nmaterial = \"mask\"\n\n\
         [[meshes]]\nfile = \"blend.obj\"\nmaterial = \"blend\"\n\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0.3, -1.0, -0.2]\nintensity = 1.5\n\n\
         [[lights]]\ntype = \"point\"\nposition = [0.2, 2.2, -0.4]\nintensity = 2.0\n"
    );
    load(dir, &text)
}

/// GPU ≡ CPU on alpha: at 1 spp each pixel is one path, and the GPU's traversals (glint's BVH
/// and ray queries) trace the CPU's paths, alpha decisions included (the 99% bound is
/// tests/suite/gpu_vs_cpu.rs's, for the same reasons); and the two GPU traversals each other's.
#[test]
fn gpu_traversals_and_cpu_trace_the_same_paths_through_alpha() {
    let Some(ctx) = gpu() else { return };
    let hardware_ctx = gpu_with_ray_queries();
    let mut software = PathAgreement::default();
    let mut hardware = PathAgreement::default();
    let mut between = PathAgreement::default();
    for seed in [3, 4] {
        let dir = tempfile::tempdir().unwrap();
        let scene = mixed_scene(dir.path(), seed);
        let cpu = render(&mut CpuRenderer::new(&scene), 1);
        let soft = render(
            &mut GpuRenderer::with_traversal(ctx, &scene, Traversal::Software).unwrap(),
            1,
        );
        software.add(&cpu, &soft);
        if let Some(hctx) = hardware_ctx {
            let hard = render(
                &mut GpuRenderer::with_traversal(hctx, &scene, Traversal::Hardware).unwrap(),
                1,
            );
            hardware.add(&cpu, &hard);
            between.add(&soft, &hard);
        }
    }
    eprint!("software BVH against the CPU: ");
    software.check(0.99);
    if hardware_ctx.is_some() {
        eprint!("ray queries against the CPU: ");
        hardware.check(0.99);
        eprint!("ray queries against the software BVH: ");
        between.check(0.99);
    }
}
