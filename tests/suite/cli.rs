//! `glint render` end to end: PNG and EXR files written and read back, the JSON summary, exit
//! codes, the CPU fallback with no Vulkan driver, and every class of bad flag; the same command
//! twice writes byte-identical EXR and PNG files.

use crate::common;
use glint::image::output::Image;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run glint")
}

fn json(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

/// Files in `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn gpu_render_to_png_reads_back_as_the_furnace() {
    if common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let furnace = scene_path("furnace.toml");
    let out = glint(
        dir.path(),
        &[
            "render",
            furnace.to_str().unwrap(),
            "-o",
            "f.png",
            "--gpu",
            "--width",
            "20",
            "--height",
            "10",
            "--json",
        ],
    );
    let summary = json(&out);
    assert_eq!(summary["backend"], "vulkan");
    assert_eq!(summary["width"], 20);
    assert_eq!(summary["height"], 10);
    assert_eq!(summary["spp"], 16);
    assert_eq!(summary["paths"], 20 * 10 * 16);
    assert_eq!(summary["max_bounces"], 24);
    assert_eq!(summary["seed"], 0);
    assert_eq!(summary["sampler"], "independent");
    assert!(summary["seconds"].as_f64().unwrap() > 0.0);
    assert!(summary["paths_per_second"].as_f64().unwrap() > 0.0);
    assert!(!summary["device"].as_str().unwrap().is_empty());
    let png = image::open(dir.path().join("f.png")).unwrap().into_rgb8();
    assert_eq!(png.dimensions(), (20, 10));
    // Radiance 1 − 2^−25 encodes to 255 everywhere.
    assert!(png.pixels().all(|p| p.0 == [255, 255, 255]));
    assert_eq!(
        files(dir.path()),
        ["f.png"],
        "no temporary file left behind"
    );
}

#[test]
fn cpu_render_to_exr_is_linear_and_unclamped() {
    let dir = tempfile::tempdir().unwrap();
    // A lamp of radiance 7 seen directly: the EXR keeps 7, the PNG would clamp to 1.
    std::fs::write(
        dir.path().join("lamp.toml"),
        r#"
[camera]
eye = [0.0, 0.0, -5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 10.0
[render]
width = 8
height = 6
spp = 2
max_bounces = 3
background = [0.25, 0.5, 0.75]
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 2.0, 3.0]
strength = 7.0
[[quads]]
corner = [-10.0, -10.0, 0.0]
u = [20.0, 0.0, 0.0]
v = [0.0, 20.0, 0.0]
material = "lamp"
"#,
    )
    .unwrap();
    let summary = json(&glint(
        dir.path(),
        &["render", "lamp.toml", "-o", "lamp.exr", "--cpu", "--json"],
    ));
    assert_eq!(summary["device"], "cpu");
    let img = Image::read_exr(&dir.path().join("lamp.exr")).unwrap();
    assert_eq!((img.width, img.height), (8, 6));
    for p in &img.pixels {
        assert_eq!(*p, [7.0, 14.0, 21.0]);
    }
}

/// The README's promise: the same command gives the same bytes. Whole files are compared, as
/// `cmp` would: the EXR's header too, whose glint attributes once came out in a different order
/// on every run.
#[test]
fn the_same_command_writes_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_path("cornell.toml");
    let scene = scene.to_str().unwrap();
    for (run, folder) in ["a", "b"].iter().enumerate() {
        std::fs::create_dir(dir.path().join(folder)).unwrap();
        for file in ["x.exr", "x.png"] {
            let out = format!("{folder}/{file}");
            let args = ["render", scene, "--cpu", "--width", "16", "--height", "12"];
            let args = [&args[..], &["--spp", "4", "-o", &out]].concat();
            let result = glint(dir.path(), &args);
            assert!(
                result.status.success(),
                "run {run}: {}",
                String::from_utf8_lossy(&result.stderr)
            );
        }
    }
    for file in ["x.exr", "x.png"] {
        let a = std::fs::read(dir.path().join("a").join(file)).unwrap();
        let b = std::fs::read(dir.path().join("b").join(file)).unwrap();
        assert!(a == b, "{file}: the two runs' files differ");
    }
}

