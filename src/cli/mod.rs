//! The `glint` command line.

mod bench;
mod compare;
mod merge;
mod post;
mod render;
mod render_writer;
mod sample_range;
mod stress_mesh;
mod tone;
mod view;

use crate::error::InputError;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "glint",
    version,
    about = "A physically based GPU path tracer (Vulkan via wgpu)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene file to a PNG or EXR image.
    // Boxed: its flags make it several times larger than the other commands' (clippy).
    Render(Box<render::RenderArgs>),
    /// Merge partial renders (--samples, --shard) into one image, exactly.
    Merge(merge::MergeArgs),
    /// Compare two EXR renders: error metrics and, with variance images, per-pixel Z-tests.
    Compare(compare::CompareArgs),
    /// Measure paths/s on the GPU and the CPU reference (Cornell box, 256² and 512²).
    Bench(bench::BenchArgs),
    /// Open a window that renders the scene progressively; fly around, watch it refine, save.
    View(view::ViewArgs),
    /// Write a generated stress mesh (a displaced sphere, ~1M triangles by default) as PLY.
    StressMesh(stress_mesh::StressMeshArgs),
}

/// Runs the command line; exit code 0 done, 2 bad input (scene or flags), 1 anything else.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // clap exits with 2 on bad flags and 0 for --help and --version.
        Err(e) => e.exit(),
    };
    let result = match cli.command {
        Command::Render(args) => render::run(*args),
        Command::Merge(args) => merge::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Bench(args) => bench::run(args),
        Command::View(args) => view::run(args),
        Command::StressMesh(args) => stress_mesh::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(interrupted) = e.downcast_ref::<crate::interrupt::Interrupted>() {
                crate::errln!("glint: {interrupted}");
                return ExitCode::from(crate::interrupt::exit_code(interrupted.signal));
            }
            crate::errln!("glint: error: {e:#}");
            if e.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
