//! Heterogeneous media from OpenVDB density grids (`[media.NAME] grid`, `[[volumes]]`):
//! delta tracking's free flights and ratio tracking's transmittance against a ray-marched
//! reference in a smooth grid; a constant grid rendering as the homogeneous medium of its
//! coefficients; the GPU tracing the CPU's paths through a grid; and the named refusals of
//! bad files, truncated ones among them. The .vdb files are written by `common::vdb`.
//!
//! Statistical checks: each estimate is the mean of n independent samples, compared with its
//! reference in units of its standard error (the samples' standard deviation over √n, or for
//! images the per-pixel variances of the mean summed over the pixels, over their count
//! squared). A correct estimator's z is then close to standard normal (n is in the thousands),
//! and |z| < 5 fails with probability below 10⁻⁶ per check; the seeds are fixed, so a run
//! passes or fails alike every time. A wrong weight (a channel's pdf in place of the
//! mixture's, a majorant left out of the null-collision probability, a missed block) biases
//! the estimates by tens of standard errors.

use crate::common;
use common::vdb::{write_vdb, VdbGrid};
use common::{gpu, render_cpu, render_gpu, render_with_variance, renderers, PathAgreement};
use glam::Vec3;
use glint::cpu::core::ray::Ray;
use glint::cpu::core::rng::Rng;
use glint::cpu::media::grid::{
    density, dir_to_grid, grid_free_flight, grid_transmittance, to_grid, Grids,
};
use glint::kernel::types::{Medium, NO_GRID};
use glint::kernel::KernelScene;
use glint::scene::Scene;
use std::path::Path;

/// Parses `toml` as a scene file in `dir`.
fn parse_in(dir: &Path, toml: &str) -> Result<Scene, String> {
    Scene::parse(toml, &dir.join("scene.toml")).map_err(|e| e.to_string())
}

/// A scene with a camera looking at the origin from −z, a sun and a grey sky, and `more`.
fn scene_text(more: &str, size: u32, spp: u32, seed: u32) -> String {
    scene_text_from([0.0, 0.4, -4.0], "", more, size, spp, seed)
}

/// [`scene_text`] with the camera's eye at `eye`, looking along +z, and `camera` added to its
/// table.
fn scene_text_from(
    eye: [f32; 3],
    camera: &str,
    more: &str,
    size: u32,
    spp: u32,
    seed: u32,
) -> String {
    let target = [eye[0], eye[1] - 0.1, eye[2] + 1.0];
    format!(
        r#"
[camera]
{camera}
eye = {eye:?}
target = {target:?}
up = [0.0, 1.0, 0.0]
vfov = 40
[render]
width = {size}
height = {size}
spp = {spp}
max_bounces = 4
seed = {seed}
background = [0.2, 0.25, 0.3]
[[lights]]
type = "directional"
direction = [-0.5, -1.0, 0.3]
intensity = 3.0
{more}
"#
    )
}

/// A smooth grid of 24³ voxels: a Gaussian blob over a low floor, empty where x < 6 (whole
/// empty majorant blocks for the walk to step over).
pub(crate) fn smooth_grid() -> VdbGrid {
    let mut g = VdbGrid::float("density", [24, 24, 24], |x, y, z| {
        if x < 6 {
            return 0.0;
        }
        let d = Vec3::new(x as f32 - 14.0, y as f32 - 12.0, z as f32 - 11.0);
        0.1 + 2.5 * (-d.length_squared() / (2.0 * 5.0 * 5.0)).exp()
    });
    g.translation = [-12.0, -12.0, -12.0];
    g
}

