//! `glint view`.

use super::model::ModelArgs;
use super::tone::ToneArgs;
use crate::error::InputError;
use crate::gpu::TraversalChoice;
use crate::scene::MAX_IMAGE_SIDE;
use crate::viewer::{action::Script, ViewOptions};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Scene file (TOML), or a model file (.glb, .gltf, .obj, .ply) to view as a scene; edits
    /// on disk are picked up while the window is open.
    pub scene: PathBuf,
    /// Window and image width in pixels (overrides [render] width).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64), allow_negative_numbers = true)]
    pub width: Option<u32>,
    /// Window and image height in pixels (overrides [render] height).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64), allow_negative_numbers = true)]
    pub height: Option<u32>,
    /// Samples per pixel added each frame; without it the batch adapts to ~30 ms frames.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024), allow_negative_numbers = true)]
    pub spp_per_frame: Option<u32>,
    /// Quit after N frames.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..), allow_negative_numbers = true)]
    pub frames: Option<u64>,
    /// On exit, write what is shown (.png) or the linear mean radiance (.exr).
    #[arg(long, value_name = "FILE")]
    pub screenshot: Option<PathBuf>,
    /// How the kernel finds hits: hardware (ray queries), software (glint's BVH) or auto (as
    /// for `render`).
    #[arg(long, value_enum, default_value_t = TraversalChoice::Auto)]
    pub traversal: TraversalChoice,
    #[command(flatten)]
    pub tone: ToneArgs,
    #[command(flatten)]
    pub model: ModelArgs,
    /// Tests: actions to inject before given frames, e.g. "5:orbit 40 0; 10:reload".
    #[arg(long, hide = true)]
    pub script: Option<String>,
    /// Tests and measurements: one JSON line per frame and per event on stdout.
    #[arg(long, hide = true)]
    pub log_frames: bool,
}

pub fn run(args: ViewArgs) -> Result<()> {
    let script = match &args.script {
        Some(text) => Script::parse(text).map_err(|e| InputError(format!("--script: {e}")))?,
        None => Script::default(),
    };
    args.model.refuse_for_scene_file(&args.scene)?;
    crate::viewer::run(ViewOptions {
        model: args.model.options(args.width, args.height),
        scene: args.scene,
        width: args.width,
        height: args.height,
        spp_per_frame: args.spp_per_frame,
        frames: args.frames,
        screenshot: args.screenshot,
        display: args.tone.transform(),
        script,
        log_frames: args.log_frames,
        traversal: args.traversal,
    })
}
