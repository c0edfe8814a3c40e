//! Files and streams under abuse (issue 15's input/output classes, each the case the issue
//! found plus a neighbour; numbers in test names are the issue's items): flags out of range,
//! closed stdout and stderr, outputs that collide or overwrite an input, permissions and links
//! kept, FIFOs, /dev/zero and oversized scenes, unwritable outputs, `compare` on PNGs and NaNs.

use glint::image::output::Image;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn cornell() -> String {
    scene_path("cornell.toml").to_str().unwrap().to_string()
}

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run glint")
}

/// A small, fast CPU render of `scene` (4 spp unless `extra` says) with extra arguments.
fn render(dir: &Path, scene: &str, extra: &[&str]) -> Output {
    let mut args = vec!["render", scene, "--cpu", "--width", "8", "--height", "8"];
    if !extra.contains(&"--spp") {
        args.extend(["--spp", "4"]);
    }
    args.extend_from_slice(extra);
    glint(dir, &args)
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Exit code 2, one clear error naming `needle`, no panic.
fn assert_refused(out: &Output, needle: &str, what: &str) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{what}: {err}");
    assert!(err.contains(needle), "{what}: {needle:?} not in {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
}

fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

// ---- 1: number flags outside their real range ----

#[test]
fn item1_time_limit_beyond_a_duration_is_refused_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    for value in ["1e20", "1.8e19", "1e10", "inf", "nan", "-1", "-0.5"] {
        let out = render(
            dir.path(),
            &cornell(),
            &["-o", "x.png", "--time-limit", value],
        );
        assert_refused(&out, "--time-limit", value);
    }
    assert_eq!(files(dir.path()), Vec::<String>::new());
    // The largest value accepted still renders (and does not panic computing a deadline).
    let out = render(
        dir.path(),
        &cornell(),
        &["-o", "x.png", "--time-limit", "1e9"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

// ---- 2: a closed stdout or stderr ----

#[test]
fn item2_json_into_a_closed_pipe_exits_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = Command::new(GLINT)
        .args([
            "render",
            &cornell(),
            "--cpu",
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "4",
            "-o",
            "x.png",
            "--json",
        ])
        .current_dir(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // `| true`: the reader is gone before glint prints.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(stderr(&out).is_empty(), "{}", stderr(&out));
    assert_eq!(files(dir.path()), ["x.png"]);
}

#[test]
fn item2_compare_text_into_a_closed_pipe_exits_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let image = Image {
        width: 2,
        height: 1,
        pixels: vec![[0.5; 3], [1.0; 3]],
    };
    image.write(&dir.path().join("a.exr")).unwrap();
    let mut child = Command::new(GLINT)
        .args(["compare", "a.exr", "a.exr"])
        .current_dir(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"));
}

/// `2>&-` and `>&-`: the error still exits 2, the render still exits 0.
#[test]
fn item2_closed_stderr_or_stdout_keeps_the_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    let status = |script: &str| {
        Command::new("sh")
            .args(["-c", script, "sh", GLINT, &cornell()])
            .current_dir(dir.path())
            .stdout(Stdio::null())
            .status()
            .unwrap()
            .code()
    };
    assert_eq!(status(r#"exec "$1" render missing.toml 2>&-"#), Some(2));
    assert_eq!(
        status(r#"exec "$1" render "$2" --cpu --width 4 --height 4 --spp 1 -o y.png --bogus 2>&-"#),
        Some(2)
    );
    assert_eq!(
        status(
            r#"exec "$1" render "$2" --cpu --width 4 --height 4 --spp 1 -o y.png --json >&- 2>&-"#
        ),
        Some(0)
    );
    assert_eq!(files(dir.path()), ["y.png"]);
}

// ---- 3: outputs that are the same file, or an input ----

#[test]
fn item3_two_outputs_naming_one_file_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["-o", "x.exr", "--variance", "x.exr"], "same file"),
        (
            vec!["-o", "x.exr", "--variance", "sub/../x.exr"],
            "same file",
        ),
        (vec!["-o", "x.exr", "--variance", "./x.exr"], "same file"),
    ];
    for (extra, needle) in &cases {
        let out = render(dir.path(), &cornell(), extra);
        assert_refused(&out, needle, &format!("{extra:?}"));
    }
    assert_eq!(files(dir.path()), ["sub"]);
    // Through a symbolic link to the other output, existing or not.
    std::os::unix::fs::symlink("x.exr", dir.path().join("link.exr")).unwrap();
    let out = render(
        dir.path(),
        &cornell(),
        &["-o", "x.exr", "--variance", "link.exr"],
    );
    assert_refused(&out, "same file", "dangling link");
    std::fs::write(dir.path().join("x.exr"), b"old").unwrap();
    let out = render(
        dir.path(),
        &cornell(),
        &["-o", "link.exr", "--variance", "x.exr"],
    );
    assert_refused(&out, "same file", "link");
    // A hard link is the same file too.
    std::fs::hard_link(dir.path().join("x.exr"), dir.path().join("hard.exr")).unwrap();
    let out = render(
        dir.path(),
        &cornell(),
        &["-o", "hard.exr", "--variance", "x.exr"],
    );
    assert_refused(&out, "same file", "hard link");
    assert_eq!(std::fs::read(dir.path().join("x.exr")).unwrap(), b"old");
}

#[test]
fn item3_an_output_that_is_an_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // A scene whose name makes the default output (<stem>.png) the scene itself.
    let text = std::fs::read_to_string(scene_path("furnace.toml")).unwrap();
    std::fs::write(dir.path().join("scene.png"), &text).unwrap();
    let out = glint(dir.path(), &["render", "scene.png", "--cpu", "--spp", "1"]);
    assert_refused(&out, "the scene file", "default output onto the scene");
    // An output linked to the scene.
    std::os::unix::fs::symlink("scene.png", dir.path().join("out.png")).unwrap();
    let out = glint(
        dir.path(),
        &["render", "scene.png", "-o", "out.png", "--cpu"],
    );
    assert_refused(&out, "the scene file", "output linked to the scene");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("scene.png")).unwrap(),
        text
    );

    // compare --diff onto A or B.
    let image = Image {
        width: 1,
        height: 1,
        pixels: vec![[0.25; 3]],
    };
    image.write(&dir.path().join("a.exr")).unwrap();
    image.write(&dir.path().join("b.exr")).unwrap();
    let before = std::fs::read(dir.path().join("a.exr")).unwrap();
    for diff in ["a.exr", "./b.exr"] {
        let out = glint(dir.path(), &["compare", "a.exr", "b.exr", "--diff", diff]);
        assert_refused(&out, "would destroy an input", diff);
    }
    assert_eq!(std::fs::read(dir.path().join("a.exr")).unwrap(), before);
}

