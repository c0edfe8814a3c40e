//! The Kubernetes recipe in deploy/kubernetes: the manifests' structure (an Indexed Job whose
//! completions, parallelism and --shard-count agree, a merge Job, one volume claim), and their
//! shell commands run here as the pods would run them, with JOB_COMPLETION_INDEX set as the Job
//! controller sets it and the merged image checked against a single render. (No cluster runs in
//! CI; tests/suite/slurm.rs runs the Slurm recipe for real.)
// A partial file's ranges are a list: a one-range list is what most of them hold.
#![allow(clippy::single_range_in_vec_init)]

use crate::common;
use glint::render::partial::Partial;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn deploy(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("deploy")
        .join(path)
}

fn manifest(name: &str) -> Value {
    let text = std::fs::read_to_string(deploy(&format!("kubernetes/{name}"))).unwrap();
    serde_norway::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The container's `sh -c` script.
fn script(job: &Value) -> String {
    let container = &job["spec"]["template"]["spec"]["containers"][0];
    let command = container["command"].as_array().expect("a command list");
    assert_eq!(command[0], "sh");
    assert_eq!(command[1], "-c");
    command[2].as_str().unwrap().to_string()
}

fn volume_claims(job: &Value) -> Vec<String> {
    job["spec"]["template"]["spec"]["volumes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|v| v["persistentVolumeClaim"]["claimName"].as_str())
        .map(String::from)
        .collect()
}

#[test]
fn kubernetes_manifests_are_an_indexed_job_and_a_merge_job() {
    let shards = manifest("shards-job.yaml");
    let merge = manifest("merge-job.yaml");
    let storage = manifest("storage.yaml");
    for job in [&shards, &merge] {
        assert_eq!(job["apiVersion"], "batch/v1");
        assert_eq!(job["kind"], "Job");
        assert_eq!(job["spec"]["template"]["spec"]["restartPolicy"], "Never");
    }
    let spec = &shards["spec"];
    assert_eq!(spec["completionMode"], "Indexed");
    let completions = spec["completions"].as_u64().unwrap();
    assert!(completions > 1);
    assert_eq!(spec["parallelism"].as_u64(), Some(completions));
    let shard_script = script(&shards);
    assert!(shard_script.contains("glint render"), "{shard_script}");
    assert!(shard_script.contains("--shard auto"), "{shard_script}");
    assert!(
        shard_script.contains(&format!("--shard-count {completions}")),
        "--shard-count must equal completions: {shard_script}"
    );
    assert!(shard_script.contains("$JOB_COMPLETION_INDEX"));
    let merge_script = script(&merge);
    assert!(merge_script.contains("glint merge"), "{merge_script}");
    // Same image, same volume claim, which storage.yaml defines.
    let image = |job: &Value| job["spec"]["template"]["spec"]["containers"][0]["image"].clone();
    assert_eq!(image(&shards), image(&merge));
    assert_eq!(storage["kind"], "PersistentVolumeClaim");
    let claim = storage["metadata"]["name"].as_str().unwrap().to_string();
    assert_eq!(volume_claims(&shards), vec![claim.clone()]);
    assert_eq!(volume_claims(&merge), vec![claim]);
    // run.sh waits for the shards before it starts the merge.
    let run = std::fs::read_to_string(deploy("kubernetes/run.sh")).unwrap();
    let wait = run.find("kubectl wait --for=condition=complete").unwrap();
    assert!(run.find("merge-job.yaml").unwrap() > wait);
}

/// The pods' scripts, run here with /scene and /renders moved into a temporary folder and
/// `glint` on PATH: every index, then the merge, give the single render of the same scene.
#[test]
fn kubernetes_job_scripts_render_and_merge_the_single_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene_dir = d.join("scene");
    let renders = d.join("renders");
    std::fs::create_dir_all(&scene_dir).unwrap();
    std::fs::create_dir_all(&renders).unwrap();
    let cornell =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml"))
            .unwrap();
    let small = cornell
        .replace("width = 512", "width = 20")
        .replace("height = 512", "height = 20")
        .replace("spp = 64", "spp = 8")
        .replace("max_bounces = 8", "max_bounces = 3");
    assert_ne!(small, cornell);
    std::fs::write(scene_dir.join("scene.toml"), &small).unwrap();
    let relocate = |s: String| {
        s.replace("/scene/", &format!("{}/", scene_dir.display()))
            .replace("/renders/", &format!("{}/", renders.display()))
    };
    let path = format!(
        "{}:{}",
        Path::new(GLINT).parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let shards = manifest("shards-job.yaml");
    let run = |script: &str, index: Option<u64>| {
        let mut command = Command::new("sh");
        command.args(["-c", script]).env("PATH", &path);
        command.env_remove("SLURM_ARRAY_TASK_ID");
        if let Some(i) = index {
            command.env("JOB_COMPLETION_INDEX", i.to_string());
        }
        let out = command.output().unwrap();
        assert!(
            out.status.success(),
            "{script}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let shard_script = relocate(script(&shards)).replace("glint render", "glint render --cpu");
    for i in 0..shards["spec"]["completions"].as_u64().unwrap() {
        run(&shard_script, Some(i));
    }
    run(&relocate(script(&manifest("merge-job.yaml"))), None);
    let single = Command::new(GLINT)
        .args(["render", "--cpu", "-o"])
        .arg(d.join("single.exr"))
        .arg(scene_dir.join("scene.toml"))
        .output()
        .unwrap();
    assert!(
        single.status.success(),
        "{}",
        String::from_utf8_lossy(&single.stderr)
    );
    let merged = Partial::read(&renders.join("merged.exr")).unwrap();
    let single = Partial::read(&d.join("single.exr")).unwrap();
    assert_eq!(merged.info.ranges, vec![0..8]);
    assert!(renders.join("merged.variance.exr").exists());
    let worst = common::merge_bound::worst_vs_bound(&merged.accumulation, &single.accumulation);
    assert!(worst <= 1.0, "merged differs by {worst} × the bound");
}
