//! `glint render`'s outputs beyond the mean: the denoiser's AOVs, the denoised image, tone
//! mapping for PNG, and the firefly clamp. Checked before rendering, applied after.

use super::tone::ToneArgs;
use crate::error::InputError;
use crate::image::denoise;
use crate::image::format::ImageFormat;
use crate::image::output::Image;
use crate::image::output_check::OutputSet;
use crate::image::tonemap::DisplayTransform;
use crate::kernel::types::Params;
use crate::render::Renderer;
use anyhow::{Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args, Debug, Default)]
pub struct PostArgs {
    /// Write Open Image Denoise's result (RT filter, guided by albedo and normal) to the output
    /// file; the raw estimate goes to --raw. Needs OIDN: `pip install pyoidn`.
    #[arg(long)]
    pub denoise: bool,
    /// With --denoise: also write the raw, unbiased mean radiance to this .exr.
    #[arg(long, value_name = "FILE.exr", requires = "denoise")]
    pub raw: Option<PathBuf>,
    /// Write the mean albedo at each path's first non-specular vertex to this .exr.
    #[arg(long, value_name = "FILE.exr")]
    pub albedo: Option<PathBuf>,
    /// Write the mean world-space shading normal there to this .exr (averaged, not renormalised).
    #[arg(long, value_name = "FILE.exr")]
    pub normal: Option<PathBuf>,
    /// Write the mean camera distance of the first hit to this .exr (background: 1e30).
    #[arg(long, value_name = "FILE.exr")]
    pub depth: Option<PathBuf>,
    #[command(flatten)]
    pub tone: ToneArgs,
    /// Firefly clamp (biased, off by default): each contribution of light that has scattered
    /// at least once is scaled down so its brightest channel is at most L.
    #[arg(long = "clamp", value_name = "L", value_parser = parse_clamp)]
    pub radiance_clamp: Option<f32>,
}

fn parse_clamp(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if !v.is_finite() || v <= 0.0 {
        return Err(format!("must be a finite number > 0, got {s}"));
    }
    Ok(v)
}

impl PostArgs {
    fn display(&self) -> DisplayTransform {
        self.tone.transform()
    }

    fn aov_outputs(&self) -> [(&'static str, Option<&PathBuf>); 3] {
        [
            ("--albedo", self.albedo.as_ref()),
            ("--normal", self.normal.as_ref()),
            ("--depth", self.depth.as_ref()),
        ]
    }

    /// Whether the kernel must accumulate AOVs.
    pub fn needs_aovs(&self) -> bool {
        self.denoise || self.aov_outputs().iter().any(|(_, p)| p.is_some())
    }

    /// Adds the extra outputs to the command's [`OutputSet`], so they are checked together
    /// with the others (format, folder, same file twice, an output that is an input).
    pub fn outputs(&self, set: OutputSet) -> OutputSet {
        self.aov_outputs()
            .into_iter()
            .chain([("--raw", self.raw.as_ref())])
            .fold(set, |set, (flag, path)| {
                set.exr_opt(flag, path.map(|p| p.as_path()))
            })
    }

    /// Refuses AOVs and --denoise on a partial or resumed render (exit 2): the AOV means are
    /// not kept in partial files, so they would cover only this run's samples.
    pub fn refuse_partial(&self, partial_or_resumed: bool) -> Result<()> {
        if partial_or_resumed && self.needs_aovs() {
            return Err(InputError(
                "--denoise, --albedo, --normal and --depth need a whole render: they cannot be \
                 combined with --samples, --shard or --resume"
                    .into(),
            )
            .into());
        }
        Ok(())
    }

    /// For --denoise, checks that OIDN loads (exit 1 with the install step when not), before
    /// rendering.
    pub fn check(&self) -> Result<()> {
        if self.denoise {
            denoise::oidn()?;
        }
        Ok(())
    }

    /// How PNG output is shown.
    pub fn display_transform(&self) -> DisplayTransform {
        self.display()
    }

    /// Sets what the kernel needs: AOVs and the firefly clamp.
    pub fn configure(&self, params: &mut Params) {
        params.aovs = self.needs_aovs() as u32;
        params.radiance_clamp = self.radiance_clamp.unwrap_or(0.0);
    }

    /// Writes `image` to `path`: tone-mapped for PNG, linear for EXR.
    pub fn write_output(&self, image: &Image, path: &Path) -> Result<()> {
        let shown = match ImageFormat::from_path(path) {
            Ok(ImageFormat::Png) => self.display().image(image),
            _ => image.clone(),
        };
        shown
            .write(path)
            .with_context(|| format!("writing {}", path.display()))
    }

    /// With --denoise, writes the denoised `mean` to `output` (the raw mean is the render
    /// writer's, at --raw); writes the AOVs. Returns the seconds spent denoising, with --denoise.
    pub fn finish(
        &self,
        renderer: &mut dyn Renderer,
        mean: &Image,
        output: &Path,
    ) -> Result<Option<f64>> {
        let aovs = if self.needs_aovs() {
            Some(renderer.read_aovs()?)
        } else {
            None
        };
        let mut denoise_seconds = None;
        if let (Some(aovs), true) = (&aovs, self.denoise) {
            let started = Instant::now();
            let denoised = denoise::oidn()?.denoise(mean, aovs)?;
            denoise_seconds = Some(started.elapsed().as_secs_f64());
            self.write_output(&denoised, output)?;
        }
        if let Some(aovs) = &aovs {
            for (image, (_, path)) in [&aovs.albedo, &aovs.normal, &aovs.depth]
                .into_iter()
                .zip(self.aov_outputs())
            {
                if let Some(path) = path {
                    self.write_output(image, path)?;
                }
            }
        }
        Ok(denoise_seconds)
    }
}
