//! A long GPU render's memory stops growing. Debian 12's lavapipe (Mesa 22.3) recompiled the
//! kernel at every dispatch and kept every copy (src/gpu/inline_uniforms.rs): a 48² render of
//! the bunny grew by about 33 MB/s until the machine ran out of memory.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

/// Resident memory of a running process, in bytes (Linux: `VmRSS` in /proc/PID/status); None
/// once it has exited.
fn resident_bytes(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let kib: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())?;
    Some(kib * 1024)
}

fn render(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut cmd = Command::new(GLINT);
    cmd.args(["render", "--gpu", "--width", "32", "--height", "32"])
        .arg(scene)
        .arg("-o")
        .arg(out)
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    cmd
}

/// After a first run has filled the shader cache, a 6-second render of the bunny (hundreds of
/// dispatches) may grow by at most 16 MB between its 2nd and its 5th second; the leak grew by
/// about 100 MB there.
#[test]
fn a_long_gpu_render_does_not_grow() {
    if std::env::var_os("GLINT_SKIP_GPU_TESTS").is_some() {
        eprintln!("GLINT_SKIP_GPU_TESTS is set: skipping");
        return;
    }
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bunny.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bunny.png");
    let warm = render(&scene, &out, &["--spp", "4"]).output().unwrap();
    assert!(
        warm.status.success(),
        "{}",
        String::from_utf8_lossy(&warm.stderr)
    );
    let mut child = render(&scene, &out, &["--spp", "1000000", "--time-limit", "6"])
        .spawn()
        .unwrap();
    let started = Instant::now();
    let at = |seconds: u64| {
        let when = Duration::from_secs(seconds);
        std::thread::sleep(when.saturating_sub(started.elapsed()));
        resident_bytes(child.id()).expect("the render ended early")
    };
    let early = at(2);
    let late = at(5);
    let status = child.wait().unwrap();
    assert!(status.success(), "render failed: {status}");
    let growth = late.saturating_sub(early);
    eprintln!("resident memory: {early} bytes at 2 s, {late} at 5 s");
    assert!(
        growth < 16 << 20,
        "the render grew by {growth} bytes in 3 s ({early} → {late})"
    );
}