#[test]
fn default_output_is_the_scene_stem_as_png() {
    let dir = tempfile::tempdir().unwrap();
    let furnace = scene_path("furnace.toml");
    let out = glint(
        dir.path(),
        &["render", furnace.to_str().unwrap(), "--cpu", "--spp", "1"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(files(dir.path()), ["furnace.png"]);
    assert!(out.stdout.is_empty(), "nothing on stdout without --json");
}

#[test]
fn flags_override_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    let summary = json(&glint(
        dir.path(),
        &[
            "render",
            cornell.to_str().unwrap(),
            "-o",
            "c.png",
            "--cpu",
            "--json",
            "--spp",
            "3",
            "--width",
            "12",
            "--height",
            "7",
            "--max-bounces",
            "2",
            "--seed",
            "9",
        ],
    ));
    for (key, value) in [
        ("spp", 3),
        ("width", 12),
        ("height", 7),
        ("max_bounces", 2),
        ("seed", 9),
        ("paths", 12 * 7 * 3),
    ] {
        assert_eq!(summary[key], value, "{key}");
    }
    assert_eq!(
        image::open(dir.path().join("c.png"))
            .unwrap()
            .into_rgb8()
            .dimensions(),
        (12, 7)
    );
}

#[test]
fn time_limit_stops_early_and_writes_what_it_has() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    let summary = json(&glint(
        dir.path(),
        &[
            "render",
            cornell.to_str().unwrap(),
            "-o",
            "c.exr",
            "--cpu",
            "--json",
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "100000000",
            "--time-limit",
            "0",
        ],
    ));
    assert_eq!(summary["stopped_by"], "time-limit");
    let spp = summary["spp"].as_u64().unwrap();
    assert!((1..100).contains(&spp), "{spp}");
    let img = Image::read_exr(&dir.path().join("c.exr")).unwrap();
    assert!(img.mean() > 0.0 && img.mean().is_finite());
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[camera]\neye = [0, 0, 0]\n").unwrap();
    let furnace = scene_path("furnace.toml");
    let furnace = furnace.to_str().unwrap();
    for (args, needle) in [
        (vec!["render", "bad.toml", "-o", "x.png"], "bad.toml:"),
        (
            vec!["render", "missing.toml", "-o", "x.png"],
            "missing.toml",
        ),
        (vec!["render", furnace, "-o", "x.jpg"], "x.jpg"),
        (
            vec!["render", furnace, "-o", "no/such/dir/x.png"],
            "does not exist",
        ),
        (
            vec!["render", furnace, "-o", "x.png", "--spp", "-1"],
            "--spp",
        ),
        (
            vec!["render", furnace, "-o", "x.png", "--width", "0"],
            "--width",
        ),
        (
            vec![
                "render", furnace, "-o", "x.png", "--width", "16384", "--height", "16384",
            ],
            "too large",
        ),
        (
            vec!["render", furnace, "-o", "x.png", "--time-limit", "soon"],
            "--time-limit",
        ),
        (
            vec!["render", furnace, "-o", "x.png", "--cpu", "--gpu"],
            "--gpu",
        ),
        (vec!["render"], "SCENE"),
    ] {
        let out = glint(dir.path(), &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    assert_eq!(files(dir.path()), ["bad.toml"]);
}

/// With no Vulkan driver, `render` says so in one line and renders on the CPU; `--gpu` fails.
#[test]
fn without_vulkan_falls_back_to_cpu_unless_gpu_is_required() {
    let dir = tempfile::tempdir().unwrap();
    let furnace = scene_path("furnace.toml");
    let run = |extra: &[&str]| {
        Command::new(GLINT)
            .args([
                "render",
                furnace.to_str().unwrap(),
                "-o",
                "f.png",
                "--spp",
                "1",
                "--json",
            ])
            .args(extra)
            .current_dir(dir.path())
            // Point the Vulkan loader at no driver at all.
            .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
            .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
            .output()
            .unwrap()
    };
    let out = run(&[]);
    let summary = json(&out);
    assert_eq!(summary["device"], "cpu");
    let stderr = String::from_utf8_lossy(&out.stderr);
    let notes: Vec<_> = stderr.lines().filter(|l| l.starts_with("glint:")).collect();
    assert_eq!(notes.len(), 1, "{stderr}");
    assert!(
        notes[0].contains("no Vulkan device") && notes[0].contains("CPU"),
        "{stderr}"
    );

    std::fs::remove_file(dir.path().join("f.png")).unwrap();
    let out = run(&["--gpu"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no Vulkan device"));
    assert_eq!(files(dir.path()), Vec::<String>::new());
}

#[test]
fn variance_and_target_error_flags() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    let summary = json(&glint(
        dir.path(),
        &[
            "render",
            cornell.to_str().unwrap(),
            "-o",
            "c.exr",
            "--variance",
            "v.exr",
            "--cpu",
            "--json",
            "--width",
            "24",
            "--height",
            "24",
            "--spp",
            "100000",
            "--target-error",
            "0.5",
        ],
    ));
    assert_eq!(summary["stopped_by"], "target-error");
    let error = summary["relative_error"].as_f64().unwrap();
    assert!(error > 0.0 && error <= 0.5, "{error}");
    let mean = Image::read_exr(&dir.path().join("c.exr")).unwrap();
    let variance = Image::read_exr(&dir.path().join("v.exr")).unwrap();
    assert_eq!((variance.width, variance.height), (24, 24));
    assert!(variance
        .pixels
        .iter()
        .flatten()
        .all(|v| *v >= 0.0 && v.is_finite()));
    // The JSON's relative error is the documented formula over the files written.
    let recomputed = glint::render::relative_error(&mean, &variance).unwrap();
    assert!(
        (recomputed - error).abs() < 1e-9 * error.max(1.0),
        "{recomputed} vs {error}"
    );

    let out = glint(
        dir.path(),
        &[
            "render",
            cornell.to_str().unwrap(),
            "-o",
            "c.png",
            "--variance",
            "v.png",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains(".exr"));
    let out = glint(
        dir.path(),
        &["render", cornell.to_str().unwrap(), "--target-error", "0"],
    );
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn compare_reports_metrics_z_tests_and_writes_a_difference_image() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    for seed in ["1", "2"] {
        let out = glint(
            dir.path(),
            &[
                "render",
                cornell.to_str().unwrap(),
                "-o",
                &format!("{seed}.exr"),
                "--variance",
                &format!("{seed}.var.exr"),
                "--cpu",
                "--width",
                "32",
                "--height",
                "32",
                "--spp",
                "64",
                "--seed",
                seed,
            ],
        );
        assert!(out.status.success());
    }
    let out = glint(
        dir.path(),
        &[
            "compare",
            "1.exr",
            "2.exr",
            "--variance-a",
            "1.var.exr",
            "--variance-b",
            "2.var.exr",
            "--diff",
            "d.png",
            "--json",
        ],
    );
    let c = json(&out);
    assert!(c["rmse"].as_f64().unwrap() > 0.0);
    assert!(c["relative_mse"].as_f64().unwrap() > 0.0);
    assert_eq!(c["mean_a"].as_array().unwrap().len(), 3);
    let z = &c["z_test"];
    assert_eq!(z["tested"], 32 * 32 * 3);
    assert!(z["pass_rate"].as_f64().unwrap() > 0.95, "{z}");
    assert_eq!(
        image::open(dir.path().join("d.png"))
            .unwrap()
            .into_rgb8()
            .dimensions(),
        (32, 32)
    );

    // An image against itself: zero error, every test passes.
    let out = glint(
        dir.path(),
        &[
            "compare",
            "1.exr",
            "1.exr",
            "--variance-a",
            "1.var.exr",
            "--variance-b",
            "1.var.exr",
        ],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains("RMSE            0.000000") && text.contains("100.00%"),
        "{text}"
    );

    // Bad input: a missing file, images of different sizes, a variance without its pair.
    glint(
        dir.path(),
        &[
            "render",
            cornell.to_str().unwrap(),
            "-o",
            "small.exr",
            "--cpu",
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "1",
        ],
    );
    for (args, needle) in [
        (vec!["compare", "1.exr", "missing.exr"], "missing.exr"),
        (vec!["compare", "1.exr", "small.exr"], "sizes differ"),
        (
            vec!["compare", "1.exr", "2.exr", "--variance-a", "1.var.exr"],
            "--variance-b",
        ),
    ] {
        let out = glint(dir.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(needle),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// `glint bench --quick` runs every configuration and reports its figures. The GPU and the CPU
/// trace the same paths for the same seed, so their segment counts per path agree closely:
/// that checks the kernel's ray counter against the CPU mirror's.
#[test]
fn bench_runs_and_its_ray_counts_agree_between_devices() {
    if common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let summary = json(&glint(
        dir.path(),
        &["bench", "--quick", "--runs", "1", "--json"],
    ));
    let results = summary["results"].as_array().unwrap();
    assert_eq!(
        results.len(),
        8,
        "2 devices × 2 sizes × light sampling on/off"
    );
    assert_eq!(summary["gpu_backend"], "vulkan");
    for r in results {
        assert!(r["paths_per_second"].as_f64().unwrap() > 0.0, "{r}");
        assert!(r["ms_per_batch"].as_f64().unwrap() > 0.0, "{r}");
        assert!(r["rays_per_second"].as_f64().unwrap() > 0.0, "{r}");
    }
    let per_path = |device: &str, size: u64, light: bool| {
        results
            .iter()
            .find(|r| r["device"] == device && r["width"] == size && r["light_sampling"] == light)
            .and_then(|r| r["segments_per_path"].as_f64())
            .unwrap()
    };
    for (size, light) in [(32, false), (32, true), (64, false), (64, true)] {
        let (gpu, cpu) = (per_path("gpu", size, light), per_path("cpu", size, light));
        assert!(
            (gpu / cpu - 1.0).abs() < 0.02,
            "{size}² light {light}: gpu {gpu} vs cpu {cpu}"
        );
        // Shadow rays: more segments with light sampling.
        assert!(cpu > if light { 4.0 } else { 2.0 }, "{cpu}");
    }
}

/// A bad command line is one line on stderr and exit code 2, whatever the command, like every
/// other bad input; clap's usage block and tips are left out, its details kept.
#[test]
fn bad_command_lines_are_one_line_with_exit_2() {
    for (args, needle) in [
        (vec!["render"], "<SCENE>"),
        (vec!["render", "x.toml", "--no-such-flag"], "--no-such-flag"),
        (
            vec!["render", "x.toml", "--tonemap", "foo"],
            "clamp, aces or agx",
        ),
        (vec!["render", "x.toml", "--spp", "-3"], "--spp"),
        (vec!["merge"], "required"),
        (vec!["compare", "a.exr"], "<B>"),
        (vec!["no-such-command"], "no-such-command"),
    ] {
        let out = std::process::Command::new(GLINT)
            .args(&args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.starts_with("glint: error:"), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
    // --help still prints the help, on stdout, with exit code 0.
    let out = std::process::Command::new(GLINT)
        .args(["render", "--help"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("Usage"));
}

/// A shader cache folder whose parents do not exist yet is created before the GPU opens.
/// Mesa creates only the last folder and otherwise disables its cache, and lavapipe then
/// recompiled the kernel for every dispatch: minutes per sample on a mesh scene. Where there
/// is no GPU the render falls back to the CPU, but the folder is still made.
#[test]
fn missing_shader_cache_folders_are_created() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("a").join("b");
    let scene = scene_path("cornell.toml");
    let out = Command::new(GLINT)
        .args(["render", scene.to_str().unwrap()])
        .args([
            "--width", "8", "--height", "8", "--spp", "1", "-o", "out.exr",
        ])
        .env("MESA_SHADER_CACHE_DIR", &cache)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(cache.is_dir(), "{} was not created", cache.display());
}

/// `--traversal`: `software` and `auto` render everywhere, `hardware` where the device has
/// ray queries (else exit 1, naming why, and no file); `--json` says which ran, and on lavapipe
/// `auto` is the software traversal (measured slower there: BENCHMARKS.md). Both traversals
/// write the same image, bit for bit. The CPU reference always reports `software`.
#[test]
fn traversal_flag_picks_and_reports_the_traversal() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    let run = |output: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            cornell.to_str().unwrap(),
            "-o",
            output,
            "--width",
            "16",
            "--height",
            "16",
            "--spp",
            "2",
            "--json",
        ];
        args.extend(extra);
        glint(dir.path(), &args)
    };
    let cpu = json(&run("cpu.png", &["--cpu", "--traversal", "hardware"]));
    assert_eq!(cpu["traversal"], "software");
    let bad = run("bad.png", &["--traversal", "sideways"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(!dir.path().join("bad.png").exists());
    let Some(ctx) = common::gpu() else { return };
    let software = json(&run("software.png", &["--gpu", "--traversal", "software"]));
    assert_eq!(software["traversal"], "software");
    let auto = json(&run("auto.png", &["--gpu"]));
    if ctx.device_name().contains("llvmpipe") {
        assert_eq!(auto["traversal"], "software");
    }
    let hardware = run("hardware.png", &["--gpu", "--traversal", "hardware"]);
    if ctx.has_ray_queries() {
        assert_eq!(json(&hardware)["traversal"], "hardware");
        assert_eq!(
            std::fs::read(dir.path().join("hardware.png")).unwrap(),
            std::fs::read(dir.path().join("software.png")).unwrap()
        );
    } else {
        assert_eq!(hardware.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&hardware.stderr).contains("no ray queries"));
        assert!(!dir.path().join("hardware.png").exists());
    }
}

/// `--sampler sobol` reaches the render (its JSON says so and its image differs from the
/// independent sampler's), `--print-scene` writes it, and an unknown sampler is refused.
#[test]
fn sampler_option() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    let cornell = cornell.to_str().unwrap();
    let small = [
        "--cpu", "--spp", "4", "--width", "16", "--height", "16", "--json",
    ];
    let mut images = Vec::new();
    for sampler in ["independent", "sobol"] {
        let output = format!("{sampler}.exr");
        let mut args = vec!["render", cornell, "--sampler", sampler, "-o", &output];
        args.extend(small);
        let summary = json(&glint(dir.path(), &args));
        assert_eq!(summary["sampler"], sampler);
        images.push(glint::image::output::Image::read_exr(&dir.path().join(&output)).unwrap());
    }
    assert_ne!(images[0].pixels, images[1].pixels);
    let bunny = scene_path("models/bunny.ply");
    let printed = glint(
        dir.path(),
        &[
            "render",
            bunny.to_str().unwrap(),
            "--sampler",
            "sobol",
            "--print-scene",
        ],
    );
    assert!(printed.status.success());
    assert!(String::from_utf8_lossy(&printed.stdout).contains("sampler = \"sobol\""));
    let refused = glint(dir.path(), &["render", cornell, "--sampler", "halton"]);
    assert!(!refused.status.success());
}