/// The kernel scene, `size` pixels square, of a volume of `grid` (written to `dir`) with
/// `medium`'s coefficients, scaled by `scale`.
pub(crate) fn grid_scene(
    dir: &Path,
    grid: &VdbGrid,
    medium: &str,
    scale: f32,
    size: u32,
    spp: u32,
    seed: u32,
) -> KernelScene {
    std::fs::write(dir.join("grid.vdb"), write_vdb(std::slice::from_ref(grid))).unwrap();
    let more = format!(
        "[media.smoke]\ngrid = \"grid.vdb\"\n{medium}\n[[volumes]]\nmedium = \"smoke\"\n\
         scale = {scale}\nrotate = [0.0, 20.0, 0.0]\n"
    );
    parse_in(dir, &scene_text(&more, size, spp, seed))
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene()
}

/// The scene's grid medium.
fn grid_medium(scene: &KernelScene) -> Medium {
    let p = &scene.params;
    *p.media[..p.medium_count as usize]
        .iter()
        .find(|m| m.grid != NO_GRID)
        .expect("a grid medium")
}

/// Mean and standard error of samples.
fn mean_and_error(samples: &[f64]) -> (f64, f64) {
    let n = samples.len() as f64;
    let mean = samples.iter().sum::<f64>() / n;
    let var = samples.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn assert_z(name: &str, samples: &[f64], want: f64) {
    let (mean, error) = mean_and_error(samples);
    let z = (mean - want) / error.max(1e-12);
    eprintln!("{name}: mean {mean:.5} ± {error:.5}, reference {want:.5}, z = {z:.2}");
    assert!(z.abs() < 5.0, "{name}: z = {z:.2}");
}

/// Delta tracking (free flights) and ratio tracking (transmittance) through the smooth grid
/// with chromatic coefficients, along three rays (one along an axis, two oblique, one of them
/// through the empty blocks), against a midpoint rule of 20000 steps over the same trilinear
/// density: per channel, the transmittance through the grid, the chance of passing without a
/// real collision (delta tracking's weight where it does not scatter), and the scattered
/// weight before the segment's middle, ∫₀^{t½} σs(t) T(t) dt.
#[test]
fn delta_and_ratio_tracking_match_a_ray_marched_grid() {
    let dir = tempfile::tempdir().unwrap();
    let scene = grid_scene(
        dir.path(),
        &smooth_grid(),
        "sigma_a = [0.1, 0.3, 0.6]\nsigma_s = [0.2, 0.3, 0.6]",
        0.1,
        4,
        1,
        1,
    );
    let m = grid_medium(&scene);
    let grids = Grids {
        grids: &scene.grids,
        voxels: &scene.grid_voxels,
    };
    let g = &scene.grids[m.grid as usize];
    let sigma_t = Vec3::from(m.sigma_t);
    let sigma_s = Vec3::from(m.sigma_s);
    let rays = [
        (Vec3::new(-3.0, 0.05, 0.02), Vec3::X),
        (Vec3::new(-2.0, -1.5, -2.5), Vec3::new(0.6, 0.45, 0.8)),
        (Vec3::new(2.0, 2.0, -2.0), Vec3::new(-0.6, -0.55, 0.5)),
    ];
    let n = 20000;
    for (k, &(origin, dir)) in rays.iter().enumerate() {
        let ray = Ray {
            origin,
            dir: dir.normalize(),
        };
        let t_max = 6.0;
        // The reference: the optical depth per unit σ̂t, marched.
        let steps = 20000;
        let h = t_max / steps as f32;
        let o = to_grid(g, ray.origin);
        let d = dir_to_grid(g, ray.dir);
        let mut depth = 0.0f64;
        let mut scattered_before_half = [0.0f64; 3];
        let t_half = 3.0;
        for i in 0..steps {
            let t = (i as f32 + 0.5) * h;
            let inside = (0..3).all(|a| {
                let p = o[a] + t * d[a];
                p >= 0.0 && p <= g.dims[a] as f32
            });
            let rho = if inside {
                density(grids.voxels, g, o + t * d) as f64
            } else {
                0.0
            };
            let mid_depth = depth + 0.5 * rho * h as f64;
            if t < t_half {
                for c in 0..3 {
                    scattered_before_half[c] += sigma_s[c] as f64
                        * rho
                        * (-(sigma_t[c] as f64) * mid_depth).exp()
                        * h as f64;
                }
            }
            depth += rho * h as f64;
        }
        assert!(depth > 0.3, "ray {k} misses the grid (depth {depth})");
        let through: [f64; 3] = std::array::from_fn(|c| (-(sigma_t[c] as f64) * depth).exp());
        let mut ratio = vec![[0.0f64; 3]; n];
        let mut passed = vec![[0.0f64; 3]; n];
        let mut early = vec![[0.0f64; 3]; n];
        for i in 0..n {
            let mut rng = Rng::with_sampler(i as u32, 0, 11, 77 + k as u32, 0);
            let tr = grid_transmittance(grids, &m, &ray, t_max, &mut rng);
            let mut rng = Rng::with_sampler(i as u32, 0, 12, 77 + k as u32, 0);
            let flight = grid_free_flight(grids, &m, &ray, t_max, &mut rng);
            for c in 0..3 {
                ratio[i][c] = tr[c] as f64;
                if flight.scattered {
                    if flight.t < t_half {
                        early[i][c] = flight.weight[c] as f64;
                    }
                } else {
                    passed[i][c] = flight.weight[c] as f64;
                }
            }
        }
        for c in 0..3 {
            let column = |v: &[[f64; 3]]| v.iter().map(|x| x[c]).collect::<Vec<_>>();
            assert_z(
                &format!("ray {k}, channel {c}: ratio tracking"),
                &column(&ratio),
                through[c],
            );
            assert_z(
                &format!("ray {k}, channel {c}: delta tracking passes"),
                &column(&passed),
                through[c],
            );
            assert_z(
                &format!("ray {k}, channel {c}: delta tracking scatters before t = {t_half}"),
                &column(&early),
                scattered_before_half[c],
            );
        }
    }
}

/// A closed box mesh over [lo, hi], its faces wound outwards, as OBJ.
fn box_obj(lo: f32, hi: f32) -> String {
    let mut out = String::new();
    for i in 0..8 {
        let c = |a: usize| if i >> a & 1 == 1 { hi } else { lo };
        out += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    // Faces by corner bits (x = 1, y = 2, z = 4), counter-clockwise from outside.
    for f in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        let f = f.map(|i| i + 1);
        out += &format!(
            "f {} {} {}\nf {} {} {}\n",
            f[0], f[1], f[2], f[0], f[2], f[3]
        );
    }
    out
}

/// A grid of constant density 2 over 8³ voxels, placed as the box [−1, 1]³ and turned, renders
/// as that box filled with the homogeneous medium of twice its coefficients (chromatic, so
/// spectral MIS is in play), on both devices; the homogeneous box is rendered on the CPU with
/// another seed, so the two means are independent.
#[test]
fn a_constant_grid_renders_as_the_homogeneous_medium() {
    constant_grid_against_homogeneous([0.0, 0.4, -4.0], &["cpu", "gpu"]);
}

/// The same with the camera inside the volume's box: the camera starts in the grid medium
/// (found from the eye, as no scene file can name a volume's medium), as a camera inside the
/// homogeneous box declared with `[camera] medium` does. Without that the view would be clear
/// until rays left the box and met it again. The CPU only: the kernel starts in
/// `Params::camera_medium` the same way whichever medium that is (media.rs tests it).
#[test]
fn a_camera_inside_a_volume_starts_in_its_medium() {
    constant_grid_against_homogeneous([0.15, 0.1, -0.4], &["cpu"]);
}

/// Z-tests of the image mean per channel: the constant grid seen from `eye`, on `devices`,
/// against the homogeneous box; the standard errors are from each render's per-pixel
/// variance of the mean (pixels are independent: var of the image mean is Σ var / n²).
fn constant_grid_against_homogeneous(eye: [f32; 3], devices: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let mut grid = VdbGrid::float("density", [8, 8, 8], |_, _, _| 2.0);
    grid.translation = [-3.5; 3];
    let coefficients = "sigma_a = [0.1, 0.25, 0.05]\nsigma_s = [0.6, 0.3, 0.9]\ng = 0.3";
    let (size, spp) = (16, 256);
    std::fs::write(
        dir.path().join("grid.vdb"),
        write_vdb(std::slice::from_ref(&grid)),
    )
    .unwrap();
    let volume = format!(
        "[media.smoke]\ngrid = \"grid.vdb\"\n{coefficients}\n[[volumes]]\nmedium = \"smoke\"\n\
         scale = 0.25\nrotate = [0.0, 20.0, 0.0]\n"
    );
    let scene = parse_in(dir.path(), &scene_text_from(eye, "", &volume, size, spp, 1))
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene();
    std::fs::write(dir.path().join("box.obj"), box_obj(-1.0, 1.0)).unwrap();
    let inside = eye.iter().all(|c| c.abs() < 0.9);
    let camera_medium = if inside { "medium = \"fog\"" } else { "" };
    let homogeneous = "[materials.boundary]\ntype = \"interface\"\n[media.fog]\n\
         sigma_a = [0.2, 0.5, 0.1]\nsigma_s = [1.2, 0.6, 1.8]\ng = 0.3\n\
         [[meshes]]\nfile = \"box.obj\"\nmaterial = \"boundary\"\nmedium = \"fog\"\n\
         rotate = [0.0, 20.0, 0.0]\n";
    let reference_text = scene_text_from(eye, camera_medium, homogeneous, size, spp, 2);
    let reference = parse_in(dir.path(), &reference_text)
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene();
    let mut cpu = glint::cpu::integrator::renderer::CpuRenderer::new(&reference);
    let (want, want_variance) = render_with_variance(&mut cpu, spp);
    let n = want.pixels.len() as f64;
    let mean = |image: &glint::image::output::Image, c: usize| {
        image.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n
    };
    let var = |image: &glint::image::output::Image, c: usize| {
        image.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / (n * n)
    };
    let mut under_test: Vec<(&str, Box<dyn glint::render::Renderer>)> = vec![(
        "cpu",
        Box::new(glint::cpu::integrator::renderer::CpuRenderer::new(&scene)),
    )];
    if devices.contains(&"gpu") {
        under_test.extend(renderers(&scene).into_iter().filter(|(d, _)| *d == "gpu"));
    }
    for (device, mut renderer) in under_test {
        let (image, variance) = render_with_variance(renderer.as_mut(), spp);
        for c in 0..3 {
            let (a, b) = (mean(&image, c), mean(&want, c));
            let z = (a - b)
                / (var(&variance, c) + var(&want_variance, c))
                    .sqrt()
                    .max(1e-12);
            eprintln!("{device}, channel {c}: grid {a:.5}, homogeneous {b:.5}, z = {z:.2}");
            assert!(z.abs() < 5.0, "{device}, channel {c}: z = {z:.2}");
            assert!(b > 0.05, "the medium is lit and seen: {b}");
        }
    }
}

/// The smooth grid, lit by the sun under the sky, at one path per pixel: free flights by
/// delta tracking, medium vertices whose shadow rays ratio track, phase sampling; the same
/// paths on both devices to the bound of the fog Cornell box (gpu_vs_cpu.rs; a tentative
/// collision's accept test, like a Russian roulette draw, may land within an ulp of its
/// threshold).
#[test]
fn gpu_and_cpu_trace_the_same_paths_through_a_grid() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let mut agreement = PathAgreement::default();
    for seed in [3, 4] {
        let scene = grid_scene(
            dir.path(),
            &smooth_grid(),
            "color = [0.9, 0.8, 0.6]\ndensity = 8.0\ng = 0.5",
            0.1,
            48,
            1,
            seed,
        );
        agreement.add(&render_cpu(&scene, 1), &render_gpu(ctx, &scene, 1));
    }
    agreement.check(0.99);
}

