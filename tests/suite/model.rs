//! A model file as the scene (`glint render model.glb`), glTF cameras and lights, and the scene
//! file `--print-scene` writes. Cameras' views and lights' positions, directions, cone angles and
//! intensities (÷ 683) match the files' numbers (tests/models/make_lights_cameras.py), in a model
//! scene and through `[camera] from` and `[[meshes]] lights`; `--print-scene` round-trips to the
//! same `Scene` and the same PNG bytes; a bare `.glb`, `.ply` and `.obj` fill the frame; bad
//! lights and `--camera 7` exit 2 naming the field; an orthographic camera (xmag, ymag) renders,
//! round-trips and refuses bad magnifications; assimp-testmodels' Cameras.gltf is read where it
//! is installed.

use glam::{Mat4, Vec3};
use glint::image::output::Image;
use glint::scene::light::{Light, LightKind};
use glint::scene::mesh::{gltf_camera, gltf_lights, LUMENS_PER_WATT};
use glint::scene::model::{load_model, ModelOptions};
use glint::scene::{Projection, Scene};
use std::path::{Path, PathBuf};
use std::process::Output;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");
const CAMERAS_GLTF: &str = "/usr/share/assimp/models/glTF2/cameras/Cameras.gltf";

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models")
}

fn lights_cameras() -> PathBuf {
    models().join("lights-cameras.gltf")
}

fn glint<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    std::process::Command::new(GLINT)
        .args(args)
        .output()
        .expect("run glint")
}

/// stderr without Mesa's note about XDG_RUNTIME_DIR.
fn stderr_lines(run: &Output) -> Vec<String> {
    String::from_utf8_lossy(&run.stderr)
        .lines()
        .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
        .map(String::from)
        .collect()
}

fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// A perspective camera's field of view.
fn vfov(projection: Projection) -> f32 {
    match projection {
        Projection::Perspective { vfov } => vfov,
        other => panic!("not a perspective camera: {other:?}"),
    }
}

#[test]
fn the_cameras_match_the_files_numbers() {
    let path = lights_cameras();
    let c = gltf_camera(&path, None).unwrap().expect("a camera");
    assert_eq!((c.node, c.camera), (2, 0));
    assert_eq!(c.eye, Vec3::new(0.0, 1.5, 6.0));
    assert_eq!(c.forward, Vec3::NEG_Z);
    assert_eq!(c.up, Vec3::Y);
    assert!((vfov(c.projection) - 0.6f32.to_degrees()).abs() < 1e-5);
    assert_eq!(c.aspect, Some(1.5));

    // A child of a translated node, turned +90° about +y: at (4 + 1, 2, 0), looking along −x.
    let side = gltf_camera(&path, Some(1)).unwrap().unwrap();
    assert_eq!((side.node, side.camera), (4, 1));
    assert!(
        close(side.eye, Vec3::new(5.0, 2.0, 0.0), 1e-6),
        "{}",
        side.eye
    );
    assert!(close(side.forward, Vec3::NEG_X, 1e-6), "{}", side.forward);
    assert!(close(side.up, Vec3::Y, 1e-6), "{}", side.up);
    assert!((vfov(side.projection) - 0.8f32.to_degrees()).abs() < 1e-5);
    assert_eq!(side.aspect, None);

    let e = gltf_camera(&path, Some(2)).unwrap_err();
    assert!(e.contains("2 cameras"), "{e}");

    // The model scene looks through camera 0, and its aspect ratio sets the image's height.
    let model = load_model(&path, &ModelOptions::default()).unwrap();
    let camera = &model.scene.camera;
    assert_eq!(camera.eye, c.eye);
    assert!(close(
        (camera.target - camera.eye).normalize(),
        Vec3::NEG_Z,
        1e-7
    ));
    assert_eq!(camera.projection, c.projection);
    assert_eq!(
        (model.scene.render.width, model.scene.render.height),
        (512, 341)
    );
    let wide = ModelOptions {
        height: Some(100),
        ..Default::default()
    };
    let scene = load_model(&path, &wide).unwrap().scene;
    assert_eq!((scene.render.width, scene.render.height), (150, 100));
}

