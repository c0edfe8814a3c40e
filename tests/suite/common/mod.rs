//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod chi2;
pub mod merge_bound;
pub mod probe;
pub mod vdb;

use glint::cpu::integrator::renderer::CpuRenderer;
use glint::gpu::{GpuContext, GpuRenderer};
use glint::image::output::Image;
use glint::kernel::KernelScene;
use glint::render::{render_image, Renderer};
use glint::scene::Scene;
use std::path::Path;
use std::process::Output;
use std::sync::OnceLock;

/// The test GPU: a Vulkan adapter (lavapipe in CI). A missing device fails the test, so a
/// broken driver install cannot pass as green; set GLINT_SKIP_GPU_TESTS=1 to skip on purpose.
pub fn gpu() -> Option<&'static GpuContext> {
    static CTX: OnceLock<Option<GpuContext>> = OnceLock::new();
    CTX.get_or_init(|| {
        if std::env::var_os("GLINT_SKIP_GPU_TESTS").is_some() {
            eprintln!("GLINT_SKIP_GPU_TESTS is set: skipping GPU checks");
            return None;
        }
        let ctx = GpuContext::new().unwrap_or_else(|e| {
            panic!(
                "no Vulkan device ({e}); install mesa-vulkan-drivers or set GLINT_SKIP_GPU_TESTS=1"
            )
        });
        // wgpu must not have fallen back to another API: the GL path renders differently.
        assert_eq!(ctx.adapter_info.backend, wgpu::Backend::Vulkan);
        Some(ctx)
    })
    .as_ref()
}

/// The test GPU where it has ray queries, for the hardware traversal's tests; elsewhere `None`,
/// with the reason on stderr, unless GLINT_REQUIRE_RAY_QUERIES is set (CI's lavapipe, Mesa 25,
/// has them), which makes their absence a failure.
pub fn gpu_with_ray_queries() -> Option<&'static GpuContext> {
    let ctx = gpu()?;
    if ctx.has_ray_queries() {
        return Some(ctx);
    }
    let reason = format!(
        "{} has no ray queries (VK_KHR_ray_query; lavapipe has them from Mesa 25)",
        ctx.device_name()
    );
    if std::env::var_os("GLINT_REQUIRE_RAY_QUERIES").is_some() {
        panic!("{reason}, and GLINT_REQUIRE_RAY_QUERIES is set");
    }
    eprintln!("skipping the hardware traversal's checks: {reason}");
    None
}

pub fn scene(toml: &str) -> Scene {
    Scene::parse(toml, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

pub fn kernel_scene(toml: &str) -> KernelScene {
    scene(toml).kernel_scene()
}

pub fn render_cpu(scene: &KernelScene, spp: u32) -> Image {
    render_image(&mut CpuRenderer::new(scene), spp, spp).unwrap()
}

pub fn render_gpu(ctx: &GpuContext, scene: &KernelScene, spp: u32) -> Image {
    render_image(&mut GpuRenderer::new(ctx, scene).unwrap(), spp, spp).unwrap()
}

/// `spp` samples per pixel in one batch: the image and the variance of each pixel's mean.
pub fn render_with_variance(renderer: &mut dyn Renderer, spp: u32) -> (Image, Image) {
    let image = render_image(renderer, spp, spp).unwrap();
    (image, renderer.read_variance().unwrap())
}

/// A CPU renderer for `scene` and, where there is a GPU, a GPU one: (device name, renderer).
pub fn renderers(scene: &KernelScene) -> Vec<(&'static str, Box<dyn Renderer>)> {
    let mut out: Vec<(&'static str, Box<dyn Renderer>)> =
        vec![("cpu", Box::new(CpuRenderer::new(scene)))];
    if let Some(ctx) = gpu() {
        out.push(("gpu", Box::new(GpuRenderer::new(ctx, scene).unwrap())));
    }
    out
}

/// Renders on the CPU and, where there is a GPU, on the GPU too: (device name, image) pairs.
pub fn render_both(scene: &KernelScene, spp: u32) -> Vec<(&'static str, Image)> {
    let mut out = vec![("cpu", render_cpu(scene, spp))];
    if let Some(ctx) = gpu() {
        out.push(("gpu", render_gpu(ctx, scene, spp)));
    }
    out
}

/// The largest difference of any pixel channel from `value`: the error of a closed-form image
/// (a furnace, a vanishing white object) that is `value` everywhere.
pub fn largest_deviation(image: &Image, value: f32) -> f32 {
    image
        .pixels
        .iter()
        .flatten()
        .map(|c| (c - value).abs())
        .fold(0.0, f32::max)
}

/// The text of a scene file shipped in scenes/.
pub fn shipped_scene_text(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name),
    )
    .unwrap()
}

/// A scene file shipped in scenes/, loaded as a user's would be.
pub fn shipped_scene(name: &str) -> Scene {
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name),
    )
    .unwrap()
}

