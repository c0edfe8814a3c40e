//! `glint view` end to end, in a window on an Xvfb display the test starts itself (the Xvfb
//! program must be installed), on the Vulkan device: the Cornell box's walls in the screenshot;
//! camera moves, R and resizes restart the accumulation and exposure does not; a scene edit is
//! reloaded and a broken one keeps the last good scene; no display is exit code 2; D denoises
//! (or says why not, once); I switches to bidirectional path tracing and what it saves is what
//! `glint render --integrator bdpt` writes; PNG screenshots follow --tonemap/--exposure; memory stays flat. The
//! hidden --script and --log-frames flags drive it and report each frame and event as JSON.

use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::Duration;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn skip_gpu() -> bool {
    let skip = std::env::var_os("GLINT_SKIP_GPU_TESTS").is_some();
    if skip {
        eprintln!("GLINT_SKIP_GPU_TESTS is set: skipping the viewer");
    }
    skip
}

/// An X server of our own, on a display number it picks (`-displayfd`), killed on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!("cannot start Xvfb ({e}): install the xvfb package, as .ci/run does")
            });
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let number = line.trim();
        assert!(
            !number.is_empty() && number.bytes().all(|b| b.is_ascii_digit()),
            "Xvfb did not report its display number (got {line:?})"
        );
        Xvfb {
            display: format!(":{number}"),
            child,
        }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// What each windowed test starts with: an X server of its own and a temporary folder to run
/// `glint view` in. None where the GPU tests are skipped.
struct Session {
    xvfb: Xvfb,
    dir: tempfile::TempDir,
}

impl Session {
    fn start() -> Option<Session> {
        if skip_gpu() {
            return None;
        }
        Some(Session {
            xvfb: Xvfb::start(),
            dir: tempfile::tempdir().unwrap(),
        })
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }

    /// `glint view ARGS --log-frames` on this display, in this folder.
    fn view(&self, args: &[&str]) -> Command {
        let mut cmd = Command::new(GLINT);
        cmd.arg("view")
            .args(args)
            .arg("--log-frames")
            .current_dir(self.path())
            .env("DISPLAY", &self.xvfb.display)
            .env_remove("WAYLAND_DISPLAY");
        cmd
    }

    /// `glint view` of the Cornell box at `width` × `height`, then `more`.
    fn view_cornell(&self, width: u32, height: u32, more: &[&str]) -> Command {
        let cornell = scene_path("cornell.toml");
        let (width, height) = (width.to_string(), height.to_string());
        let mut args = vec![
            cornell.to_str().unwrap(),
            "--width",
            &width,
            "--height",
            &height,
        ];
        args.extend_from_slice(more);
        self.view(&args)
    }

    /// Runs `cmd` to its end; its log, once it exited well.
    fn log_of(cmd: &mut Command) -> Vec<Value> {
        succeeded(&cmd.output().unwrap())
    }
}

fn lines(stdout: &[u8]) -> Vec<Value> {
    String::from_utf8_lossy(stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l:?}: {e}")))
        .collect()
}

fn frames(log: &[Value]) -> Vec<&Value> {
    log.iter()
        .filter(|l| l.get("frame").is_some() && l.get("event").is_none())
        .collect()
}

/// Each frame's samples per pixel.
fn frame_spp(log: &[Value]) -> Vec<u64> {
    frames(log)
        .iter()
        .map(|f| f["spp"].as_u64().unwrap())
        .collect()
}

/// I (the `integrator` script word) switched once, to `integrator`, without an error.
fn assert_switched_once_to(log: &[Value], integrator: &str) {
    let switched = events(log, "integrator");
    assert_eq!(switched.len(), 1, "{switched:?}");
    assert_eq!(switched[0]["integrator"], integrator);
    assert!(switched[0].get("error").is_none(), "{switched:?}");
}

fn events<'a>(log: &'a [Value], name: &str) -> Vec<&'a Value> {
    log.iter().filter(|l| l["event"] == name).collect()
}