#[test]
fn the_lights_match_the_files_numbers() {
    let (lights, warnings) = gltf_lights(&lights_cameras(), Mat4::IDENTITY).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(lights.len(), 3);
    assert_eq!(LUMENS_PER_WATT, 683.0);
    let Light {
        kind,
        color,
        intensity,
    } = &lights[0];
    assert_eq!(
        *kind,
        LightKind::Point {
            position: Vec3::new(1.0, 3.0, 1.0),
            radius: 0.0
        }
    );
    assert_eq!(*color, Vec3::new(1.0, 0.9, 0.8));
    assert_eq!(*intensity, 6830.0 / 683.0);
    let LightKind::Spot {
        position,
        direction,
        inner_angle,
        outer_angle,
    } = lights[1].kind
    else {
        panic!("{:?}", lights[1]);
    };
    assert_eq!(position, Vec3::new(-1.0, 4.0, 0.0));
    assert!(close(direction, Vec3::NEG_Y, 1e-6), "{direction}");
    assert!((inner_angle - 0.3f32.to_degrees()).abs() < 1e-5);
    assert!((outer_angle - 0.5f32.to_degrees()).abs() < 1e-5);
    assert_eq!(lights[1].intensity, 2.0);
    assert_eq!(lights[1].color, Vec3::ONE);
    let LightKind::Directional { direction, angle } = lights[2].kind else {
        panic!("{:?}", lights[2]);
    };
    let sixty = 60f32.to_radians();
    assert!(close(
        direction,
        Vec3::new(0.0, -sixty.sin(), -sixty.cos()),
        1e-6
    ));
    assert_eq!(angle, 0.0);
    assert_eq!(lights[2].intensity, 1.0);

    // A [[meshes]] entry's transform moves them too.
    let moved = gltf_lights(&lights_cameras(), Mat4::from_translation(Vec3::Z * 2.0))
        .unwrap()
        .0;
    assert!(
        matches!(moved[0].kind, LightKind::Point { position, .. } if position == Vec3::new(1.0, 3.0, 3.0))
    );
}

