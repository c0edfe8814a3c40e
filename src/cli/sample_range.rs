//! `glint render`'s sample ranges: `--samples A..B`, `--shard I/N`, `--shard auto` (from a
//! Slurm job array or a Kubernetes Indexed Job), and `--resume`, which continues a partial
//! file from its last sample.

use crate::error::InputError;
use crate::render::partial::{format_range, format_ranges, parse_range, Partial};
use crate::render::Renderer;
use anyhow::Result;
use clap::Args;
use std::ops::Range;
use std::path::{Path, PathBuf};

#[derive(Args, Debug, Default)]
pub struct SampleRangeArgs {
    /// Render only the global sample indices A..B (0 ≤ A < B ≤ spp): a partial render, written
    /// as an .exr that `glint merge` combines with the other ranges' files.
    #[arg(long, value_name = "A..B", value_parser = parse_range, conflicts_with = "shard")]
    pub samples: Option<Range<u32>>,
    /// Render the I-th (0-based) of N equal sample ranges of the spp. `auto` takes I and N from
    /// a Slurm job array (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT)
    /// or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX of --shard-count).
    #[arg(long, value_name = "I/N|auto", value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// N for `--shard auto` (required with JOB_COMPLETION_INDEX; overrides Slurm's count).
    #[arg(long, value_name = "N", requires = "shard", value_parser = clap::value_parser!(u32).range(1..))]
    pub shard_count: Option<u32>,
    /// Continue this partial render (or an interrupted render's .exr) from its last sample;
    /// the output defaults to the same file.
    #[arg(long, value_name = "PART.exr")]
    pub resume: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shard {
    Index { index: u32, count: u32 },
    Auto,
}

fn parse_shard(s: &str) -> Result<Shard, String> {
    if s == "auto" {
        return Ok(Shard::Auto);
    }
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("expected I/N (e.g. 0/4) or auto, got {s:?}"))?;
    let parse = |t: &str| {
        t.parse::<u32>()
            .map_err(|_| format!("{t:?} in {s:?} is not a whole number"))
    };
    let (index, count) = (parse(i)?, parse(n)?);
    if count == 0 || index >= count {
        return Err(format!(
            "shard {s:?}: I must be in 0..N (0-based), and N ≥ 1"
        ));
    }
    Ok(Shard::Index { index, count })
}

/// A checkpoint interval in seconds: finite, ≥ 0, at most a year.
pub fn parse_interval(s: &str) -> Result<std::time::Duration, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("{s:?} is not a number of seconds"))?;
    if !(0.0..=3.2e7).contains(&v) {
        return Err(format!(
            "must be between 0 and 3.2e7 seconds (a year), got {s}"
        ));
    }
    Ok(std::time::Duration::from_secs_f64(v))
}

/// The shard `auto` stands for, from the job engine's environment.
fn auto_shard(shard_count: Option<u32>) -> Result<(u32, u32), String> {
    let var = |name: &str| std::env::var(name).ok();
    let number = |name: &str, value: String| {
        value
            .trim()
            .parse::<u32>()
            .map_err(|_| format!("--shard auto: {name}={value:?} is not a whole number"))
    };
    let (index, count) = if let Some(id) = var("SLURM_ARRAY_TASK_ID") {
        let id = number("SLURM_ARRAY_TASK_ID", id)?;
        let min = match var("SLURM_ARRAY_TASK_MIN") {
            Some(v) => number("SLURM_ARRAY_TASK_MIN", v)?,
            None => 0,
        };
        let count = match (shard_count, var("SLURM_ARRAY_TASK_COUNT")) {
            (Some(n), _) => n,
            (None, Some(v)) => number("SLURM_ARRAY_TASK_COUNT", v)?,
            (None, None) => {
                return Err("--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; pass --shard-count N".into())
            }
        };
        (
            id.checked_sub(min).ok_or_else(|| {
                format!(
                    "--shard auto: SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"
                )
            })?,
            count,
        )
    } else if let Some(index) = var("JOB_COMPLETION_INDEX") {
        let index = number("JOB_COMPLETION_INDEX", index)?;
        let count = shard_count.ok_or(
            "--shard auto with JOB_COMPLETION_INDEX needs --shard-count N (the Job's completions)",
        )?;
        (index, count)
    } else {
        return Err("--shard auto: neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set; use --shard I/N".into());
    };
    if index >= count {
        return Err(format!(
            "--shard auto: index {index} is not below the shard count {count} (a Slurm array must be contiguous, e.g. --array=0-{})",
            count.saturating_sub(1)
        ));
    }
    Ok((index, count))
}