fn succeeded(out: &Output) -> Vec<Value> {
    assert!(
        out.status.success(),
        "glint view failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    lines(&out.stdout)
}

/// Mean sRGB colour of a block of the PNG: columns and rows as fractions of the size.
fn mean_rgb(png: &image::RgbImage, x: (f32, f32), y: (f32, f32)) -> [f64; 3] {
    let (w, h) = (png.width() as f32, png.height() as f32);
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for py in (y.0 * h) as u32..(y.1 * h) as u32 {
        for px in (x.0 * w) as u32..(x.1 * w) as u32 {
            let p = png.get_pixel(px, py).0;
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// The side walls of the square Cornell view, at mid-height: between the box's front edge
/// (2% in from the border) and the back wall (22% in).
const LEFT_WALL: (f32, f32) = (0.06, 0.16);
const RIGHT_WALL: (f32, f32) = (0.84, 0.94);
const WALL_ROWS: (f32, f32) = (0.3, 0.7);
/// A block of the back wall, between the light above and the spheres below.
const BACK_WALL: ((f32, f32), (f32, f32)) = ((0.3, 0.7), (0.25, 0.5));

#[test]
fn cornell_screenshot_shows_the_green_and_red_walls() {
    let Some(session) = Session::start() else {
        return;
    };
    let log = Session::log_of(&mut session.view_cornell(
        96,
        96,
        &["--frames", "8", "--screenshot", "shot.png"],
    ));
    let frames = frames(&log);
    assert_eq!(frames.len(), 8);
    // The first frame is a 1-spp preview; then samples only accumulate.
    assert_eq!(frames[0]["spp"], 1);
    assert_eq!(frames[0]["restarted"], true);
    for pair in frames.windows(2) {
        assert_eq!(
            pair[1]["spp"].as_u64().unwrap(),
            pair[0]["spp"].as_u64().unwrap() + pair[1]["batch_spp"].as_u64().unwrap()
        );
        assert_eq!(pair[1]["restarted"], false);
    }
    assert!(frames.iter().all(|f| f["width"] == 96 && f["height"] == 96));
    let saved = events(&log, "saved");
    assert_eq!(saved.len(), 1);
    assert_eq!(saved[0]["spp"], frames[7]["spp"]);

    let png = image::open(session.path().join("shot.png"))
        .unwrap()
        .into_rgb8();
    assert_eq!(png.dimensions(), (96, 96));
    let left = mean_rgb(&png, LEFT_WALL, WALL_ROWS);
    let right = mean_rgb(&png, RIGHT_WALL, WALL_ROWS);
    assert!(left[1] > 1.5 * left[0], "left wall is green: {left:?}");
    assert!(right[0] > 1.5 * right[1], "right wall is red: {right:?}");
}

#[test]
fn i_switches_to_bdpt_and_the_viewer_holds_what_render_writes() {
    let Some(session) = Session::start() else {
        return;
    };
    // Path tracing for frames 0 and 1, then I: frame 2 restarts bidirectionally (a 1-spp
    // preview), and frames 3-5 add 4 spp each, 13 in all.
    let log = Session::log_of(&mut session.view_cornell(
        32,
        32,
        &[
            "--spp-per-frame",
            "4",
            "--frames",
            "6",
            "--script",
            "2:integrator",
            "--screenshot",
            "shot.exr",
        ],
    ));
    assert_switched_once_to(&log, "bdpt");
    let spp = frame_spp(&log);
    assert_eq!(spp, [1, 5, 1, 5, 9, 13]);
    let titles = events(&log, "title");
    assert!(
        titles
            .iter()
            .any(|t| t["title"].as_str().unwrap().contains("· bdpt")),
        "the title names the integrator: {titles:?}"
    );

    // The same samples through `glint render`: sample numbers depend only on the pixel, the
    // sample index and the seed, and the splat film's sums are exact, so the two agree to
    // rounding (the viewer accumulates in other batches). The light-tracing strategies carry a
    // large share of the box's radiance here; without the splat film the mean falls by it.
    let rendered = session.path().join("render.exr");
    let out = Command::new(GLINT)
        .args(["render", scene_path("cornell.toml").to_str().unwrap()])
        .args([
            "--gpu",
            "--integrator",
            "bdpt",
            "--width",
            "32",
            "--height",
            "32",
        ])
        .args(["--spp", "13", "-o", rendered.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let viewed = glint::image::output::Image::read_exr(&session.path().join("shot.exr")).unwrap();
    let rendered = glint::image::output::Image::read_exr(&rendered).unwrap();
    let mut largest = 0.0f32;
    for (v, r) in viewed.pixels.iter().zip(&rendered.pixels) {
        for c in 0..3 {
            largest = largest.max((v[c] - r[c]).abs() / r[c].abs().max(1e-3));
        }
    }
    assert!(
        largest < 1e-3,
        "viewer against render: relative difference {largest}"
    );
}

/// The kernel's bdpt has medium vertices: I in a fog scene switches to it like anywhere else
/// (no error, the accumulation restarts), and the window shows light.
#[test]
fn i_in_a_medium_switches_to_bdpt() {
    let Some(session) = Session::start() else {
        return;
    };
    let fog = scene_path("cornell-fog.toml");
    let log = Session::log_of(&mut session.view(&[
        fog.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--spp-per-frame",
        "1",
        "--frames",
        "4",
        "--script",
        "1:integrator",
        "--screenshot",
        "shot.exr",
    ]));
    assert_switched_once_to(&log, "bdpt");
    let spp = frame_spp(&log);
    assert_eq!(spp, [1, 1, 2, 3], "the switch restarts the accumulation");
    let shot = glint::image::output::Image::read_exr(&session.path().join("shot.exr")).unwrap();
    let mean = shot.mean();
    assert!(mean.is_finite() && mean > 0.0, "image mean {mean}");
}

#[test]
fn a_camera_move_restarts_the_accumulation_and_exposure_does_not() {
    let Some(session) = Session::start() else {
        return;
    };
    let log = Session::log_of(&mut session.view_cornell(
        48,
        48,
        &[
            "--spp-per-frame",
            "2",
            "--frames",
            "12",
            "--script",
            "3:orbit 40 0; 5:exposure 1; 6:pan 5 5; 7:dolly 1; 8:fly 0 0 0.1; 9:restart; 10:save-png",
        ],
    ));
    let spp = frame_spp(&log);
    // 1-spp previews at the start and after each move or restart, then 2 per frame.
    assert_eq!(spp, [1, 3, 5, 1, 3, 5, 1, 1, 1, 1, 3, 5]);
    let restarted: Vec<bool> = frames(&log)
        .iter()
        .map(|f| f["restarted"].as_bool().unwrap())
        .collect();
    assert_eq!(
        restarted,
        [true, false, false, true, false, false, true, true, true, true, false, false]
    );
    let saved = events(&log, "saved");
    assert_eq!(saved.len(), 1, "P saves once");
    let name = saved[0]["path"].as_str().unwrap();
    assert_eq!(name, "cornell-001.png");
    assert!(session.path().join(name).is_file());
}

#[test]
fn a_resize_restarts_at_the_new_size() {
    let Some(session) = Session::start() else {
        return;
    };
    let log = Session::log_of(&mut session.view_cornell(
        40,
        40,
        &[
            "--frames",
            "12",
            "--script",
            "2:resize 64 32",
            "--screenshot",
            "shot.exr",
        ],
    ));
    let resized = events(&log, "resize");
    assert_eq!(resized.len(), 1, "{log:?}");
    let last = *frames(&log).last().unwrap();
    assert_eq!(
        (last["width"].as_u64(), last["height"].as_u64()),
        (Some(64), Some(32))
    );
    let first_big = frames(&log).into_iter().find(|f| f["width"] == 64).unwrap();
    assert_eq!(first_big["spp"], 1, "the new size starts from a preview");
    let exr = glint::image::output::Image::read_exr(&session.path().join("shot.exr")).unwrap();
    assert_eq!((exr.width, exr.height), (64, 32));
}

/// Reads the viewer's log lines as they come.
fn spawn_with_log(mut cmd: Command) -> (Child, mpsc::Receiver<Value>) {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            let value = serde_json::from_str(&line).unwrap_or_else(|e| panic!("{line:?}: {e}"));
            if tx.send(value).is_err() {
                break;
            }
        }
    });
    (child, rx)
}

/// Replaces the file in one step, as editors do, so the viewer never reads half a file.
fn save_atomically(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// Log lines up to and including the first that `pred` accepts. The first line may take
/// minutes: lavapipe compiles the kernel's variant for the scene on a cold shader cache (3
/// minutes measured for a model scene on 2 busy cores).
fn wait_for(rx: &mpsc::Receiver<Value>, what: &str, pred: impl Fn(&Value) -> bool) -> Vec<Value> {
    let mut seen = Vec::new();
    loop {
        let line = rx
            .recv_timeout(Duration::from_secs(600))
            .unwrap_or_else(|_| panic!("no {what} in the viewer's log; got {seen:?}"));
        let done = pred(&line);
        seen.push(line);
        if done {
            return seen;
        }
    }
}

/// Drives a viewer whose script holds two `wait-edit`s through `good` then `broken` (each
/// an edit on disk, made when the viewer waits for it); checks that it exits well, reloads
/// the good edit and refuses the broken one. The refusal's message and each frame's spp.
fn good_then_broken_edit(
    (child, rx): (Child, mpsc::Receiver<Value>),
    good: impl FnOnce(),
    broken: impl FnOnce(),
) -> (String, Vec<u64>) {
    let waiting = |v: &Value| v["event"] == "waiting-for-edit";
    let mut log = wait_for(&rx, "first wait", waiting);
    good();
    log.extend(wait_for(&rx, "second wait", waiting));
    broken();
    log.extend(rx.iter());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}: {stderr}", out.status);
    let reloads = events(&log, "reload");
    assert_eq!(reloads.len(), 2, "{log:?}");
    assert_eq!(reloads[0]["ok"].as_bool(), Some(true), "{log:?}");
    assert_eq!(reloads[1]["ok"].as_bool(), Some(false), "{log:?}");
    let error = reloads[1]["error"].as_str().unwrap().to_owned();
    let spp = frame_spp(&log);
    (error, spp)
}

#[test]
fn scene_edits_on_disk_are_picked_up_and_broken_ones_keep_the_last_good_scene() {
    let Some(session) = Session::start() else {
        return;
    };
    let scene = session.path().join("box.toml");
    let original = std::fs::read_to_string(scene_path("cornell.toml")).unwrap();
    std::fs::write(&scene, &original).unwrap();
    // `wait-edit` holds the viewer at a frame until the file changes, so the edits land at
    // known frames; the change itself is found by the same polling as any edit.
    let (child, rx) = spawn_with_log(session.view(&[
        "box.toml",
        "--width",
        "48",
        "--height",
        "48",
        "--spp-per-frame",
        "4",
        "--frames",
        "14",
        "--script",
        "3:wait-edit; 8:wait-edit",
        "--screenshot",
        "shot.png",
    ]));
    let waiting = |v: &Value| v["event"] == "waiting-for-edit";
    let mut log = wait_for(&rx, "first wait", waiting);
    // The red wall turns blue.
    let red = "color = [0.65, 0.05, 0.05]";
    assert!(original.contains(red));
    let blue = original.replace(red, "color = [0.05, 0.05, 0.65]");
    save_atomically(&scene, &blue);
    log.extend(wait_for(&rx, "second wait", waiting));
    // A broken edit: a negative radius.
    let broken = blue.replacen("radius = 90.0", "radius = -2.0", 1);
    assert_ne!(broken, blue);
    save_atomically(&scene, &broken);
    log.extend(rx.iter());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}: {stderr}", out.status);

    let reloads = events(&log, "reload");
    assert_eq!(reloads.len(), 2, "{log:?}");
    assert_eq!(
        (reloads[0]["ok"].as_bool(), reloads[0]["frame"].as_u64()),
        (Some(true), Some(3))
    );
    assert_eq!(
        (reloads[1]["ok"].as_bool(), reloads[1]["frame"].as_u64()),
        (Some(false), Some(8))
    );
    let error = reloads[1]["error"].as_str().unwrap();
    assert!(
        error.contains("box.toml:") && error.contains("radius"),
        "{error}"
    );
    assert!(stderr.contains("keeping the last good scene"), "{stderr}");
    assert!(stderr.contains("radius"), "{stderr}");

    let spp = frame_spp(&log);
    // The good edit restarts; the broken one changes nothing.
    assert_eq!(spp, [1, 5, 9, 1, 5, 9, 13, 17, 21, 25, 29, 33, 37, 41]);
    let png = image::open(session.path().join("shot.png"))
        .unwrap()
        .into_rgb8();
    let right = mean_rgb(&png, RIGHT_WALL, WALL_ROWS);
    assert!(
        right[2] > 1.5 * right[0],
        "the right wall turned blue: {right:?}"
    );
}

#[test]
fn no_display_is_a_one_line_error_with_exit_code_2() {
    let cornell = scene_path("cornell.toml");
    let out = Command::new(GLINT)
        .args(["view", cornell.to_str().unwrap()])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].contains("no display"), "{stderr}");
    assert!(lines[0].contains("glint render"), "{stderr}");
}

