//! The Slurm recipe in deploy/slurm for real: a one-node cluster (munged, slurmctld and slurmd,
//! with a configuration this test writes into a temporary folder and ports of its own) runs
//! submit.sh: a job array of 4 shards and a merge job that depends on it. The merged image must
//! equal a single render of the same seed to float rounding. The daemons are stopped however the
//! test ends. Skipped, with a message, without Slurm and munge (Debian's slurm-wlm and munge,
//! which scripts/test installs) or without root.
// A partial file's ranges are a list: a one-range list is what most of them hold.
#![allow(clippy::single_range_in_vec_init)]

use crate::common;
use glint::render::partial::Partial;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");
const TOOLS: [&str; 6] = ["munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo"];
const RENDER_ARGS: &str = "--cpu --width 24 --height 24 --spp 16 --max-bounces 4 --seed 3";

fn installed(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// The daemons of a one-node cluster in `dir`; dropping it stops them.
struct Cluster {
    dir: PathBuf,
    daemons: Vec<Child>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for daemon in &mut self.daemons {
            let _ = daemon.kill();
            let _ = daemon.wait();
        }
        // munged forks into the background: stop it by its pid file.
        if let Ok(pid) = std::fs::read_to_string(self.dir.join("munged.pid")) {
            let _ = Command::new("kill").arg(pid.trim()).status();
        }
    }
}

impl Cluster {
    fn conf(&self) -> PathBuf {
        self.dir.join("slurm.conf")
    }

