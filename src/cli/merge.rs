//! `glint merge`.

use crate::error::InputError;
use crate::image::output_check::OutputSet;
use crate::render::merge::{merge, Part};
use crate::render::partial::{format_ranges, write_image, Partial};
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Partial renders (EXR files written by `glint render`, e.g. with --samples or --shard).
    #[arg(required = true, value_name = "PART")]
    pub parts: Vec<PathBuf>,
    /// The merged image: .exr (a partial file covering every input's samples, which can be
    /// resumed or merged again) or .png.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the variance of each pixel's mean (σ²/n per channel, linear) to this .exr;
    /// bidirectional parts' from their batch means, joined by Chan's update.
    #[arg(long, value_name = "FILE.exr")]
    pub variance: Option<PathBuf>,
    /// Merge even when samples of the render are missing (the image is then of fewer samples).
    #[arg(long)]
    pub allow_gaps: bool,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: MergeArgs) -> Result<()> {
    let started = Instant::now();
    // Every output writable, none the same file as another or as a part (src/image/output_check.rs).
    let mut outputs = OutputSet::new();
    for part in &args.parts {
        outputs = outputs.input("a part", part);
    }
    outputs
        .image("-o", &args.output)
        .exr_opt("--variance", args.variance.as_deref())
        .check()?;
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        let partial = Partial::read(path).map_err(InputError)?;
        parts.push(Part {
            path: path.clone(),
            partial,
        });
    }
    let read_seconds = started.elapsed().as_secs_f64();
    let inputs: Vec<_> = parts
        .iter()
        .map(|p| {
            serde_json::json!({
                "file": p.path.display().to_string(),
                "samples": format_ranges(&p.partial.info.ranges),
                "device": p.partial.info.device,
            })
        })
        .collect();
    let merge_started = Instant::now();
    let merged = merge(parts, args.allow_gaps).map_err(InputError)?;
    let merge_seconds = merge_started.elapsed().as_secs_f64();
    let info = &merged.partial.info;
    write_image(&args.output, &merged.partial)
        .with_context(|| format!("writing {}", args.output.display()))?;
    if let Some(path) = &args.variance {
        merged
            .partial
            .accumulation
            .variance_image()
            .write(path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let a = &merged.partial.accumulation;
    if args.json {
        let summary = serde_json::json!({
            "output": args.output.display().to_string(),
            "width": a.width,
            "height": a.height,
            "spp": a.count,
            // Adaptive parts: the mean of the pixels' own counts (else the same as spp).
            "mean_spp": a.total_samples() as f64 / a.counts.len().max(1) as f64,
            "render_spp": info.spp,
            "seed": info.seed,
            "samples": format_ranges(&info.ranges),
            "missing": format_ranges(&merged.missing),
            "inputs": inputs,
            "read_seconds": read_seconds,
            "merge_seconds": merge_seconds,
            "wall_seconds": started.elapsed().as_secs_f64(),
        });
        crate::outln!("{summary}");
    } else {
        let mut line = format!(
            "merged {} parts: samples {} of 0..{} ({} spp)",
            args.parts.len(),
            format_ranges(&info.ranges),
            info.spp,
            a.count
        );
        if !merged.missing.is_empty() {
            line += &format!("; missing {}", format_ranges(&merged.missing));
        }
        crate::errln!("{line}");
    }
    Ok(())
}
