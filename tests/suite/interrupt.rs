//! Renders that are stopped: SIGINT and SIGTERM write what is done (image, variance, a resumable
//! partial) and exit 130/143 with no temporary file left; a render SIGKILLed twice at random
//! moments and resumed is bit-identical to the uninterrupted one; a checkpoint folder deleted
//! mid-render gives one warning, checkpoints come back with the folder, and the final write fails
//! without it.
// A partial file's ranges are a list: a one-range list is what most of them hold.
#![allow(clippy::single_range_in_vec_init)]

use crate::common;
use glint::render::partial::Partial;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn cornell() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/cornell.toml")
        .display()
        .to_string()
}

/// A CPU render of the Cornell box at 32×32, 4 bounces, seed 9, in `dir`.
fn render_command(dir: &Path, extra: &[&str]) -> Command {
    let mut command = Command::new(GLINT);
    command
        .args([
            "render",
            &cornell(),
            "--cpu",
            "--seed",
            "9",
            "--max-bounces",
            "4",
        ])
        .args(["--width", "32", "--height", "32"])
        .args(extra)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    command
}

fn wait_for(what: &str, limit: Duration, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < limit, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .expect("run kill");
    assert!(status.success());
}

/// Waits (bounded) for the child to exit; its status and stderr.
fn finish(mut child: Child) -> (ExitStatus, String) {
    let mut status = None;
    wait_for("glint to exit", Duration::from_secs(60), || {
        status = child.try_wait().unwrap();
        status.is_some()
    });
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    (status.unwrap(), stderr)
}

fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".glint-"))
        .collect()
}

fn read(path: &Path) -> Partial {
    Partial::read(path).unwrap_or_else(|e| panic!("{e}"))
}

fn stop_with(signal_name: &str, code: i32) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Checkpoints after every batch, so the signal often arrives during a write.
    let child = render_command(
        d,
        &[
            "--spp",
            "1000000",
            "-o",
            "out.exr",
            "--variance",
            "out.var.exr",
        ],
    )
    .args(["--checkpoint-interval", "0"])
    .spawn()
    .unwrap();
    wait_for("a checkpoint", Duration::from_secs(60), || {
        d.join("out.exr").exists()
    });
    std::thread::sleep(Duration::from_millis(300));
    signal(&child, signal_name);
    let (status, stderr) = finish(child);
    assert_eq!(status.code(), Some(code), "{stderr}");
    assert!(
        stderr.contains(&format!("interrupted by SIG{signal_name}")),
        "{stderr}"
    );
    assert_eq!(temporaries(d), Vec::<String>::new());
    let out = read(&d.join("out.exr"));
    let n = out.accumulation.count;
    assert!(n > 0 && n < 1_000_000, "{n} spp");
    assert_eq!(out.info.ranges, vec![0..n]);
    // The variance image is of the same samples as the image.
    let variance = glint::image::output::Image::read_exr(&d.join("out.var.exr")).unwrap();
    assert_eq!(variance, out.accumulation.variance_image());
    // And the file resumes: one more batch on top of it.
    let resumed = render_command(d, &["--spp", "1000000", "--resume", "out.exr"])
        .args(["--time-limit", "0"])
        .output()
        .unwrap();
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let after = read(&d.join("out.exr"));
    assert!(after.accumulation.count > n);
    assert_eq!(after.info.ranges, vec![0..after.accumulation.count]);
}

#[test]
fn sigint_writes_what_is_done_and_exits_130() {
    stop_with("INT", 130);
}

#[test]
fn sigterm_writes_what_is_done_and_exits_143() {
    stop_with("TERM", 143);
}