/// A file as Blender 4.5's own exporter writes it, with a point, a spot and a sun lamp
/// (`tests/models/make_blender_lamps.py`): it lists KHR_lights_punctual in
/// `extensionsRequired`, as Blender does whenever a scene has a lamp, which glint once
/// refused. It renders as a model file, and Blender's watts arrive as the exporter converts
/// them (a point or spot lamp of P W radiates P/4π W/sr; a sun of E W/m² gives E).
#[test]
fn a_blender_export_with_lamps_renders() {
    let path = models().join("blender-lamps.glb");
    let bytes = std::fs::read(&path).unwrap();
    let root = gltf::Gltf::from_slice_without_validation(&bytes)
        .unwrap()
        .document
        .into_json();
    assert_eq!(root.extensions_required, ["KHR_lights_punctual"]);
    let (lights, warnings) = gltf_lights(&path, Mat4::IDENTITY).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let watts_per_steradian = |watts: f32| watts / (4.0 * std::f32::consts::PI);
    let relative = |a: f32, b: f32| ((a - b) / b).abs();
    assert!(
        matches!(lights[0].kind, LightKind::Point { .. }),
        "{lights:?}"
    );
    assert!(relative(lights[0].intensity, watts_per_steradian(300.0)) < 1e-5);
    assert!(
        matches!(lights[1].kind, LightKind::Spot { .. }),
        "{lights:?}"
    );
    assert!(relative(lights[1].intensity, watts_per_steradian(500.0)) < 1e-5);
    assert!(
        matches!(lights[2].kind, LightKind::Directional { .. }),
        "{lights:?}"
    );
    assert!(relative(lights[2].intensity, 2.0) < 1e-5);

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lamps.png");
    let run = glint(&[
        "render".as_ref(),
        path.as_os_str(),
        "--cpu".as_ref(),
        "--spp".as_ref(),
        "4".as_ref(),
        "--width".as_ref(),
        "32".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{:?}", stderr_lines(&run));
    assert!(std::fs::metadata(&out).unwrap().len() > 0);
}

#[test]
fn debians_cameras_gltf_reads() {
    let path = Path::new(CAMERAS_GLTF);
    if !path.exists() {
        eprintln!("skipped: {CAMERAS_GLTF} is not installed (Debian assimp-testmodels)");
        return;
    }
    // nodes[1]: a perspective camera at (0.5, 0.5, 3), yfov 0.7, aspect 1; nodes[2]: an
    // orthographic one.
    let c = gltf_camera(path, None).unwrap().unwrap();
    assert_eq!(c.eye, Vec3::new(0.5, 0.5, 3.0));
    assert_eq!(c.forward, Vec3::NEG_Z);
    assert!((vfov(c.projection) - 0.7f32.to_degrees()).abs() < 1e-5);
    assert_eq!(c.aspect, Some(1.0));

    let run = glint(&["render", CAMERAS_GLTF, "--camera", "7", "--print-scene"]);
    assert_eq!(run.status.code(), Some(2));
    let lines = stderr_lines(&run);
    assert_eq!(lines.len(), 1, "{lines:?}");
    for needle in ["Cameras.gltf", "--camera 7", "2 cameras"] {
        assert!(lines[0].contains(needle), "{lines:?} lacks {needle}");
    }
    // Camera 1 is orthographic, xmag = ymag = 1: a view 2 high.
    let run = glint(&["render", CAMERAS_GLTF, "--camera", "1", "--print-scene"]);
    assert!(run.status.success(), "{:?}", stderr_lines(&run));
    let toml = String::from_utf8(run.stdout).unwrap();
    assert!(
        toml.contains("projection = \"orthographic\"\nheight = 2.0\n"),
        "{toml}"
    );

    // It has no material: the model gets the default one, and renders.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cameras.png");
    let run = glint(&[
        "render",
        CAMERAS_GLTF,
        "--cpu",
        "--spp",
        "1",
        "--width",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{:?}", stderr_lines(&run));
    assert!(out.exists());
}

/// lights-cameras.gltf with `edit` applied to its JSON, written to `dir`.
fn edited(dir: &Path, name: &str, edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    let text = std::fs::read_to_string(lights_cameras()).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    edit(&mut json);
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string(&json).unwrap()).unwrap();
    path
}

fn lights_json(json: &mut serde_json::Value) -> &mut serde_json::Value {
    &mut json["extensions"]["KHR_lights_punctual"]["lights"]
}

#[test]
fn bad_lights_exit_2_naming_the_file_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases: Vec<(PathBuf, &[&str])> = vec![
        (
            edited(dir.path(), "negative.gltf", |j| {
                lights_json(j)[0]["intensity"] = (-5.0).into()
            }),
            &["negative.gltf", "lights[0].intensity", "≥ 0"],
        ),
        (
            edited(
                dir.path(),
                "cone.gltf",
                |j| {
                    lights_json(j)[1]["spot"] =
                        serde_json::json!({"innerConeAngle": 0.5, "outerConeAngle": 0.3})
                },
            ),
            &[
                "cone.gltf",
                "lights[1].spot.outerConeAngle",
                "innerConeAngle",
            ],
        ),
        (
            edited(dir.path(), "flat.gltf", |j| {
                j["nodes"][7]["scale"] = serde_json::json!([0.0, 0.0, 0.0])
            }),
            &["flat.gltf", "nodes[7]", "direction", "zero"],
        ),
    ];
    for (path, needles) in cases {
        for command in [&["render", "--print-scene"][..], &["view"][..]] {
            let mut args: Vec<&std::ffi::OsStr> = command.iter().map(|s| s.as_ref()).collect();
            args.insert(1, path.as_os_str());
            let run = glint(&args);
            let lines = stderr_lines(&run);
            assert_eq!(run.status.code(), Some(2), "{command:?} {lines:?}");
            assert_eq!(lines.len(), 1, "{lines:?}");
            for needle in needles {
                assert!(lines[0].contains(needle), "{lines:?} lacks {needle:?}");
            }
            assert!(run.stdout.is_empty());
        }
    }

    // A light of a type glint does not know: one warning, and the others stay.
    let path = edited(dir.path(), "area.gltf", |j| {
        lights_json(j)[2]["type"] = "area".into()
    });
    let run = glint(&[
        std::ffi::OsStr::new("render"),
        path.as_os_str(),
        "--print-scene".as_ref(),
    ]);
    assert!(run.status.success(), "{:?}", stderr_lines(&run));
    let lines = stderr_lines(&run);
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(
        lines[0].contains("area.gltf") && lines[0].contains("lights[2]"),
        "{lines:?}"
    );
    let toml = String::from_utf8(run.stdout).unwrap();
    assert_eq!(toml.matches("[[lights]]").count(), 2, "{toml}");
}

/// `glint render MODEL FLAGS --print-scene` saved next to the model, then both rendered with
/// `render_flags`: the same scene and the same image.
fn assert_round_trip(model: &Path, flags: &[&str]) {
    let dir = model.parent().unwrap();
    let stem = model.file_stem().unwrap().to_str().unwrap();
    let toml = dir.join(format!("{stem}.toml"));
    let mut args = vec!["render", model.to_str().unwrap(), "--print-scene"];
    args.extend_from_slice(flags);
    let run = glint(&args);
    assert!(run.status.success(), "{:?}", stderr_lines(&run));
    std::fs::write(&toml, &run.stdout).unwrap();

    let mut images = Vec::new();
    for (input, name) in [(model, "model.png"), (toml.as_path(), "scene.png")] {
        let out = dir.join(name);
        let mut args = vec!["render", input.to_str().unwrap(), "--cpu", "--spp", "2"];
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        if input == model {
            args.extend_from_slice(flags);
        }
        let run = glint(&args);
        assert!(run.status.success(), "{:?}", stderr_lines(&run));
        images.push(std::fs::read(&out).unwrap());
    }
    assert!(
        images[0] == images[1],
        "{}: the images differ",
        model.display()
    );
    let scene = Scene::load(&toml).unwrap();
    assert!(scene.environment.is_some());
}

#[test]
fn print_scene_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("lights-cameras.gltf");
    std::fs::copy(lights_cameras(), &gltf).unwrap();
    let ply = dir.path().join("bunny.ply");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/bunny.ply"),
        &ply,
    )
    .unwrap();
    // The same Scene, field for field.
    for model in [&gltf, &ply] {
        let built = load_model(model, &ModelOptions::default()).unwrap();
        let text = glint::scene::model_toml::model_toml(&built);
        let toml = model.with_extension("toml");
        std::fs::write(&toml, text).unwrap();
        assert_eq!(
            Scene::load(&toml).unwrap(),
            built.scene,
            "{}",
            model.display()
        );
    }
    assert_round_trip(&gltf, &["--width", "40"]);
    let sky = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/skies/sky.hdr");
    assert_round_trip(
        &gltf,
        &[
            "--camera",
            "1",
            "--environment",
            sky.to_str().unwrap(),
            "--environment-strength",
            "0.5",
            "--environment-rotate",
            "30",
            "--height",
            "24",
            "--max-bounces",
            "3",
            "--light-sampler",
            "tree",
        ],
    );
    assert_round_trip(&ply, &["--width", "32", "--height", "24"]);
}