    fn start(dir: &Path) -> Cluster {
        let mut cluster = Cluster {
            dir: dir.to_path_buf(),
            daemons: Vec::new(),
        };
        for sub in ["state", "spool", "log"] {
            std::fs::create_dir_all(dir.join(sub)).unwrap();
        }
        let key: Vec<u8> = (0..1024u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        let key_path = dir.join("munge.key");
        std::fs::write(&key_path, key).unwrap();
        std::fs::set_permissions(
            &key_path,
            std::os::unix::fs::PermissionsExt::from_mode(0o600),
        )
        .unwrap();
        let d = dir.display();
        let status = Command::new("munged")
            .arg("--force")
            .arg(format!("--socket={d}/munge.sock"))
            .arg(format!("--key-file={d}/munge.key"))
            .arg(format!("--pid-file={d}/munged.pid"))
            .arg(format!("--log-file={d}/log/munged.log"))
            .arg(format!("--seed-file={d}/munged.seed"))
            .status()
            .unwrap();
        assert!(status.success(), "munged did not start");
        let host = String::from_utf8(Command::new("hostname").output().unwrap().stdout).unwrap();
        let host = host.trim();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        // Ports of this process's own, so a leftover cluster cannot answer.
        let port = 20000 + (std::process::id() % 20000) * 2;
        let conf = format!(
            "ClusterName=glinttest\nSlurmctldHost={host}\nSlurmUser=root\nSlurmdUser=root\n\
             AuthType=auth/munge\nAuthInfo=socket={d}/munge.sock\nCredType=cred/munge\n\
             SlurmctldPort={port}\nSlurmdPort={}\nStateSaveLocation={d}/state\n\
             SlurmdSpoolDir={d}/spool\nSlurmctldPidFile={d}/slurmctld.pid\n\
             SlurmdPidFile={d}/slurmd.pid\nSlurmctldLogFile={d}/log/slurmctld.log\n\
             SlurmdLogFile={d}/log/slurmd.log\nProctrackType=proctrack/linuxproc\n\
             TaskPlugin=task/none\nJobAcctGatherType=jobacct_gather/none\n\
             AccountingStorageType=accounting_storage/none\nSchedulerType=sched/builtin\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nMpiDefault=none\n\
             ReturnToService=2\nNodeName={host} CPUs={cpus} State=UNKNOWN\n\
             PartitionName=glint Nodes=ALL Default=YES MaxTime=INFINITE State=UP\n",
            port + 1
        );
        std::fs::write(cluster.conf(), conf).unwrap();
        for (daemon, extra) in [("slurmctld", &["-i"][..]), ("slurmd", &[][..])] {
            let child = Command::new(daemon)
                .arg("-D")
                .args(extra)
                .arg("-f")
                .arg(cluster.conf())
                .stdout(Stdio::null())
                .stderr(std::fs::File::create(dir.join(format!("log/{daemon}.err"))).unwrap())
                .spawn()
                .unwrap();
            cluster.daemons.push(child);
        }
        cluster.wait_for("the node to be idle", Duration::from_secs(60), |c| {
            c.command("sinfo", &["-h", "-o", "%t"]).trim() == "idle"
        });
        cluster
    }

    /// Runs a Slurm client command against this cluster; its stdout.
    fn command(&self, tool: &str, args: &[&str]) -> String {
        let out = Command::new(tool)
            .args(args)
            .env("SLURM_CONF", self.conf())
            .output()
            .unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    fn wait_for(&self, what: &str, limit: Duration, mut done: impl FnMut(&Cluster) -> bool) {
        let start = Instant::now();
        while !done(self) {
            if start.elapsed() > limit {
                panic!("timed out waiting for {what}\n{}", self.logs());
            }
            std::thread::sleep(Duration::from_millis(250));
        }
    }

    fn logs(&self) -> String {
        let mut text = String::new();
        for name in [
            "log/slurmctld.log",
            "log/slurmd.log",
            "log/slurmctld.err",
            "log/slurmd.err",
        ] {
            let log = std::fs::read_to_string(self.dir.join(name)).unwrap_or_default();
            let tail: Vec<&str> = log.lines().rev().take(15).collect();
            text += &format!(
                "--- {name}\n{}\n",
                tail.into_iter().rev().collect::<Vec<_>>().join("\n")
            );
        }
        text
    }
}

#[test]
fn slurm_job_array_and_dependent_merge_render_the_single_image() {
    let missing: Vec<&str> = TOOLS.into_iter().filter(|t| !installed(t)).collect();
    if !missing.is_empty() {
        eprintln!(
            "skipping the Slurm test: {} not installed (apt-get install slurm-wlm munge)",
            missing.join(", ")
        );
        return;
    }
    if !is_root() {
        eprintln!("skipping the Slurm test: slurmd must run as root");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cluster = Cluster::start(&d.join("cluster"));
    let out = d.join("renders");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml");
    let submit = Command::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("deploy/slurm/submit.sh"))
        .env("SLURM_CONF", cluster.conf())
        .env("SCENE", &scene)
        .env("OUT", &out)
        .env("SHARDS", "4")
        .env("GLINT", GLINT)
        .env("GLINT_ARGS", RENDER_ARGS)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&submit.stdout).into_owned();
    assert!(
        submit.status.success(),
        "submit.sh: {stdout}{}",
        String::from_utf8_lossy(&submit.stderr)
    );
    let jobs: Vec<&str> = stdout.split_whitespace().collect();
    assert_eq!(jobs.len(), 2, "{stdout}");
    // The merge job waits on the array: it cannot start while a shard is pending.
    let dependency = cluster.command("squeue", &["-h", "-j", jobs[1], "-o", "%E"]);
    assert!(
        dependency.is_empty() || dependency.contains(jobs[0]),
        "merge job dependency: {dependency:?}"
    );
    cluster.wait_for("the jobs to finish", Duration::from_secs(240), |c| {
        c.command("squeue", &["-h"]).trim().is_empty()
    });
    let merged_path = out.join("merged.exr");
    if !merged_path.exists() {
        let merge_log = std::fs::read_to_string(out.join("merge.log")).unwrap_or_default();
        panic!(
            "no merged image; merge.log:\n{merge_log}\n{}",
            cluster.logs()
        );
    }
    for i in 0..4 {
        let part = Partial::read(&out.join(format!("part-{i}.exr"))).unwrap();
        assert_eq!(part.info.ranges, vec![4 * i..4 * i + 4]);
    }
    let merged = Partial::read(&merged_path).unwrap();
    assert_eq!(merged.info.ranges, vec![0..16]);
    assert!(out.join("merged.variance.exr").exists());
    let single = Command::new(GLINT)
        .arg("render")
        .arg(&scene)
        .args(RENDER_ARGS.split(' '))
        .arg("-o")
        .arg(d.join("single.exr"))
        .output()
        .unwrap();
    assert!(
        single.status.success(),
        "{}",
        String::from_utf8_lossy(&single.stderr)
    );
    let single = Partial::read(&d.join("single.exr")).unwrap();
    let worst = common::merge_bound::worst_vs_bound(&merged.accumulation, &single.accumulation);
    assert!(worst <= 1.0, "merged differs by {worst} × the bound");
    drop(cluster);
}
