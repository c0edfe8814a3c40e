//! `glint stress-mesh`: writes the generated stress mesh (a displaced sphere) as PLY.

use crate::error::InputError;
use crate::image::atomic_write::write_atomically;
use crate::image::output_check::OutputSet;
use crate::scene::stress::StressMesh;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StressMeshArgs {
    /// Output file (.ply).
    pub output: PathBuf,
    /// About how many triangles.
    #[arg(long, default_value_t = 1_000_000)]
    pub triangles: usize,
}

pub fn run(args: StressMeshArgs) -> Result<()> {
    if args.output.extension().and_then(|e| e.to_str()) != Some("ply") {
        return Err(InputError(format!(
            "{}: the stress mesh is written as .ply",
            args.output.display()
        ))
        .into());
    }
    if !(32..=crate::scene::mesh::MAX_TRIANGLES).contains(&args.triangles) {
        return Err(InputError(format!(
            "--triangles must be in 32..={}, got {}",
            crate::scene::mesh::MAX_TRIANGLES,
            args.triangles
        ))
        .into());
    }
    OutputSet::new().file("the output", &args.output).check()?;
    let mesh = StressMesh::with_triangles(args.triangles);
    // Atomically: an error or an interruption leaves no half-written file.
    write_atomically(&args.output, |out| mesh.encode_ply(out))?;
    crate::errln!(
        "glint: wrote {} ({} triangles)",
        args.output.display(),
        mesh.indices.len()
    );
    Ok(())
}