/// `scene` rendered at `size`², with `seed`.
pub fn sized(scene: Scene, size: u32, seed: u32) -> KernelScene {
    scene
        .with_overrides(&glint::scene::RenderOverrides {
            width: Some(size),
            height: Some(size),
            seed: Some(seed),
            ..Default::default()
        })
        .unwrap()
        .kernel_scene()
}

/// The Cornell box from scenes/cornell.toml.
pub fn cornell() -> Scene {
    shipped_scene("cornell.toml")
}

/// The Cornell box at `size`², with `seed`.
pub fn cornell_at(size: u32, seed: u32) -> KernelScene {
    sized(cornell(), size, seed)
}

/// A diffuse floor of albedo 0.6 under an emitting sphere (radiance 4, radius 1, centre 2 above
/// the origin), seen at 30° elevation through a 0.5° lens, with one bounce: every pixel sees the
/// point below the lamp, whose radiance is ρ L (r/d)² = 0.6 (tests/suite/closed_form.rs derives it).
pub fn floor_under_lamp(size: u32, spp: u32, seed: u32) -> KernelScene {
    kernel_scene(&format!(
        r#"
[camera]
eye = [0.0, 5.0, -8.660254]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 0.5
[render]
width = {size}
height = {size}
spp = {spp}
max_bounces = 1
seed = {seed}
[materials.floor]
type = "diffuse"
color = [0.6, 0.6, 0.6]
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
strength = 4.0
[[quads]]
corner = [-100.0, 0.0, -100.0]
u = [200.0, 0.0, 0.0]
v = [0.0, 0.0, 200.0]
material = "floor"
[[spheres]]
center = [0.0, 2.0, 0.0]
radius = 1.0
material = "lamp"
"#
    ))
}

/// Asserts that at least `min_fraction` of the paths of two renders at 1 spp agree
/// ([`PathAgreement`], one pair).
pub fn assert_paths_agree(cpu: &Image, gpu: &Image, min_fraction: f64) {
    let mut agreement = PathAgreement::default();
    agreement.add(cpu, gpu);
    agreement.check(min_fraction);
}

/// Pixel-by-pixel agreement of a CPU and a GPU render at 1 spp, where each pixel is one path
/// (see tests/suite/gpu_vs_cpu.rs for why a small fraction may differ).
#[derive(Debug, Default)]
pub struct PathAgreement {
    agree: usize,
    lit: usize,
    total: usize,
    worst_agreeing: f32,
}

impl PathAgreement {
    /// Counts the paths whose radiance agrees to 1e-3 of its scale.
    pub fn add(&mut self, cpu: &Image, gpu: &Image) {
        assert_eq!(cpu.pixels.len(), gpu.pixels.len());
        for (a, b) in cpu.pixels.iter().zip(&gpu.pixels) {
            let diff = (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max);
            let scale = a.iter().chain(b).fold(1e-3f32, |m, v| m.max(v.abs()));
            self.total += 1;
            self.lit += a.iter().any(|v| *v > 0.0) as usize;
            if diff <= 1e-3 * scale {
                self.agree += 1;
                self.worst_agreeing = self.worst_agreeing.max(diff / scale);
            }
        }
    }

    /// Asserts that at least `min_fraction` of the paths agree and that most carry light
    /// (a black image would agree trivially).
    pub fn check(&self, min_fraction: f64) {
        let (agree, lit, total) = (self.agree, self.lit, self.total);
        let fraction = agree as f64 / total as f64;
        eprintln!(
            "paths agreeing to 1e-3: {agree}/{total} ({:.2}%), worst relative difference among them {:.2e}; {lit} carry light",
            100.0 * fraction,
            self.worst_agreeing
        );
        assert!(lit > total * 3 / 4, "{lit} of {total} paths carry light");
        assert!(
            fraction >= min_fraction,
            "only {:.2}% of paths agree",
            100.0 * fraction
        );
    }
}