/// The I-th of N equal ranges of `spp` samples: [⌊I·spp/N⌋, ⌊(I+1)·spp/N⌋).
pub fn shard_range(index: u32, count: u32, spp: u32) -> Range<u32> {
    let bound = |i: u32| (i as u64 * spp as u64 / count as u64) as u32;
    bound(index)..bound(index + 1)
}

/// What a render covers: the sample range it is asked for, and what it starts from.
pub struct RangePlan {
    pub target: Range<u32>,
    /// The resumed file's statistics, of samples `target.start..target.start + count`.
    pub resumed: Option<Partial>,
}

impl RangePlan {
    /// Whether the render covers less than 0..spp, so only an .exr can hold it usefully.
    pub fn is_partial(&self, spp: u32) -> bool {
        self.target != (0..spp)
    }

    /// Samples per pixel still to render.
    pub fn samples_wanted(&self) -> u32 {
        self.target.end - self.target.start
    }

    /// Sets the renderer up to add samples from where this plan starts.
    pub fn start(&self, renderer: &mut dyn Renderer) -> Result<()> {
        let resumed = self.resumed.as_ref().map(|p| &p.accumulation);
        renderer.load_accumulation(self.target.start, resumed)
    }
}

/// What the render of this scene (its [`crate::render::partial::settings_hash`], seed, size and
/// `spp`) covers, from the flags.
pub fn plan(
    args: &SampleRangeArgs,
    spp: u32,
    settings: &str,
    size: (u32, u32),
) -> Result<RangePlan, InputError> {
    let asked = match (&args.samples, args.shard) {
        (Some(r), _) => Some(r.clone()),
        (None, Some(Shard::Index { index, count })) => Some(checked_shard(index, count, spp)?),
        (None, Some(Shard::Auto)) => {
            let (index, count) = auto_shard(args.shard_count).map_err(InputError)?;
            Some(checked_shard(index, count, spp)?)
        }
        (None, None) => None,
    };
    if let Some(r) = &asked {
        if r.end > spp {
            return Err(InputError(format!(
                "--samples {} lies beyond the render's {spp} spp; raise --spp",
                format_range(r)
            )));
        }
    }
    let Some(path) = &args.resume else {
        return Ok(RangePlan {
            target: asked.unwrap_or(0..spp),
            resumed: None,
        });
    };
    let resumed = Partial::read(path).map_err(InputError)?;
    let name = path.display();
    let info = &resumed.info;
    let a = &resumed.accumulation;
    if info.settings != settings || (a.width, a.height) != size {
        return Err(InputError(format!(
            "{name} is a render of a different scene or settings than this one (scene, size, seed, bounces, light sampling and the like must all be the same to resume)"
        )));
    }
    let target = match asked {
        Some(r) => r,
        // A full render resumes towards this render's spp (which may be more than before).
        None if info.target == (0..info.spp) => 0..spp,
        None => info.target.clone(),
    };
    let done = match info.ranges.as_slice() {
        [r] => r.clone(),
        _ => {
            return Err(InputError(format!(
                "{name} holds samples {} with gaps; only one range can be resumed",
                format_ranges(&info.ranges)
            )))
        }
    };
    if done.start != target.start || done.end > target.end {
        return Err(InputError(format!(
            "{name} holds samples {}, which is not the start of the range {} this render covers",
            format_range(&done),
            format_range(&target)
        )));
    }
    if target.end > spp {
        return Err(InputError(format!(
            "{name} is part of a {} spp render; pass --spp {} to resume it",
            info.spp, info.spp
        )));
    }
    Ok(RangePlan {
        target,
        resumed: Some(resumed),
    })
}

fn checked_shard(index: u32, count: u32, spp: u32) -> Result<Range<u32>, InputError> {
    let r = shard_range(index, count, spp);
    if r.is_empty() {
        return Err(InputError(format!(
            "shard {index}/{count} of {spp} spp has no samples; use at most {spp} shards"
        )));
    }
    Ok(r)
}

/// The default output of a render of `target` of `spp` samples from `scene`: the resumed file,
/// `<stem>.png` for a full render, `<stem>.A-B.exr` for a partial one.
pub fn default_output(scene: &Path, plan: &RangePlan, args: &SampleRangeArgs, spp: u32) -> PathBuf {
    if let Some(path) = &args.resume {
        return path.clone();
    }
    let stem = scene.file_stem().unwrap_or_else(|| "render".as_ref());
    if plan.is_partial(spp) {
        let mut name = stem.to_os_string();
        name.push(format!(".{}-{}.exr", plan.target.start, plan.target.end));
        PathBuf::from(name)
    } else {
        PathBuf::from(stem).with_extension("png")
    }
}
