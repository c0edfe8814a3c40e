//! `glint compare`.

use crate::error::InputError;
use crate::image::compare::{compare, difference_image, Z_CRITICAL, Z_TEST_ALPHA};
use crate::image::output::Image;
use crate::image::output_check::OutputSet;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image under test (linear EXR).
    pub a: PathBuf,
    /// The reference (linear EXR).
    pub b: PathBuf,
    /// Variance image of A's pixel means, as `render --variance` writes it.
    #[arg(long, requires = "variance_b")]
    pub variance_a: Option<PathBuf>,
    /// Variance image of B's pixel means.
    #[arg(long, requires = "variance_a")]
    pub variance_b: Option<PathBuf>,
    /// Write a false-colour difference image (red: A brighter, blue: B brighter; with variances,
    /// full colour means a 3σ difference).
    #[arg(long, value_name = "OUT.png")]
    pub diff: Option<PathBuf>,
    /// Print the figures as one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

fn read(path: &Path) -> Result<Image, InputError> {
    Image::read_exr(path).map_err(|e| InputError(format!("{e:#}")))
}

pub fn run(args: CompareArgs) -> Result<()> {
    OutputSet::new()
        .input("A", &args.a)
        .input("B", &args.b)
        .input_opt("--variance-a", args.variance_a.as_deref())
        .input_opt("--variance-b", args.variance_b.as_deref())
        .image_opt("--diff", args.diff.as_deref())
        .check()?;
    let a = read(&args.a)?;
    let b = read(&args.b)?;
    let variances = match (&args.variance_a, &args.variance_b) {
        (Some(va), Some(vb)) => Some((read(va)?, read(vb)?)),
        _ => None,
    };
    let variance_refs = variances.as_ref().map(|(va, vb)| (va, vb));
    let c = compare(&a, &b, variance_refs).map_err(InputError)?;
    if c.nonfinite_a + c.nonfinite_b > 0 {
        crate::errln!(
            "glint: warning: non-finite (NaN or infinite) pixel channels: {} in A, {} in B; they are left out of every figure",
            c.nonfinite_a,
            c.nonfinite_b
        );
    }
    if let Some(diff) = &args.diff {
        difference_image(&a, &b, variance_refs).write(diff)?;
    }
    if args.json {
        let z = c.z_test.as_ref().map(|z| {
            serde_json::json!({
                "pass_rate": z.pass_rate,
                "tested": z.tested,
                "alpha": Z_TEST_ALPHA,
                "z_of_means": z.z_of_means,
                "variance_ratio": z.variance_ratio,
            })
        });
        crate::outln!(
            "{}",
            serde_json::json!({
                "a": args.a.display().to_string(),
                "b": args.b.display().to_string(),
                "width": a.width,
                "height": a.height,
                "rmse": c.rmse,
                "relative_mse": c.relative_mse,
                "mean_a": c.mean_a,
                "mean_b": c.mean_b,
                "max_difference": c.max_difference,
                "nonfinite_a": c.nonfinite_a,
                "nonfinite_b": c.nonfinite_b,
                "z_test": z,
            })
        );
        return Ok(());
    }
    crate::outln!(
        "A: {}  B (reference): {}  ({}×{})",
        args.a.display(),
        args.b.display(),
        a.width,
        a.height
    );
    crate::outln!("RMSE            {:.6}", c.rmse);
    crate::outln!(
        "relative MSE    {:.6}   (mean of (A−B)² / (B² + 0.01))",
        c.relative_mse
    );
    crate::outln!(
        "mean A (RGB)    {:.6} {:.6} {:.6}",
        c.mean_a[0],
        c.mean_a[1],
        c.mean_a[2]
    );
    crate::outln!(
        "mean B (RGB)    {:.6} {:.6} {:.6}",
        c.mean_b[0],
        c.mean_b[1],
        c.mean_b[2]
    );
    crate::outln!("max |A−B|       {:.6}", c.max_difference);
    crate::outln!(
        "non-finite      A {}  B {}   (NaN or infinite pixel channels, left out of the figures)",
        c.nonfinite_a,
        c.nonfinite_b
    );
    if let Some(z) = &c.z_test {
        crate::outln!(
            "Z-test          {:.2}% of {} pixel channels pass |z| ≤ {:.3} (α = {}; expect about {:.0}% for matching renders)",
            100.0 * z.pass_rate,
            z.tested,
            Z_CRITICAL,
            Z_TEST_ALPHA,
            100.0 * (1.0 - Z_TEST_ALPHA)
        );
        crate::outln!(
            "z of the means  {:.3}   (|z| > 4 is a significant overall bias)",
            z.z_of_means
        );
        crate::outln!(
            "variance ratio  {:.3}   (mean (A−B)² / mean (VA+VB); 1 when variances are honest)",
            z.variance_ratio
        );
    }
    Ok(())
}
