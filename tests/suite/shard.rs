//! Partial renders and `glint merge`, end to end: 4 shards merged against one render of the same
//! seed, on the GPU and the CPU, within the rounding bound the docs derive (bit-identical when the
//! shards are the single render's batches); GPU shards merged with CPU shards pass the Z-test
//! against another seed's render; every refusal of `merge` (settings, seed, size, spp, overlaps,
//! gaps, --allow-gaps), truncated and corrupted partial files, bad --samples/--shard values, and
//! --shard auto from Slurm's and Kubernetes' variables.
// A partial file's ranges are a list: a one-range list is what most of them hold.
#![allow(clippy::single_range_in_vec_init)]

use crate::common;
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::gpu::GpuRenderer;
use glint::image::compare::compare;
use glint::render::accumulation::Accumulation;
use glint::render::partial::Partial;
use glint::render::Renderer;
use glint::scene::Sampler;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn cornell() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/cornell.toml")
        .display()
        .to_string()
}

/// A small, quick Cornell box: 24×24, 4 bounces.
const SMALL: [&str; 6] = ["--width", "24", "--height", "24", "--max-bounces", "4"];

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run glint")
}

fn ok(out: &Output) -> &Output {
    assert!(
        out.status.success(),
        "exit {:?}: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Exit code 2 with a one-line message (no panic) that mentions every one of `names`.
fn refused(out: &Output, names: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for name in names {
        assert!(stderr.contains(name), "{name} not in: {stderr}");
    }
    stderr
}

fn render(dir: &Path, device: &str, extra: &[&str]) {
    let scene = cornell();
    let mut args = vec!["render", scene.as_str(), device];
    // SMALL's settings, less those `extra` sets itself (clap refuses a flag given twice).
    for pair in SMALL.chunks(2) {
        if !extra.contains(&pair[0]) {
            args.extend(pair);
        }
    }
    args.extend(extra);
    ok(&glint(dir, &args));
}

fn read(path: &Path) -> Partial {
    Partial::read(path).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders 16 spp in 4 shards on `device`, merges them, and checks the result against a
/// single render of the same seed.
fn shards_merge_to_the_single_render(device: &str) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(
        d,
        device,
        &["--spp", "16", "--seed", "3", "-o", "single.exr"],
    );
    let mut parts = Vec::new();
    for i in 0..4 {
        let part = format!("part-{i}.exr");
        let shard = format!("{i}/4");
        render(
            d,
            device,
            &["--spp", "16", "--seed", "3", "--shard", &shard, "-o", &part],
        );
        let p = read(&d.join(&part));
        assert_eq!(p.info.ranges, vec![4 * i..4 * i + 4]);
        assert_eq!(p.accumulation.count, 4);
        parts.push(part);
    }
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(String::as_str));
    args.extend(["-o", "merged.exr", "--variance", "merged.var.exr", "--json"]);
    let out = glint(d, &args);
    let summary: Value = serde_json::from_slice(&ok(&out).stdout).unwrap();
    assert_eq!(summary["spp"], 16);
    assert_eq!(summary["samples"], "0..16");
    assert_eq!(summary["missing"], "");
    let merged = read(&d.join("merged.exr"));
    let single = read(&d.join("single.exr"));
    assert_eq!(merged.info.ranges, vec![0..16]);
    let worst = common::merge_bound::worst_vs_bound(&merged.accumulation, &single.accumulation);
    eprintln!("{device}: largest |merged − single| is {worst:.2e} of the bound");
    assert!(
        worst <= 1.0,
        "{device}: merged differs by {worst} × the bound"
    );
    // The variance image is M2/(n(n−1)) of the merged statistics.
    let variance = glint::image::output::Image::read_exr(&d.join("merged.var.exr")).unwrap();
    assert_eq!(variance, merged.accumulation.variance_image());
    // Any EXR reader sees the mean as the RGB image.
    let rgb = glint::image::output::Image::read_exr(&d.join("merged.exr")).unwrap();
    assert_eq!(rgb.pixels, merged.accumulation.mean);
}

#[test]
fn cpu_shards_merge_to_the_single_render() {
    shards_merge_to_the_single_render("--cpu");
}

#[test]
fn gpu_shards_merge_to_the_single_render() {
    if common::gpu().is_none() {
        return;
    }
    shards_merge_to_the_single_render("--gpu");
}

/// Shards that are exactly a single render's batches merge to the same bits: the merge repeats
/// the kernel's pairwise update in the same order. With either sampler: a sample's numbers
/// depend on its global index, not on the batch or shard that renders it.
#[test]
fn shards_that_are_the_batches_merge_bit_identically() {
    for sampler in [Sampler::Independent, Sampler::Sobol] {
        shards_merge_bit_identically(sampler);
    }
}

fn shards_merge_bit_identically(sampler: Sampler) {
    let mut scene = common::shipped_scene("cornell.toml");
    scene.render.width = 16;
    scene.render.height = 16;
    scene.render.max_bounces = 4;
    scene.render.sampler = sampler;
    let scene = scene.kernel_scene();
    let check = |make: &mut dyn FnMut() -> Box<dyn Renderer>, device: &str| {
        let mut single = make();
        for _ in 0..3 {
            single.add_samples(4).unwrap();
        }
        let single = single.read_accumulation().unwrap();
        let mut merged = Accumulation::empty(16, 16);
        for start in [0, 4, 8] {
            let mut shard = make();
            shard.load_accumulation(start, None).unwrap();
            shard.add_samples(4).unwrap();
            merged.merge(&shard.read_accumulation().unwrap());
        }
        assert_eq!(merged.count, 12);
        let differing = (0..single.mean.len())
            .filter(|&i| merged.mean[i] != single.mean[i] || merged.m2[i] != single.m2[i])
            .count();
        assert_eq!(
            differing, 0,
            "{device}, {sampler:?}: pixels differing from the single render"
        );
    };
    check(&mut || Box::new(CpuRenderer::new(&scene)), "cpu");
    if let Some(ctx) = common::gpu() {
        check(
            &mut || Box::new(GpuRenderer::new(ctx, &scene).unwrap()),
            "gpu",
        );
    }
}

/// Shards rendered on the GPU merged with shards rendered on the CPU against a single CPU
/// render of another seed: the per-pixel Z-test of `glint compare` (|z| ≤ 2.576, so about 99%
/// of pixel channels for unbiased estimates with honest variances; 95% allows for the
/// Cornell box's heavy-tailed pixels at 64 spp, as tests/suite/statistics.rs does) and no overall
/// bias (|z of the image means| < 4).
#[test]
fn gpu_and_cpu_shards_merge_to_an_unbiased_image() {
    if common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let common = ["--spp", "64", "--seed", "5"];
    for (i, device) in ["--gpu", "--cpu", "--gpu", "--cpu"].iter().enumerate() {
        let mut args = common.to_vec();
        let shard = format!("{i}/4");
        let part = format!("part-{i}.exr");
        args.extend(["--shard", &shard, "-o", &part]);
        render(d, device, &args);
    }
    ok(&glint(
        d,
        &[
            "merge",
            "part-0.exr",
            "part-1.exr",
            "part-2.exr",
            "part-3.exr",
            "-o",
            "merged.exr",
            "--variance",
            "merged.var.exr",
        ],
    ));
    render(
        d,
        "--cpu",
        &[
            "--spp",
            "64",
            "--seed",
            "6",
            "-o",
            "single.exr",
            "--variance",
            "single.var.exr",
        ],
    );
    let merged = read(&d.join("merged.exr"));
    assert!(merged.info.device.contains("cpu") && merged.info.device.contains(','));
    let single = read(&d.join("single.exr"));
    let c = compare(
        &merged.accumulation.mean_image(),
        &single.accumulation.mean_image(),
        Some((
            &merged.accumulation.variance_image(),
            &single.accumulation.variance_image(),
        )),
    )
    .unwrap();
    let z = c.z_test.unwrap();
    eprintln!(
        "pass rate {:.4}, z of means {:.2}, variance ratio {:.2}",
        z.pass_rate, z.z_of_means, z.variance_ratio
    );
    assert!(z.pass_rate >= 0.95, "pass rate {}", z.pass_rate);
    assert!(z.z_of_means.abs() < 4.0, "z of means {}", z.z_of_means);
}

/// Four CPU shards of 8 spp (2 each) of the small Cornell box, seed 1, in `dir`.
fn four_parts(dir: &Path) -> Vec<PathBuf> {
    (0..4)
        .map(|i| {
            let part = format!("part-{i}.exr");
            let shard = format!("{i}/4");
            render(
                dir,
                "--cpu",
                &["--spp", "8", "--seed", "1", "--shard", &shard, "-o", &part],
            );
            dir.join(part)
        })
        .collect()
}

fn merge(dir: &Path, parts: &[&str], extra: &[&str]) -> Output {
    let mut args = vec!["merge"];
    args.extend(parts);
    args.extend(["-o", "merged.exr"]);
    args.extend(extra);
    glint(dir, &args)
}

#[test]
fn merge_refuses_parts_of_other_renders_overlaps_and_gaps() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    four_parts(d);
    let render_part = |name: &str, extra: &[&str]| {
        let mut args = vec!["--spp", "8", "--seed", "1", "--shard", "1/4", "-o", name];
        args.extend(extra);
        render(d, "--cpu", &args);
    };
    // Another scene setting, seed, size and total spp, each in place of part 1.
    render_part("bounces.exr", &["--max-bounces", "3"]);
    render_part("light.exr", &["--light-sampling", "off"]);
    render(
        d,
        "--cpu",
        &[
            "--spp", "8", "--seed", "2", "--shard", "1/4", "-o", "seed.exr",
        ],
    );
    render_part("size.exr", &["--width", "23"]);
    render(
        d,
        "--cpu",
        &[
            "--spp",
            "16",
            "--seed",
            "1",
            "--samples",
            "2..4",
            "-o",
            "spp.exr",
        ],
    );
    for (odd, what) in [
        ("bounces.exr", "different scenes or settings"),
        ("light.exr", "different scenes or settings"),
        ("seed.exr", "seed"),
        ("size.exr", "24×24"),
        ("spp.exr", "16 spp"),
    ] {
        let out = merge(d, &["part-0.exr", odd, "part-2.exr", "part-3.exr"], &[]);
        let message = refused(&out, &["part-0.exr", odd, what]);
        assert_eq!(message.lines().count(), 1, "{message}");
    }
    // Overlaps: a part twice, and ranges that cross.
    let out = merge(
        d,
        &[
            "part-0.exr",
            "part-1.exr",
            "part-1.exr",
            "part-2.exr",
            "part-3.exr",
        ],
        &[],
    );
    refused(&out, &["part-1.exr", "overlap", "2..4"]);
    render(
        d,
        "--cpu",
        &[
            "--spp",
            "8",
            "--seed",
            "1",
            "--samples",
            "3..6",
            "-o",
            "cross.exr",
        ],
    );
    let out = merge(d, &["part-0.exr", "part-1.exr", "cross.exr"], &[]);
    refused(&out, &["part-1.exr", "cross.exr", "3..4"]);
    // Gaps, inside and at the end, unless allowed.
    let out = merge(d, &["part-0.exr", "part-2.exr", "part-3.exr"], &[]);
    refused(&out, &["2..4", "part-0.exr", "part-2.exr", "--allow-gaps"]);
    let out = merge(d, &["part-0.exr", "part-1.exr", "part-2.exr"], &[]);
    refused(&out, &["6..8", "part-2.exr"]);
    assert!(!d.join("merged.exr").exists(), "a refusal wrote an output");
    let out = merge(
        d,
        &["part-3.exr", "part-0.exr"],
        &["--allow-gaps", "--json"],
    );
    let summary: Value = serde_json::from_slice(&ok(&out).stdout).unwrap();
    assert_eq!(summary["samples"], "0..2,6..8");
    assert_eq!(summary["missing"], "2..6");
    assert_eq!(summary["spp"], 4);
    let merged = read(&d.join("merged.exr"));
    assert_eq!(merged.info.ranges, vec![0..2, 6..8]);
    // A merged file with gaps cannot be resumed; one range can.
    let scene = cornell();
    let mut args = vec![
        "render",
        scene.as_str(),
        "--cpu",
        "--spp",
        "8",
        "--seed",
        "1",
    ];
    args.extend(SMALL);
    args.extend(["--resume", "merged.exr", "-o", "resumed.exr"]);
    refused(&glint(d, &args), &["merged.exr", "gaps"]);
}

