//! The `glint` command line.

mod bench;
mod compare;
mod merge;
mod model;
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
/// A bad command line: one line on stderr and exit code 2, like every other bad input (clap's
/// own report adds a usage block and a hint). --help and --version print as clap does.
fn usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        e.exit();
    }
    crate::errln!("glint: {}", first_paragraph(&e.render().to_string()));
    ExitCode::from(2)
}

/// The text up to its first blank line, on one line: clap's message with its details (the
/// possible values, the missing arguments) but not the usage block or the tips after it.
fn first_paragraph(text: &str) -> String {
    text.lines()
        .take_while(|line| !line.trim().is_empty())
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(" ")
}

pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
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
            if let Some(interrupted) = e.downcast_ref::<crate::render::interrupt::Interrupted>() {
                crate::errln!("glint: {interrupted}");
                return ExitCode::from(crate::render::interrupt::exit_code(interrupted.signal));
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