/// `glint render DEVICE SCENE -o OUT` (DEVICE is `--cpu` or `--gpu`), run to its end.
pub fn run_render(device: &str, scene: &Path, out: &Path) -> std::process::Output {
    run_render_with(device, scene, out, &[])
}

/// [`run_render`] with more arguments after the rest.
pub fn run_render_with(
    device: &str,
    scene: &Path,
    out: &Path,
    more: &[&str],
) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(["render", device])
        .arg(scene)
        .arg("-o")
        .arg(out)
        .args(more)
        .output()
        .expect("run glint")
}

/// What a refused render owes its user: exit status 2, one line on stderr (a warning about
/// XDG_RUNTIME_DIR aside) that holds every needle, and no output file.
pub fn assert_refused(run: &std::process::Output, out: &Path, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
        .collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    for needle in needles {
        assert!(lines[0].contains(needle), "{stderr:?} lacks {needle:?}");
    }
    assert!(!out.exists(), "{} was written", out.display());
}

/// Writes a `width`×`height` EXR map with texels `texel(x, y)` (top row first) into `dir`.
pub fn write_map(
    dir: &std::path::Path,
    name: &str,
    width: u32,
    height: u32,
    texel: impl Fn(u32, u32) -> [f32; 3],
) -> std::path::PathBuf {
    let path = dir.join(name);
    image::Rgb32FImage::from_fn(width, height, |x, y| image::Rgb(texel(x, y)))
        .save(&path)
        .unwrap();
    path
}

/// `scene` with light sampling `on` and `seed`, ready for a renderer.
pub fn with_light_sampling(scene: &Scene, on: bool, seed: u32) -> KernelScene {
    scene
        .clone()
        .with_overrides(&glint::scene::RenderOverrides {
            light_sampling: Some(on),
            seed: Some(seed),
            ..Default::default()
        })
        .unwrap()
        .kernel_scene()
}

/// A 16² camera 10 in front of the origin and a white diffuse material: the start of the
/// mesh tests' scenes (tests/suite/mesh.rs, tests/suite/hardware_traversal.rs), which add `[[meshes]]`.
pub const MESH_SCENE_HEADER: &str = r#"
[camera]
eye = [0.0, 0.0, -10.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0

[render]
width = 16
height = 16
spp = 1
max_bounces = 4

[materials.white]
type = "diffuse"
color = [0.5, 0.5, 0.5]
"#;

/// `glint ARGS` run in `dir`, which must succeed (its stderr in the failure message).
pub fn glint_ok(dir: &Path, args: &[&str]) -> Output {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run glint");
    assert!(
        out.status.success(),
        "glint {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A Cornell box's scene text (scenes/cornell.toml's, or a variant of it) with its mirror matte
/// and its ceiling light grown from 130 × 105 to 330 × 305 (centred as before).
pub fn all_diffuse_with_a_larger_light(text: &str) -> String {
    text.replace("type = \"specular\"", "type = \"diffuse\"")
        .replace(
            "corner = [343.0, 554.0, 332.0]",
            "corner = [443.0, 554.0, 432.0]",
        )
        .replace("u = [-130.0, 0.0, 0.0]", "u = [-330.0, 0.0, 0.0]")
        .replace("v = [0.0, 0.0, -105.0]", "v = [0.0, 0.0, -305.0]")
}

/// The Cornell box all diffuse (the mirror sphere matte: a delta vertex would rule strategies
/// out) with a larger light (so that BSDF sampling finds it often enough to test), rendered
/// bidirectionally with two bounces, at `size`² and `seed`: light tracing's splats carry much
/// of the light, and no sample is a firefly.
pub fn bdpt_diffuse_box(size: u32, seed: u32) -> KernelScene {
    let text = all_diffuse_with_a_larger_light(&shipped_scene_text("cornell.toml"));
    let mut scene = sized(self::scene(&text), size, seed);
    scene.params.integrator = glint::kernel::types::INTEGRATOR_BDPT;
    scene.params.max_bounces = 2;
    scene
}