// ---- 6: rewriting keeps the mode and writes through links ----

#[test]
fn item6_rewriting_keeps_the_mode_and_follows_symlinks() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.png");
    std::fs::write(&path, b"old").unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
    let out = render(dir.path(), &cornell(), &["-o", "x.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let meta = std::fs::metadata(&path).unwrap();
    assert_eq!(meta.permissions().mode() & 0o777, 0o600);
    assert!(image::open(&path).is_ok());

    // A link into another folder: the target is rewritten, the link stays a link.
    std::fs::create_dir(dir.path().join("real")).unwrap();
    let target = dir.path().join("real/y.exr");
    std::fs::write(&target, b"old").unwrap();
    std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
    std::os::unix::fs::symlink("real/y.exr", dir.path().join("link.exr")).unwrap();
    let out = render(dir.path(), &cornell(), &["-o", "link.exr"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let link = std::fs::symlink_metadata(dir.path().join("link.exr")).unwrap();
    assert!(link.file_type().is_symlink());
    assert_eq!(
        std::fs::metadata(&target).unwrap().permissions().mode() & 0o777,
        0o640
    );
    assert_eq!(Image::read_exr(&target).unwrap().width, 8);
    // A dangling link: its target is created.
    std::os::unix::fs::symlink("real/new.exr", dir.path().join("dangling.exr")).unwrap();
    let out = render(dir.path(), &cornell(), &["-o", "dangling.exr"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("real/new.exr").is_file());
    assert_eq!(files(&dir.path().join("real")), ["new.exr", "y.exr"]);
}

// ---- 10: scene files that are not regular files, or too large ----

fn mkfifo(path: &Path) {
    let c_path = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c_path.as_ptr(), 0o600) }, 0);
}

#[test]
fn item10_special_scene_files_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    mkfifo(&dir.path().join("fifo.toml"));
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.toml")).unwrap();
    for (scene, needle) in [
        ("fifo.toml", "FIFO"),
        ("zero.toml", "character device"),
        (".", "folder"),
    ] {
        let started = Instant::now();
        let out = glint(dir.path(), &["render", scene, "-o", "x.png"]);
        assert_refused(&out, needle, scene);
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "{scene} blocked"
        );
    }
    assert_eq!(files(dir.path()), ["fifo.toml", "zero.toml"]);
}