#[test]
fn resuming_after_sigkill_gives_the_uninterrupted_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spp = ["--spp", "2048"];
    let single = render_command(d, &spp)
        .args(["-o", "single.exr"])
        .output()
        .unwrap();
    assert!(
        single.status.success(),
        "{}",
        String::from_utf8_lossy(&single.stderr)
    );
    let single = read(&d.join("single.exr"));
    // Two kills mid-render, each one after the render has written a new checkpoint (so it made
    // progress) and then a further 0–50 ms that vary from run to run (printed, to reproduce a
    // failure). Waiting for a checkpoint rather than a share of a timed render keeps this true
    // on machines of any speed and load. A render that finished before its kill is started
    // again from nothing; the attempts are bounded.
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    let spp_in = |path: &Path| path.exists().then(|| read(path).accumulation.count);
    let out_path = d.join("out.exr");
    let mut kills_mid_render = 0;
    for attempt in 0..8u32 {
        if kills_mid_render == 2 {
            break;
        }
        let before = spp_in(&out_path).unwrap_or(0);
        let mut command = render_command(d, &spp);
        command.args(["-o", "out.exr", "--checkpoint-interval", "0"]);
        if out_path.exists() {
            command.args(["--resume", "out.exr"]);
        }
        let mut child = command.spawn().unwrap();
        wait_for(
            "a new checkpoint or the end",
            Duration::from_secs(120),
            || child.try_wait().unwrap().is_some() || spp_in(&out_path).unwrap_or(0) > before,
        );
        let delay_ms = u64::from((nanos >> (attempt * 3)) % 51);
        std::thread::sleep(Duration::from_millis(delay_ms));
        child.kill().ok(); // SIGKILL; it may have exited already
        child.wait().unwrap();
        let state = spp_in(&out_path);
        eprintln!(
            "attempt {attempt}: from {before} spp, killed {delay_ms} ms after a checkpoint, \
             the file holds {state:?} spp"
        );
        if state == Some(2048) {
            std::fs::remove_file(&out_path).unwrap();
        } else {
            kills_mid_render += 1;
        }
    }
    assert_eq!(
        kills_mid_render, 2,
        "the renders kept finishing before the kill"
    );
    let mut command = render_command(d, &spp);
    command.args(["-o", "out.exr"]);
    if d.join("out.exr").exists() {
        command.args(["--resume", "out.exr"]);
    }
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let resumed = read(&d.join("out.exr"));
    assert_eq!(resumed.info.ranges, vec![0..2048]);
    let worst = common::merge_bound::worst_vs_bound(&resumed.accumulation, &single.accumulation);
    eprintln!("largest |resumed − uninterrupted| is {worst:.2e} of the bound");
    assert!(worst <= 1.0, "resumed differs by {worst} × the bound");
    // Checkpoints are written at batch ends, which are block ends of the kernel's fixed merge
    // schedule, so the resumed render merges the same blocks in the same order: same bits.
    assert!(
        resumed.accumulation == single.accumulation,
        "the resumed render is not bit-identical to the uninterrupted one"
    );
}

/// The checkpoint's folder is deleted mid-render: one warning, the render goes on, and the
/// checkpoints come back once the folder does. Without the folder at the end, the final write
/// fails (exit 1) and leaves nothing behind.
#[test]
fn a_failing_checkpoint_does_not_stop_the_render() {
    for recreate in [true, false] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let sub = d.join("sub");
        std::fs::create_dir(&sub).unwrap();
        let out = sub.join("out.exr");
        let child = render_command(d, &["--spp", "1000000", "-o", "sub/out.exr"])
            .args(["--checkpoint-interval", "0"])
            .spawn()
            .unwrap();
        wait_for("a checkpoint", Duration::from_secs(60), || out.exists());
        // glint writes a checkpoint's temporary file into the folder after every batch, so a
        // removal can race with a new file (DirectoryNotEmpty): retry until it is gone.
        wait_for("the folder removed", Duration::from_secs(30), || {
            std::fs::remove_dir_all(&sub).is_ok() || !sub.exists()
        });
        std::thread::sleep(Duration::from_millis(500));
        if recreate {
            std::fs::create_dir(&sub).unwrap();
            wait_for(
                "a checkpoint after the folder is back",
                Duration::from_secs(30),
                || out.exists(),
            );
        }
        signal(&child, "INT");
        let (status, stderr) = finish(child);
        assert_eq!(
            stderr
                .matches("warning: cannot write the checkpoint")
                .count(),
            1,
            "{stderr}"
        );
        if recreate {
            assert_eq!(status.code(), Some(130), "{stderr}");
            assert!(read(&out).accumulation.count > 0);
            assert_eq!(temporaries(&sub), Vec::<String>::new());
        } else {
            assert_eq!(status.code(), Some(1), "{stderr}");
            assert!(stderr.contains("sub/out.exr"), "{stderr}");
            assert!(!sub.exists());
        }
    }
}