#[test]
fn damaged_partial_files_are_refused_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = four_parts(d);
    let bytes = std::fs::read(&parts[1]).unwrap();
    let write = |name: &str, data: &[u8]| std::fs::write(d.join(name), data).unwrap();
    // Truncated pixels, at several lengths.
    for (i, keep) in [
        bytes.len() - 1,
        bytes.len() * 2 / 3,
        bytes.len() / 2,
        400,
        12,
    ]
    .into_iter()
    .enumerate()
    {
        let name = format!("truncated-{i}.exr");
        write(&name, &bytes[..keep]);
        refused(
            &merge(d, &["part-0.exr", &name, "part-2.exr", "part-3.exr"], &[]),
            &[&name],
        );
    }
    // A corrupted header: flipped bytes through the attribute area, and the glint attributes'
    // values edited in place (same length, so the file still parses as an EXR).
    for (i, at) in [8usize, 40, 100, 200, 300].into_iter().enumerate() {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x5a;
        let name = format!("header-{i}.exr");
        write(&name, &damaged);
        let out = merge(d, &["part-0.exr", &name, "part-2.exr", "part-3.exr"], &[]);
        // Some flips land in values that still parse (a name, a hash): then it is another
        // refusal, or a merge; never a panic.
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(matches!(out.status.code(), Some(0 | 2)), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        let _ = std::fs::remove_file(d.join("merged.exr"));
    }
    let edit = |from: &str, to: &str, name: &str| {
        let text_pos = bytes
            .windows(from.len())
            .position(|w| w == from.as_bytes())
            .unwrap_or_else(|| panic!("{from} not in the header"));
        let mut damaged = bytes.clone();
        damaged[text_pos..text_pos + to.len()].copy_from_slice(to.as_bytes());
        write(name, &damaged);
    };
    edit("2..4", "4..2", "range.exr");
    refused(
        &merge(d, &["range.exr"], &[]),
        &["range.exr", "\"4..2\" is empty"],
    );
    edit("glint-partial/1", "glint-partial/9", "format.exr");
    refused(
        &merge(d, &["format.exr"], &[]),
        &["format.exr", "glint.format"],
    );
    // A plain EXR that is no partial file, and a file that is no EXR at all.
    glint::image::output::Image {
        width: 2,
        height: 2,
        pixels: vec![[0.5; 3]; 4],
    }
    .write(&d.join("plain.exr"))
    .unwrap();
    refused(
        &merge(d, &["plain.exr"], &[]),
        &["plain.exr", "not a glint partial"],
    );
    write("text.exr", b"not an image");
    refused(&merge(d, &["text.exr"], &[]), &["text.exr"]);
    refused(&merge(d, &["missing.exr"], &[]), &["missing.exr"]);
    assert!(!d.join("merged.exr").exists());
}