/// The refusals, each naming the field and the file: a missing file, one that is not a VDB,
/// an OpenVDB stream without grid offsets, a vector grid, a grid name the file lacks, negative and non-finite densities, a grid too
/// large for one GPU binding, a grid medium filling a sphere, a volume of a homogeneous
/// medium, a camera inside two volumes (or one and a declared medium), and every truncation of a valid file (an error, never a panic); a half-float grid
/// reads.
#[test]
fn bad_grids_are_refused_with_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path();
    let refuse = |file: &str, extra: &str, needles: &[&str]| {
        let more = format!(
            "[media.smoke]\ngrid = \"{file}\"\nsigma_s = [1.0, 1.0, 1.0]\n{extra}\n\
             [[volumes]]\nmedium = \"smoke\"\n"
        );
        let e = parse_in(path, &scene_text(&more, 8, 1, 1))
            .err()
            .unwrap_or_else(|| {
                panic!("{file} {extra}: accepted");
            });
        for needle in needles {
            assert!(e.contains(needle), "{file}: {needle:?} not in: {e}");
        }
    };
    refuse(
        "absent.vdb",
        "",
        &["media.smoke.grid", "absent.vdb", "cannot read"],
    );
    std::fs::write(path.join("text.vdb"), "not a vdb at all").unwrap();
    refuse(
        "text.vdb",
        "",
        &["media.smoke.grid", "text.vdb", "not an OpenVDB file"],
    );
    let mut vector = VdbGrid::float("density", [4, 4, 4], |_, _, _| 1.0);
    vector.grid_type = "Tree_vec3s_5_4_3".into();
    std::fs::write(path.join("vector.vdb"), write_vdb(&[vector])).unwrap();
    refuse(
        "vector.vdb",
        "",
        &[
            "media.smoke.grid",
            "vector.vdb",
            "Tree_vec3s_5_4_3",
            "float grids",
        ],
    );
    let smoke = write_vdb(&[VdbGrid::float("smoke", [4, 4, 4], |_, _, _| 1.0)]);
    std::fs::write(path.join("named.vdb"), &smoke).unwrap();
    refuse(
        "named.vdb",
        "",
        &["no grid named \"density\"", "\"smoke\" (Tree_float_5_4_3)"],
    );
    refuse(
        "named.vdb",
        "grid_name = \"heat\"",
        &["no grid named \"heat\""],
    );
    let negative = VdbGrid::float(
        "density",
        [4, 4, 4],
        |x, _, _| if x == 2 { -0.5 } else { 1.0 },
    );
    std::fs::write(path.join("negative.vdb"), write_vdb(&[negative])).unwrap();
    refuse(
        "negative.vdb",
        "",
        &["negative density (-0.5)", "negative.vdb"],
    );
    let nan = VdbGrid::float(
        "density",
        [4, 4, 4],
        |x, _, _| if x == 2 { f32::NAN } else { 1.0 },
    );
    std::fs::write(path.join("nan.vdb"), write_vdb(&[nan])).unwrap();
    refuse("nan.vdb", "", &["not finite", "nan.vdb"]);
    // A camera starts in one medium: not inside two volumes' boxes, nor inside one and a
    // declared medium. (The 4³ grid's box moved over the eye at [0, 0.4, −4].)
    std::fs::write(
        path.join("small.vdb"),
        write_vdb(&[VdbGrid::float("density", [4, 4, 4], |_, _, _| 1.0)]),
    )
    .unwrap();
    let over_eye = "[[volumes]]\nmedium = \"smoke\"\ntranslate = [-2.0, -1.6, -6.0]\n";
    let two = format!(
        "[media.smoke]\ngrid = \"small.vdb\"\nsigma_s = [1.0, 1.0, 1.0]\n{over_eye}{over_eye}"
    );
    let e = parse_in(path, &scene_text(&two, 8, 1, 1)).unwrap_err();
    assert!(
        e.contains("camera.eye") && e.contains("smoke (volumes[0]) and smoke (volumes[1])"),
        "{e}"
    );
    let declared = format!(
        "[media.fog]\nsigma_s = [0.1, 0.1, 0.1]\n[media.smoke]\ngrid = \"small.vdb\"\n\
         sigma_s = [1.0, 1.0, 1.0]\n{over_eye}"
    );
    let e = parse_in(
        path,
        &scene_text_from([0.0, 0.4, -4.0], "medium = \"fog\"", &declared, 8, 1, 1),
    )
    .unwrap_err();
    assert!(
        e.contains("camera.eye") && e.contains("volumes[0]") && e.contains("\"fog\""),
        "{e}"
    );
    let mut large = VdbGrid::float("density", [1, 1, 1], |_, _, _| 1.0);
    large.voxels.insert([4000, 4000, 4000], 1.0);
    std::fs::write(path.join("large.vdb"), write_vdb(&[large])).unwrap();
    refuse(
        "large.vdb",
        "",
        &["4001 × 4001 × 4001 voxels", "MiB one GPU binding holds"],
    );

    let mut stream = write_vdb(&[smooth_grid()]);
    stream[20] = 0;
    std::fs::write(path.join("stream.vdb"), stream).unwrap();
    refuse("stream.vdb", "", &["stream.vdb", "without grid offsets"]);

    // Placing: a grid medium fills no sphere; a volume needs a grid medium.
    std::fs::write(path.join("ok.vdb"), write_vdb(&[smooth_grid()])).unwrap();
    let e = parse_in(
        path,
        &scene_text(
            "[materials.b]\ntype = \"interface\"\n[media.smoke]\ngrid = \"ok.vdb\"\n\
             sigma_s = [1.0, 1.0, 1.0]\n[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\n\
             material = \"b\"\nmedium = \"smoke\"\n",
            8,
            1,
            1,
        ),
    )
    .unwrap_err();
    assert!(
        e.contains("spheres[0].medium") && e.contains("[[volumes]]"),
        "{e}"
    );
    let e = parse_in(
        path,
        &scene_text(
            "[media.fog]\nsigma_s = [1.0, 1.0, 1.0]\n[[volumes]]\nmedium = \"fog\"\n",
            8,
            1,
            1,
        ),
    )
    .unwrap_err();
    assert!(
        e.contains("volumes[0].medium") && e.contains("no density grid"),
        "{e}"
    );

    // A half-float grid reads, its values rounded to 16 bits.
    let mut half = VdbGrid::float("density", [4, 4, 4], |x, _, _| 1.0 + x as f32 / 3.0);
    half.half = true;
    let parsed =
        glint::scene::grid::parse_density_grid(&write_vdb(&[half]), "density", "half").unwrap();
    assert_eq!(parsed.dims, [4, 4, 4]);
    assert!(
        (parsed.density[1] - 4.0 / 3.0).abs() < 1e-3,
        "{}",
        parsed.density[1]
    );

    // A type named as half floats without the metadata that says so (which the reader goes
    // by) is refused, not read as 32-bit floats.
    let mut unmarked = VdbGrid::float("density", [2, 2, 2], |_, _, _| 1.0);
    unmarked.grid_type = "Tree_float_5_4_3_HalfFloat".into();
    let e = glint::scene::grid::parse_density_grid(&write_vdb(&[unmarked]), "density", "unmarked")
        .unwrap_err();
    assert!(e.contains("is_saved_as_half_float"), "{e}");

    // Every truncation of a valid file is an error, none a panic (one in 7 lengths, and the
    // last 64: the file is some 6 KB).
    let whole = write_vdb(&[smooth_grid()]);
    assert!(glint::scene::grid::parse_density_grid(&whole, "density", "whole").is_ok());
    let lengths = (0..whole.len())
        .step_by(7)
        .chain(whole.len() - 64..whole.len());
    for len in lengths {
        let cut = glint::scene::grid::parse_density_grid(&whole[..len], "density", "cut");
        assert!(
            cut.is_err(),
            "a file cut at {len} of {} bytes read",
            whole.len()
        );
    }
}