#[test]
fn bad_view_input_is_reported_before_any_window() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_path("cornell.toml");
    for args in [
        vec!["view", "missing.toml"],
        vec![
            "view",
            cornell.to_str().unwrap(),
            "--screenshot",
            "shot.bmp",
        ],
        vec![
            "view",
            cornell.to_str().unwrap(),
            "--screenshot",
            "no/such/dir/shot.png",
        ],
        vec!["view", cornell.to_str().unwrap(), "--script", "1:spin"],
        vec!["view", cornell.to_str().unwrap(), "--frames", "0"],
    ] {
        let out = Command::new(GLINT)
            .args(&args)
            .current_dir(dir.path())
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("no display"), "{args:?}: {stderr}");
    }
}

/// Issue 15, item 10: the scene file replaced by a FIFO (whose open() blocks until a writer
/// comes) or by a link to /dev/zero (which never ends) must not freeze the window: the reload
/// fails with a clear error and frames keep coming.
#[test]
fn a_scene_replaced_by_a_fifo_or_dev_zero_does_not_freeze_the_window() {
    let Some(session) = Session::start() else {
        return;
    };
    let scene = session.path().join("box.toml");
    std::fs::copy(scene_path("cornell.toml"), &scene).unwrap();
    let (mut child, rx) = spawn_with_log(session.view(&[
        "box.toml",
        "--width",
        "32",
        "--height",
        "32",
        "--spp-per-frame",
        "1",
    ]));
    let is_frame = |v: &Value| v.get("frame").is_some() && v.get("event").is_none();
    wait_for(&rx, "a first frame", is_frame);
    type MakeSpecialFile<'a> = &'a dyn Fn(&Path);
    let replacements: [(&str, MakeSpecialFile); 2] = [
        ("FIFO", &|tmp: &Path| {
            let c_path = std::ffi::CString::new(tmp.to_str().unwrap()).unwrap();
            // SAFETY: a valid NUL-terminated path.
            assert_eq!(unsafe { libc::mkfifo(c_path.as_ptr(), 0o600) }, 0);
        }),
        ("character device", &|tmp: &Path| {
            std::os::unix::fs::symlink("/dev/zero", tmp).unwrap();
        }),
    ];
    for (needle, make) in replacements {
        let tmp = session.path().join("new.tmp");
        make(&tmp);
        std::fs::rename(&tmp, &scene).unwrap();
        let reload = wait_for(&rx, "the failed reload", |v| v["event"] == "reload");
        let error = reload.last().unwrap()["error"]
            .as_str()
            .unwrap()
            .to_string();
        assert!(error.contains(needle), "{error}");
        // Frames go on after it.
        for _ in 0..3 {
            wait_for(&rx, "frames after the reload", is_frame);
        }
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

/// Whether Open Image Denoise loads here; where it does not, the denoising test says so and
/// passes, except under GLINT_REQUIRE_OIDN (set by .ci/run, which installs it).
fn oidn_available() -> bool {
    match glint::image::denoise::oidn() {
        Ok(_) => true,
        Err(e) if std::env::var_os("GLINT_REQUIRE_OIDN").is_some() => {
            panic!("GLINT_REQUIRE_OIDN is set: {e}")
        }
        Err(e) => {
            eprintln!("skipping: {e}");
            false
        }
    }
}

/// How far each pixel of a block of the PNG (as in [`mean_rgb`]) is from the mean of its left
/// and right neighbours, on average, in sRGB levels: pixel noise raises it, while a smooth wall
/// (its shading a gradient, which this second difference cancels) keeps it near 0.
fn roughness(png: &image::RgbImage, x: (f32, f32), y: (f32, f32)) -> f64 {
    let (w, h) = (png.width() as f32, png.height() as f32);
    let mut sum = 0.0;
    let mut n = 0.0;
    for y in (y.0 * h) as u32..(y.1 * h) as u32 {
        for x in (x.0 * w) as u32 + 1..(x.1 * w) as u32 - 1 {
            let level = |x: u32, c: usize| png.get_pixel(x, y).0[c] as f64;
            for c in 0..3 {
                sum += (level(x, c) - 0.5 * (level(x - 1, c) + level(x + 1, c))).abs();
                n += 1.0;
            }
        }
    }
    sum / n
}

#[test]
fn d_denoises_the_shown_image_and_the_title_says_so() {
    let Some(session) = Session::start() else {
        return;
    };
    if !oidn_available() {
        return;
    }
    let run = |script: &str, shot: &str| {
        let mut args = vec![
            "--spp-per-frame",
            "2",
            "--frames",
            "10",
            "--screenshot",
            shot,
        ];
        if !script.is_empty() {
            args.extend(["--script", script]);
        }
        Session::log_of(&mut session.view_cornell(48, 48, &args))
    };
    // D before the first frame; `wait-denoised` holds frame 3 until the background denoise
    // started at frame 1 (the first with 2 spp or more) lands.
    let log = run("0:denoise; 3:wait-denoised", "denoised.png");
    let raw_log = run("", "raw.png");

    let toggles = events(&log, "denoise");
    assert_eq!(toggles.len(), 1, "{log:?}");
    assert_eq!(toggles[0]["on"], true);
    let landed = events(&log, "denoised");
    assert!(!landed.is_empty(), "{log:?}");
    assert_eq!(landed[0]["frame"], 3);
    let shown: Vec<bool> = frames(&log)
        .iter()
        .map(|f| f["denoised"].as_bool().unwrap())
        .collect();
    assert_eq!(shown[..3], [false; 3], "nothing denoised before frame 3");
    assert!(shown[3..].iter().all(|&s| s), "{shown:?}");
    let titles: Vec<&str> = events(&log, "title")
        .iter()
        .map(|t| t["title"].as_str().unwrap())
        .collect();
    assert!(!titles.is_empty());
    assert!(
        titles.iter().all(|t| t.contains("· denoised")),
        "{titles:?}"
    );
    assert!(events(&raw_log, "title")
        .iter()
        .all(|t| !t["title"].as_str().unwrap().contains("denoised")));
    // The AOVs change nothing in the accumulation: both runs reach the same samples.
    assert_eq!(frame_spp(&log), frame_spp(&raw_log));

    // The screenshot is the denoised image of the same samples: smooth where the raw one is
    // noisy (19 spp), with the walls' colours kept.
    let open = |name: &str| image::open(session.path().join(name)).unwrap().into_rgb8();
    let (denoised, raw) = (open("denoised.png"), open("raw.png"));
    for (cols, rows) in [(LEFT_WALL, WALL_ROWS), (RIGHT_WALL, WALL_ROWS), BACK_WALL] {
        let (rough_denoised, rough_raw) = (
            roughness(&denoised, cols, rows),
            roughness(&raw, cols, rows),
        );
        eprintln!("roughness: denoised {rough_denoised:.2}, raw {rough_raw:.2}");
        assert!(
            rough_denoised < 0.5 * rough_raw,
            "denoised {rough_denoised}, raw {rough_raw}"
        );
        let (d, r) = (mean_rgb(&denoised, cols, rows), mean_rgb(&raw, cols, rows));
        eprintln!("wall: denoised {d:?}, raw {r:?}");
        // The raw block mean's own noise is under 1 level (σ ≈ 6 levels per pixel over ~100
        // pixels); 8 levels catch a denoiser that darkens or tints a wall.
        for c in 0..3 {
            assert!((d[c] - r[c]).abs() < 8.0, "denoised {d:?}, raw {r:?}");
        }
    }
}

#[test]
fn d_without_oidn_keeps_the_raw_image_and_says_why_once() {
    let Some(session) = Session::start() else {
        return;
    };
    let out = session
        .view_cornell(
            32,
            32,
            &[
                "--spp-per-frame",
                "1",
                "--frames",
                "6",
                "--script",
                "0:denoise; 2:denoise; 4:denoise",
            ],
        )
        // An explicit library path that does not exist is the only place looked.
        .env("GLINT_OIDN_LIB", "/nonexistent/libOpenImageDenoise.so")
        .output()
        .unwrap();
    let log = succeeded(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let why: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("Open Image Denoise"))
        .collect();
    assert_eq!(why.len(), 1, "{stderr}");
    assert!(why[0].contains("raw image"), "{stderr}");
    assert!(why[0].contains("pip install pyoidn"), "{stderr}");
    let toggles = events(&log, "denoise");
    assert_eq!(toggles.len(), 3, "{log:?}");
    assert!(toggles.iter().all(|t| t["on"] == false));
    assert!(events(&log, "denoised").is_empty());
    assert!(frames(&log).iter().all(|f| f["denoised"] == false));
    let titles = events(&log, "title");
    assert!(!titles.is_empty());
    for title in titles {
        let title = title["title"].as_str().unwrap();
        assert!(title.contains("no denoiser"), "{title}");
        assert!(!title.contains("· denoised"), "{title}");
    }
}

/// A PNG screenshot goes through `--tonemap` and `--exposure` (src/image/tonemap.rs) exactly; an EXR
/// one stays linear. Same flags and frames, so both runs hold the same samples.
#[test]
fn tonemap_and_exposure_shape_png_screenshots_only() {
    let Some(session) = Session::start() else {
        return;
    };
    for shot in ["shot.exr", "shot.png"] {
        Session::log_of(&mut session.view_cornell(
            32,
            32,
            &[
                "--spp-per-frame",
                "2",
                "--frames",
                "4",
                "--tonemap",
                "agx",
                "--exposure",
                "1.5",
                "--screenshot",
                shot,
            ],
        ));
    }
    let linear = glint::image::output::Image::read_exr(&session.path().join("shot.exr")).unwrap();
    let expected = glint::image::tonemap::DisplayTransform {
        tonemap: glint::image::tonemap::Tonemap::Agx,
        exposure: 1.5,
    }
    .image(&linear)
    .to_srgb8();
    let png = image::open(session.path().join("shot.png"))
        .unwrap()
        .into_rgb8();
    assert_eq!(png.into_raw(), expected);
}

/// `--tonemap` and `--exposure` are `glint render`'s (src/cli/tone.rs): the same values are
/// refused the same way, in one line, before any window.
#[test]
fn bad_tonemap_or_exposure_for_view_exits_2() {
    let cornell = scene_path("cornell.toml");
    for (flag, value, needle) in [
        ("--tonemap", "foo", "clamp, aces or agx"),
        ("--exposure", "nan", "finite"),
        ("--exposure", "inf", "finite"),
    ] {
        let out = Command::new(GLINT)
            .args(["view", cornell.to_str().unwrap(), flag, value])
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{flag} {value}: {stderr}");
        assert!(
            stderr.starts_with("glint: error:") && stderr.contains(flag) && stderr.contains(needle),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"));
    }
}

/// Resident memory of a running process, in bytes (Linux: `VmRSS` in /proc/PID/status).
fn resident_bytes(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let kib: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap();
    kib * 1024
}

/// The viewer must run for hours: its memory stops growing once it runs. Debian 12's lavapipe
/// (Mesa 22.3) recompiled the kernel and the display shader at every frame and kept each copy
/// (src/gpu/inline_uniforms.rs): about 0.4 MB a frame, 120 MB over the 300 frames measured
/// here. After start-up (the first 100 frames), the next 300 may add at most 16 MB.
#[test]
fn the_viewer_memory_stops_growing() {
    let Some(session) = Session::start() else {
        return;
    };
    let cmd = session.view_cornell(64, 64, &["--spp-per-frame", "1", "--frames", "420"]);
    let (mut child, rx) = spawn_with_log(cmd);
    let frame = |n: u64| move |l: &Value| l["frame"].as_u64() == Some(n);
    wait_for(&rx, "frame 100", frame(100));
    let after_start = resident_bytes(child.id());
    wait_for(&rx, "frame 400", frame(400));
    let later = resident_bytes(child.id());
    assert!(child.wait().unwrap().success());
    let growth = later.saturating_sub(after_start);
    eprintln!("resident memory: {after_start} bytes at frame 100, {later} at frame 400");
    assert!(
        growth < 16 << 20,
        "the viewer grew by {growth} bytes over 300 frames ({after_start} → {later})"
    );
}

#[test]
fn a_model_file_is_viewed_and_its_edits_are_picked_up() {
    let Some(session) = Session::start() else {
        return;
    };
    let model = session.path().join("lc.gltf");
    let original = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models/lights-cameras.gltf"),
    )
    .unwrap();
    std::fs::write(&model, &original).unwrap();
    let (child, rx) = spawn_with_log(session.view(&[
        "lc.gltf",
        "--camera",
        "1",
        "--width",
        "32",
        "--height",
        "24",
        "--spp-per-frame",
        "2",
        "--frames",
        "10",
        "--script",
        "3:wait-edit; 6:wait-edit",
    ]));
    // A dimmer point light, then a negative intensity.
    let bright = "\"intensity\": 6830";
    assert!(original.contains(bright));
    let (error, spp) = good_then_broken_edit(
        (child, rx),
        || save_atomically(&model, &original.replace(bright, "\"intensity\": 683")),
        || save_atomically(&model, &original.replace(bright, "\"intensity\": -1")),
    );
    assert!(
        error.contains("lc.gltf") && error.contains("lights[0].intensity"),
        "{error}"
    );
    assert_eq!(spp, [1, 3, 5, 1, 3, 5, 7, 9, 11, 13]);
}

/// The viewer watches every file the scene's load read, not only the scene file: an edited
/// texture is picked up, and a broken one keeps the last good scene.
#[test]
fn edits_of_a_scenes_texture_are_picked_up() {
    let Some(session) = Session::start() else {
        return;
    };
    let dir = session.path();
    std::fs::write(
        dir.join("s.toml"),
        "[camera]\neye = [0, 0, -5]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\n\
         [render]\nwidth = 16\nheight = 16\nspp = 1\nmax_bounces = 1\nbackground = [1, 1, 1]\n\
         [materials.m]\ntype = \"diffuse\"\ncolor = { texture = \"t.png\" }\n\
         [[spheres]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
    )
    .unwrap();
    let texture = dir.join("t.png");
    let save_png = |grey: u8| {
        let tmp = dir.join("t.tmp.png");
        image::GrayImage::from_pixel(2, 2, image::Luma([grey]))
            .save(&tmp)
            .unwrap();
        std::fs::rename(&tmp, &texture).unwrap();
    };
    save_png(100);
    let (child, rx) = spawn_with_log(session.view(&[
        "s.toml",
        "--spp-per-frame",
        "2",
        "--frames",
        "10",
        "--script",
        "3:wait-edit; 6:wait-edit",
    ]));
    let (error, spp) = good_then_broken_edit(
        (child, rx),
        || save_png(200),
        || save_atomically(&texture, "not a PNG"),
    );
    assert!(error.contains("t.png"), "{error}");
    assert_eq!(spp, [1, 3, 5, 1, 3, 5, 7, 9, 11, 13]);
}