#[test]
fn sample_ranges_and_shards_are_checked_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = cornell();
    let run = |extra: &[&str], env: &[(&str, &str)]| {
        let mut command = Command::new(GLINT);
        command
            .args(["render", scene.as_str(), "--cpu", "--spp", "8"])
            .args(SMALL)
            .args(extra)
            .current_dir(d)
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("JOB_COMPLETION_INDEX");
        for (k, v) in env {
            command.env(k, v);
        }
        command.output().unwrap()
    };
    refused(
        &run(&["--samples", "4..12", "-o", "a.exr"], &[]),
        &["4..12", "8 spp"],
    );
    assert_eq!(
        run(&["--samples", "4..4", "-o", "a.exr"], &[])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        run(&["--shard", "4/4", "-o", "a.exr"], &[]).status.code(),
        Some(2)
    );
    refused(
        &run(&["--shard", "2/16", "-o", "a.exr"], &[]),
        &["no samples"],
    );
    refused(
        &run(&["--shard", "0/2", "-o", "a.png"], &[]),
        &["a.png", ".exr"],
    );
    refused(
        &run(&["--shard", "auto", "-o", "a.exr"], &[]),
        &["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"],
    );
    refused(
        &run(
            &["--shard", "auto", "-o", "a.exr"],
            &[("JOB_COMPLETION_INDEX", "1")],
        ),
        &["--shard-count"],
    );
    assert!(
        std::fs::read_dir(d).unwrap().next().is_none(),
        "a refusal left a file"
    );
    // --shard auto from a Slurm array task (ids 5..8, this is the third) and an Indexed Job.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "7"),
        ("SLURM_ARRAY_TASK_MIN", "5"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    ok(&run(&["--shard", "auto", "-o", "slurm.exr"], &slurm));
    assert_eq!(read(&d.join("slurm.exr")).info.ranges, vec![4..6]);
    ok(&run(
        &["--shard", "auto", "--shard-count", "2", "-o", "k8s.exr"],
        &[("JOB_COMPLETION_INDEX", "1")],
    ));
    assert_eq!(read(&d.join("k8s.exr")).info.ranges, vec![4..8]);
    // The default output of a partial render names its range.
    ok(&run(&["--samples", "1..3"], &[]));
    assert!(d.join("cornell.1-3.exr").exists());
}

