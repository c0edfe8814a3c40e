//! `glint render` end to end: files written and read back, JSON, exit codes, fallback.

mod common;
use glint::output::Image;
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