/// The share of the frame the model covers (depth AOV: the background is 1e30), the extent of
/// the covered pixels as fractions of the width and height, and whether any touches the border.
fn coverage(model: &Path, dir: &Path) -> (f64, f64, f64, bool) {
    let depth = dir.join("depth.exr");
    let run = glint(&[
        "render",
        model.to_str().unwrap(),
        "--cpu",
        "--spp",
        "1",
        "--width",
        "64",
        "--height",
        "64",
        "-o",
        dir.join("x.png").to_str().unwrap(),
        "--depth",
        depth.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{:?}", stderr_lines(&run));
    let image = Image::read_exr(&depth).unwrap();
    let (w, h) = (image.width as usize, image.height as usize);
    let (mut x0, mut x1, mut y0, mut y1, mut covered) = (w, 0, h, 0, 0usize);
    for (k, p) in image.pixels.iter().enumerate() {
        if p[0] < 1e29 {
            let (x, y) = (k % w, k / w);
            covered += 1;
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
    }
    assert!(covered > 0, "{}: nothing covered", model.display());
    let border = x0 == 0 || y0 == 0 || x1 == w - 1 || y1 == h - 1;
    (
        covered as f64 / (w * h) as f64,
        (x1 - x0 + 1) as f64 / w as f64,
        (y1 - y0 + 1) as f64 / h as f64,
        border,
    )
}

#[test]
fn a_bare_model_fills_the_frame() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    // The framing camera: the bounding sphere's outline spans 1/1.1 of the frame.
    for model in [
        models().join("bare-box.glb"),
        root.join("scenes/models/bunny.ply"),
        root.join("scenes/models/cornell-walls.obj"),
    ] {
        let (fraction, width, height, border) = coverage(&model, dir.path());
        eprintln!(
            "{}: covers {:.1}% of the frame, {:.0}% of its width, {:.0}% of its height",
            model.display(),
            100.0 * fraction,
            100.0 * width,
            100.0 * height
        );
        assert!(!border, "{}: the model touches the border", model.display());
        assert!(
            width.max(height) >= 0.6 && fraction >= 0.2,
            "{}: the model does not fill the frame",
            model.display()
        );
    }
}

/// lights-cameras.gltf with its camera 0 made orthographic, `xmag` and `ymag` as given.
fn orthographic(dir: &Path, name: &str, xmag: f64, ymag: f64) -> PathBuf {
    edited(dir, name, |j| {
        j["cameras"][0] = serde_json::json!({
            "type": "orthographic",
            "orthographic": {"xmag": xmag, "ymag": ymag, "znear": 0.1, "zfar": 100.0}
        })
    })
}

/// A glTF file's orthographic camera: 2·ymag high, xmag / ymag its aspect ratio (a model
/// scene's image shape), rendered on both devices as a model file, written by `--print-scene`
/// as `projection = "orthographic"` and `height`, which renders the same image, and taken by a
/// scene file's `[camera] from`; magnifications ≤ 0 exit 2 naming the field, and a lens on it
/// is refused.
#[test]
fn a_gltf_files_orthographic_camera_renders() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = orthographic(d, "ortho.gltf", 3.0, 2.0);
    let c = gltf_camera(&path, None).unwrap().expect("a camera");
    assert_eq!((c.node, c.camera), (2, 0));
    assert_eq!(c.eye, Vec3::new(0.0, 1.5, 6.0));
    assert_eq!(c.projection, Projection::Orthographic { height: 4.0 });
    assert_eq!(c.aspect, Some(1.5));
    let model = load_model(&path, &ModelOptions::default()).unwrap();
    assert_eq!(model.scene.camera.projection, c.projection);
    assert_eq!(model.scene.camera.aperture, 0.0);
    assert_eq!(
        (model.scene.render.width, model.scene.render.height),
        (512, 341)
    );

    for device in ["--cpu", "--gpu"] {
        let out = d.join(format!("ortho{device}.png"));
        let run = glint(&[
            "render",
            path.to_str().unwrap(),
            device,
            "--spp",
            "2",
            "--width",
            "24",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(run.status.success(), "{device}: {:?}", stderr_lines(&run));
        assert!(std::fs::metadata(&out).unwrap().len() > 0);
    }

    let run = glint(&["render", path.to_str().unwrap(), "--print-scene"]);
    assert!(run.status.success(), "{:?}", stderr_lines(&run));
    let toml = String::from_utf8(run.stdout).unwrap();
    assert!(
        toml.contains("projection = \"orthographic\"\nheight = 4.0\n"),
        "{toml}"
    );
    assert!(!toml.contains("vfov"), "{toml}");
    let text = glint::scene::model_toml::model_toml(&model);
    std::fs::write(d.join("ortho.toml"), text).unwrap();
    assert_eq!(Scene::load(&d.join("ortho.toml")).unwrap(), model.scene);
    assert_round_trip(&path, &["--width", "40"]);

    // A scene file's [camera] from takes it, without a lens.
    let write = |camera: &str| {
        let text = format!(
            "[camera]\nfrom = \"ortho.gltf\"\n{camera}\n\n[render]\nwidth = 8\nheight = 8\n\
             spp = 1\nmax_bounces = 1\n"
        );
        let scene = d.join("s.toml");
        std::fs::write(&scene, text).unwrap();
        Scene::load(&scene).map_err(|e| e.to_string())
    };
    assert_eq!(write("").unwrap().camera.projection, c.projection);
    for (camera, needles) in [
        (
            "aperture = 0.5",
            &[
                "s.toml",
                "camera.aperture",
                "orthographic camera has no lens",
            ][..],
        ),
        ("height = 3.0", &["camera.height", "not both"][..]),
    ] {
        let e = write(camera).unwrap_err();
        for needle in needles {
            assert!(e.contains(needle), "{e} lacks {needle}");
        }
    }

    for (xmag, ymag, field) in [
        (3.0, 0.0, "cameras[0].orthographic.ymag"),
        (3.0, -2.0, "cameras[0].orthographic.ymag"),
        (-3.0, 2.0, "cameras[0].orthographic.xmag"),
        (3.0, 1e-30, "cameras[0].orthographic.ymag"),
    ] {
        let bad = orthographic(d, "bad.gltf", xmag, ymag);
        let run = glint(&["render", bad.to_str().unwrap(), "--print-scene"]);
        let lines = stderr_lines(&run);
        assert_eq!(run.status.code(), Some(2), "{lines:?}");
        assert_eq!(lines.len(), 1, "{lines:?}");
        for needle in ["bad.gltf", field] {
            assert!(lines[0].contains(needle), "{lines:?} lacks {needle:?}");
        }
        assert!(run.stdout.is_empty());
    }
}

fn scene_with(dir: &Path, camera: &str, mesh_extra: &str) -> Result<Scene, String> {
    std::fs::copy(lights_cameras(), dir.join("lc.gltf")).unwrap();
    let text = format!(
        "[camera]\n{camera}\n\n[render]\nwidth = 8\nheight = 8\nspp = 1\nmax_bounces = 1\n\n\
         [[meshes]]\nfile = \"lc.gltf\"\n{mesh_extra}\n"
    );
    let path = dir.join("s.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).map_err(|e| e.to_string())
}

#[test]
fn scene_files_take_a_files_camera_and_lights() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scene_with(d, "from = \"lc.gltf\"\nindex = 1", "").unwrap();
    assert!(close(scene.camera.eye, Vec3::new(5.0, 2.0, 0.0), 1e-6));
    assert!(close(
        (scene.camera.target - scene.camera.eye).normalize(),
        Vec3::NEG_X,
        1e-6
    ));
    assert!((vfov(scene.camera.projection) - 0.8f32.to_degrees()).abs() < 1e-5);
    assert_eq!(scene.lights.len(), 3);
    let first = scene_with(d, "from = \"lc.gltf\"", "lights = false").unwrap();
    assert_eq!(first.camera.eye, Vec3::new(0.0, 1.5, 6.0));
    assert!(first.lights.is_empty());
    let moved = scene_with(d, "from = \"lc.gltf\"", "translate = [0.0, 0.0, 2.0]").unwrap();
    assert!(
        matches!(moved.lights[0].kind, LightKind::Point { position, .. } if position == Vec3::new(1.0, 3.0, 3.0))
    );

    for (camera, needles) in [
        (
            "from = \"lc.gltf\"\nindex = 7",
            &["s.toml", "camera.index", "2 cameras"][..],
        ),
        (
            "from = \"lc.gltf\"\nvfov = 30.0",
            &["camera.vfov", "not both"][..],
        ),
        ("index = 0", &["camera.index", "camera.from"][..]),
        (
            "eye = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]",
            &["camera.vfov", "missing"][..],
        ),
    ] {
        let e = scene_with(d, camera, "").unwrap_err();
        for needle in needles {
            assert!(e.contains(needle), "{e} lacks {needle}");
        }
    }
}

#[test]
fn model_flags_need_a_model_file() {
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml");
    for flags in [
        &["--camera", "0"][..],
        &["--environment", "x.hdr"][..],
        &["--print-scene"][..],
    ] {
        let mut args = vec!["render", cornell.to_str().unwrap()];
        args.extend_from_slice(flags);
        let run = glint(&args);
        assert_eq!(run.status.code(), Some(2));
        let lines = stderr_lines(&run);
        assert!(lines[0].contains(flags[0]), "{lines:?}");
    }
}

#[test]
fn the_studio_preset_and_bad_environment_input() {
    let dir = tempfile::tempdir().unwrap();
    let write = |environment: &str| {
        let path = dir.path().join("s.toml");
        std::fs::write(
            &path,
            format!(
                "[camera]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
                 vfov = 40.0\n\n[render]\nwidth = 8\nheight = 8\nspp = 1\nmax_bounces = 1\n\n\
                 [environment]\n{environment}\n"
            ),
        )
        .unwrap();
        Scene::load(&path).map_err(|e| e.to_string())
    };
    let scene = write("preset = \"studio\"\nstrength = 2.0").unwrap();
    let studio = glint::scene::studio::environment(2.0, 0.0).unwrap();
    assert_eq!(scene.environment, Some(studio));
    for (text, needles) in [
        ("preset = \"beach\"", &["environment.preset", "beach"][..]),
        (
            "preset = \"studio\"\nfile = \"x.hdr\"",
            &["environment.preset", "not both"][..],
        ),
        ("strength = 1.0", &["environment.file", "missing"][..]),
    ] {
        let e = write(text).unwrap_err();
        for needle in needles {
            assert!(e.contains(needle), "{e} lacks {needle}");
        }
    }

    let ply = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/bunny.ply");
    for (flags, needles) in [
        (
            &["--camera", "0"][..],
            &["bunny.ply", "--camera 0", "no cameras"][..],
        ),
        (
            &["--environment-strength", "-1"][..],
            &["--environment-strength"][..],
        ),
        (
            &["--environment-rotate", "400"][..],
            &["--environment-rotate"][..],
        ),
        (
            &["--environment", "missing.hdr"][..],
            &["bunny.ply", "--environment missing.hdr"][..],
        ),
    ] {
        let mut args = vec!["render", ply.to_str().unwrap(), "--print-scene"];
        args.extend_from_slice(flags);
        let run = glint(&args);
        let lines = stderr_lines(&run);
        assert_eq!(run.status.code(), Some(2), "{flags:?} {lines:?}");
        for needle in needles {
            assert!(lines[0].contains(needle), "{lines:?} lacks {needle}");
        }
    }
}