/// The settings hash that partial renders must share: equal for the same scene loaded twice
/// (a mesh scene too, whose BVH build time differs from run to run, and one with an
/// environment map and textures), different when anything that changes the image changes.
#[test]
fn settings_hash_is_stable_across_loads_and_sees_changes() {
    use glint::render::partial::settings_hash;
    for name in ["bunny.toml", "sun.toml", "cornell-textured.toml"] {
        let first = settings_hash(&common::shipped_scene(name).kernel_scene());
        let again = settings_hash(&common::shipped_scene(name).kernel_scene());
        assert_eq!(first, again, "{name}");
        let mut changed = common::shipped_scene(name).kernel_scene();
        changed.params.seed += 1;
        assert_ne!(settings_hash(&changed), first, "{name}: seed");
        let mut changed = common::shipped_scene(name);
        changed.render.sampler = Sampler::Sobol;
        assert_ne!(
            settings_hash(&changed.kernel_scene()),
            first,
            "{name}: sampler"
        );
        let mut changed = common::shipped_scene(name).kernel_scene();
        if let Some(t) = changed.environment_texels.first_mut() {
            t.radiance[0] += 1.0;
            assert_ne!(settings_hash(&changed), first, "{name}: a texel of the map");
        }
        if let Some(t) = changed.texels.first_mut() {
            t[1] *= 0.5;
            assert_ne!(settings_hash(&changed), first, "{name}: a texture texel");
        }
    }
}
