//! Writing a render's outputs, at checkpoints and at the end: the image (a resumable partial
//! file when it is an .exr) and the variance image. A checkpoint that cannot be written (a full
//! disk, a deleted folder) does not stop the render: glint warns once and tries again at the
//! next checkpoint; only a failed final write is an error. With --denoise the image goes to
//! --raw (or nowhere), as `-o` is then the denoised image (src/cli/post.rs).

use crate::image::format::ImageFormat;
use crate::image::output::Image;
use crate::image::tonemap::DisplayTransform;
use crate::render::partial::{Partial, PartialInfo};
use crate::render::Renderer;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

pub struct RenderWriter {
    /// The running image: a partial file for .exr, the tone-mapped mean for .png.
    pub output: Option<PathBuf>,
    pub variance: Option<PathBuf>,
    /// How a .png output shows radiance (--tonemap, --exposure).
    pub display: DisplayTransform,
    /// The partial file's header; its ranges are filled in from the renderer at each write.
    pub info: PartialInfo,
    checkpoint_warned: bool,
}

impl RenderWriter {
    pub fn new(
        output: Option<PathBuf>,
        variance: Option<PathBuf>,
        display: DisplayTransform,
        info: PartialInfo,
    ) -> RenderWriter {
        RenderWriter {
            output,
            variance,
            display,
            info,
            checkpoint_warned: false,
        }
    }

    /// A partial file for .exr (resumable, mergeable); the tone-mapped mean for .png.
    fn write_image(&self, path: &Path, partial: &Partial) -> Result<()> {
        match ImageFormat::from_path(path).map_err(anyhow::Error::msg)? {
            ImageFormat::Exr => partial.write(path),
            _ => self
                .display
                .image(&partial.accumulation.mean_image())
                .write(path),
        }
    }

    fn partial(&self, renderer: &mut dyn Renderer) -> Result<Partial> {
        let accumulation = renderer.read_accumulation()?;
        let start = renderer.first_sample();
        let mut info = self.info.clone();
        info.ranges = std::iter::once(start..start + accumulation.count).collect();
        Ok(Partial { info, accumulation })
    }

    /// Refreshes the output with the running image; a write error is a warning (once).
    pub fn checkpoint(&mut self, renderer: &mut dyn Renderer) -> Result<()> {
        let Some(output) = &self.output else {
            return Ok(());
        };
        let partial = self.partial(renderer)?;
        if let Err(e) = self.write_image(output, &partial) {
            if !self.checkpoint_warned {
                crate::errln!(
                    "glint: warning: cannot write the checkpoint {}: {e:#}; rendering on and trying again at the next checkpoint",
                    output.display()
                );
                self.checkpoint_warned = true;
            }
        }
        Ok(())
    }

    /// Writes the image and the variance image; returns both.
    pub fn finish(&mut self, renderer: &mut dyn Renderer) -> Result<(Image, Image)> {
        let partial = self.partial(renderer)?;
        if let Some(output) = &self.output {
            self.write_image(output, &partial)
                .with_context(|| format!("writing {}", output.display()))?;
        }
        let variance = partial.accumulation.variance_image();
        if let Some(path) = &self.variance {
            variance
                .write(path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok((partial.accumulation.mean_image(), variance))
    }
}