#[test]
fn item10_a_scene_over_the_size_limit_is_refused_with_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let big = std::fs::File::create(dir.path().join("big.toml")).unwrap();
    // Sparse: no disk space, no time.
    big.set_len(glint::input_file::SCENE_FILE_LIMIT + 1)
        .unwrap();
    let out = glint(dir.path(), &["render", "big.toml", "-o", "x.png"]);
    assert_refused(&out, "64 MiB", "big scene");
    // Exactly at the limit it is read (and then refused as NUL bytes, not as too large).
    big.set_len(glint::input_file::SCENE_FILE_LIMIT).unwrap();
    let out = glint(dir.path(), &["render", "big.toml", "-o", "x.png"]);
    assert_refused(&out, "NUL", "scene at the limit");
}

// ---- 13: outputs that cannot be created, found before rendering ----

#[test]
fn item13_unwritable_outputs_fail_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("folder.png")).unwrap();
    // A render that would take minutes: the check must come first.
    let slow = ["--spp", "1000000"];
    for (output, needle) in [
        ("/proc/self/x.png", "cannot create files"),
        ("folder.png", "is a folder"),
        ("missing/x.png", "does not exist"),
        ("/proc/x.png", "cannot create files"),
    ] {
        let started = Instant::now();
        let mut extra = vec!["-o", output];
        extra.extend_from_slice(&slow);
        let out = render(dir.path(), &cornell(), &extra);
        assert_refused(&out, needle, output);
        assert!(started.elapsed() < Duration::from_secs(30), "{output}");
    }
    // --variance is checked as early.
    let out = render(
        dir.path(),
        &cornell(),
        &[
            "-o",
            "x.exr",
            "--variance",
            "/proc/self/v.exr",
            "--spp",
            "1000000",
        ],
    );
    assert_refused(&out, "--variance", "variance in /proc");
    if !is_root() {
        // Root may write anywhere: a read-only folder stops only other users.
        use std::os::unix::fs::PermissionsExt;
        let ro = dir.path().join("ro");
        std::fs::create_dir(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        let out = render(
            dir.path(),
            &cornell(),
            &["-o", "ro/x.png", "--spp", "1000000"],
        );
        assert_refused(&out, "cannot create files", "read-only folder");
    }
    assert_eq!(files(dir.path()).len(), 1 + (!is_root()) as usize);
}

// ---- 14: compare and the relative error ----