/// `glint render` on a scene whose grid file the reader panics on (a transform map it does
/// not know, named as OpenVDB names its maps) exits 2 with the named error and no panic
/// message; so does one cut short (an input error).
#[test]
fn glint_render_refuses_unreadable_grids_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let whole = write_vdb(&[smooth_grid()]);
    let at = whole
        .windows(17)
        .position(|w| w == b"ScaleTranslateMap")
        .unwrap();
    let mut unknown = whole.clone();
    unknown[at..at + 17].copy_from_slice(b"UnknownMapOfSorts");
    std::fs::write(dir.path().join("map.vdb"), &unknown).unwrap();
    std::fs::write(dir.path().join("cut.vdb"), &whole[..whole.len() / 2]).unwrap();
    for (file, needle) in [
        ("map.vdb", "the reader failed"),
        ("cut.vdb", "UnexpectedEof"),
    ] {
        let more = format!(
            "[media.smoke]\ngrid = \"{file}\"\nsigma_s = [1.0, 1.0, 1.0]\n\
             [[volumes]]\nmedium = \"smoke\"\n"
        );
        std::fs::write(dir.path().join("s.toml"), scene_text(&more, 8, 1, 1)).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(["render", "s.toml", "--cpu", "-o", "s.png"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{file}: {err}");
        for want in ["media.smoke.grid", file, needle] {
            assert!(err.contains(want), "{file}: {want:?} not in {err}");
        }
        assert!(!err.contains("panicked"), "{file}: {err}");
    }
}

/// A grid too large for one binding (330³ voxels around its active values, 137 MiB) is
/// averaged over 2³ blocks, with a warning naming the file, the sizes and the factor: each
/// coarse voxel the mean of the 8 it covers (so the medium's mass, the sum of densities times
/// the voxel volume, is kept), placed where those 8 were. Beyond a factor of 4 it is refused
/// (the 4001³ grid of `bad_grids_are_refused_with_named_errors`).
#[test]
fn a_grid_too_large_for_one_binding_is_averaged_down() {
    let dir = tempfile::tempdir().unwrap();
    let mut grid = VdbGrid::float("density", [1, 1, 1], |_, _, _| 1.0);
    for (at, value) in [
        ([329, 329, 329], 2.0),
        ([100, 101, 102], 4.0),
        ([101, 101, 102], 4.0),
        ([100, 100, 103], 8.0),
    ] {
        grid.voxels.insert(at, value);
    }
    grid.voxel_size = 0.01;
    let bytes = write_vdb(std::slice::from_ref(&grid));
    let read = glint::scene::grid::parse_density_grid(&bytes, "density", "big.vdb").unwrap();
    assert_eq!(read.downsampled, 2);
    assert_eq!(read.read_dims, [330; 3]);
    assert_eq!(read.dims, [165; 3]);
    let coarse = |x: usize, y: usize, z: usize| read.density[x + 165 * (y + 165 * z)];
    assert_eq!(coarse(0, 0, 0), 1.0 / 8.0);
    assert_eq!(coarse(164, 164, 164), 2.0 / 8.0);
    // Fine voxels (100, 101, 102), (101, 101, 102) and (100, 100, 103) share coarse (50, 50, 51).
    assert_eq!(coarse(50, 50, 51), 16.0 / 8.0);
    let mass: f64 = read.density.iter().map(|&d| d as f64).sum::<f64>() * 8.0;
    assert_eq!(mass, 1.0 + 2.0 + 4.0 + 4.0 + 8.0);
    // Coarse voxel (50, 50, 51)'s centre is the corner the 8 fine voxels share: VDB index
    // coordinates (100.5, 100.5, 102.5), times the voxel size.
    let centre = read
        .grid_to_object
        .transform_point3(Vec3::new(50.5, 50.5, 51.5));
    assert!(
        (centre - Vec3::new(1.005, 1.005, 1.025))
            .abs()
            .max_element()
            < 1e-5,
        "{centre}"
    );

    std::fs::write(dir.path().join("big.vdb"), &bytes).unwrap();
    let more = "[media.smoke]\ngrid = \"big.vdb\"\nsigma_s = [1.0, 1.0, 1.0]\n\
                [[volumes]]\nmedium = \"smoke\"\ntranslate = [-1.6, -1.6, 2.0]\n";
    std::fs::write(dir.path().join("scene.toml"), scene_text(more, 4, 1, 1)).unwrap();
    let out = common::glint_ok(
        dir.path(),
        &["render", "scene.toml", "--cpu", "-o", "out.exr"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("big.vdb:density: the grid spans 330 × 330 × 330 voxels")
            && stderr.contains("averaged it over 2³ blocks to 165 × 165 × 165 voxels"),
        "{stderr}"
    );
}

/// Frame 24 of a real Blender smoke simulation's cache, scenes/blender-smoke.vdb, as Blender
/// 3.4's mantaflow wrote it (scenes/tools/bake_blender_smoke.py: Quick Smoke, resolution 32,
/// cache type ALL, OpenVDB with Blosc, half floats; grids density, flame, shadow, temperature
/// and velocity). Its density grid reads as Blender held it at that frame: the figures below
/// are what the script printed at bake time from the domain's own density grid
/// (`domain_settings.density_grid`, 18 × 18 × 32 cells, the domain 2.5 × 2.5 × 4.5, so one
/// cubic cell of 4.5 / 32), and the voxel size is Blender's imported grid's matrix.
#[test]
fn blender_smoke_cache_reads_as_blender_baked_it() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/blender-smoke.vdb");
    let bytes = std::fs::read(&path).unwrap();
    let grid =
        glint::scene::grid::parse_density_grid(&bytes, "density", "blender-smoke.vdb").unwrap();
    // Blender: cells above the cache's clipping (10⁻⁶) from (1, 1, 6) to (16, 16, 19).
    assert_eq!(grid.dims, [16, 16, 14]);
    assert_eq!(grid.downsampled, 1);
    // Voxel size 4.5 / 32 = 0.140625, no translation: voxel (1, 1, 6)'s centre, the dense
    // grid's first (continuous coordinates ½), is at (1, 1, 6) · 0.140625.
    let voxel = 0.140625f32;
    let first = grid.grid_to_object.transform_point3(Vec3::splat(0.5));
    assert!(
        (first - Vec3::new(1.0, 1.0, 6.0) * voxel)
            .abs()
            .max_element()
            < 1e-6,
        "{first}"
    );
    let step = grid.grid_to_object.transform_vector3(Vec3::ONE);
    assert!(
        (step - Vec3::splat(voxel)).abs().max_element() < 1e-7,
        "{step}"
    );
    // Blender: 1856 cells above the clipping, the largest 0.94287109375 (a half float, read
    // back from the cache), the sum 357.27275 (Blender's sum of the same half floats).
    let nonzero = grid.density.iter().filter(|&&d| d > 0.0).count();
    assert_eq!(nonzero, 1856);
    assert_eq!(grid.max_density(), 1931.0 / 2048.0); // 0.94287109375
    let sum: f64 = grid.density.iter().map(|&d| d as f64).sum();
    assert!((sum - 357.2727521061897).abs() < 1e-4, "{sum}");
    // The other grids are there and not read: the vector one is refused by name.
    let e = glint::scene::grid::parse_density_grid(&bytes, "velocity", "blender-smoke.vdb")
        .unwrap_err();
    assert!(e.contains("Tree_vec3s_5_4_3_HalfFloat"), "{e}");
    let e =
        glint::scene::grid::parse_density_grid(&bytes, "smoke", "blender-smoke.vdb").unwrap_err();
    for name in ["density", "flame", "shadow", "temperature", "velocity"] {
        assert!(e.contains(&format!("{name:?}")), "{e}");
    }
}