#[test]
fn item14_compare_refuses_png_inputs_even_named_exr() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(dir.path(), &cornell(), &["-o", "c.exr"]);
    assert!(out.status.success());
    let out = render(dir.path(), &cornell(), &["-o", "c.png"]);
    assert!(out.status.success());
    let out = glint(dir.path(), &["compare", "c.exr", "c.png"]);
    assert_refused(&out, "not an OpenEXR file", "png");
    std::fs::copy(dir.path().join("c.png"), dir.path().join("fake.exr")).unwrap();
    let out = glint(dir.path(), &["compare", "fake.exr", "c.exr"]);
    assert_refused(&out, "Png", "png named .exr");
}

#[test]
fn item14_compare_counts_nan_pixels_and_keeps_figures_finite() {
    let dir = tempfile::tempdir().unwrap();
    let b = Image {
        width: 3,
        height: 1,
        pixels: vec![[0.5; 3], [0.5; 3], [0.5; 3]],
    };
    let mut a = b.clone();
    a.pixels[0] = [f32::NAN, 0.5, 0.5];
    a.pixels[1] = [0.75, 0.5, f32::INFINITY];
    a.write(&dir.path().join("a.exr")).unwrap();
    b.write(&dir.path().join("b.exr")).unwrap();
    let out = glint(dir.path(), &["compare", "a.exr", "b.exr", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["nonfinite_a"], 2);
    assert_eq!(v["nonfinite_b"], 0);
    let rmse = v["rmse"].as_f64().expect("a finite RMSE, not null");
    // Seven finite channel pairs, one differing by 0.25.
    assert!((rmse - (0.0625f64 / 7.0).sqrt()).abs() < 1e-9, "{rmse}");
    assert_eq!(v["max_difference"].as_f64(), Some(0.25));
    assert!(stderr(&out).contains("non-finite"), "{}", stderr(&out));
    // A NaN in B too, in the text output.
    let out = glint(dir.path(), &["compare", "b.exr", "a.exr"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("non-finite      A 0  B 2"), "{text}");
}

#[test]
fn item14_relative_error_is_null_below_two_samples() {
    let dir = tempfile::tempdir().unwrap();
    let json = |spp: &str| -> Value {
        let out = glint(
            dir.path(),
            &[
                "render",
                &cornell(),
                "--cpu",
                "--width",
                "8",
                "--height",
                "8",
                "--spp",
                spp,
                "-o",
                "x.png",
                "--json",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    assert!(json("1")["relative_error"].is_null());
    assert!(json("2")["relative_error"].as_f64().unwrap() > 0.0);
}

#[test]
fn item14_target_error_on_a_black_image_says_it_never_applied() {
    let dir = tempfile::tempdir().unwrap();
    let black = std::fs::read_to_string(scene_path("furnace.toml"))
        .unwrap()
        .replace("strength = 0.5", "strength = 0.0");
    assert!(black.contains("strength = 0.0"), "furnace.toml changed");
    std::fs::write(dir.path().join("black.toml"), black).unwrap();
    let out = render(
        dir.path(),
        "black.toml",
        &[
            "-o",
            "x.png",
            "--target-error",
            "0.1",
            "--spp",
            "16",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["stopped_by"], "spp");
    assert!(v["relative_error"].is_null());
    assert!(
        stderr(&out).contains("--target-error never applied"),
        "{}",
        stderr(&out)
    );
}

/// A full disk while encoding: the message is the I/O error, not the encoder's "decoding".
#[test]
fn item14_a_full_disk_says_so_not_decoding() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let image = Image {
        width: 64,
        height: 64,
        pixels: vec![[0.5; 3]; 64 * 64],
    };
    for format in [
        glint::image::format::ImageFormat::Exr,
        glint::image::format::ImageFormat::Png,
    ] {
        let e = glint::image::atomic_write::encode_into(&full, Path::new("x"), |w| {
            image.encode(format, w)
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("No space left on device"), "{format:?}: {e}");
        assert!(!e.contains("ecoding"), "{format:?}: {e}");
    }
}
