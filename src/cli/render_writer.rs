//! Writing a render's outputs, at checkpoints and at the end: the image (a resumable partial
//! file when it is an .exr) and the variance image. A checkpoint that cannot be written (a full
//! disk, a deleted folder) does not stop the render: glint warns once and tries again at the
//! next checkpoint; only a failed final write is an error.

use crate::output::Image;
use crate::partial::{write_image, Partial, PartialInfo};
use crate::render::Renderer;
use anyhow::{Context, Result};
use std::path::PathBuf;

pub struct RenderWriter {
    pub output: PathBuf,
    pub variance: Option<PathBuf>,
    /// The partial file's header; its ranges are filled in from the renderer at each write.
    pub info: PartialInfo,
    checkpoint_warned: bool,
}

impl RenderWriter {
    pub fn new(output: PathBuf, variance: Option<PathBuf>, info: PartialInfo) -> RenderWriter {
        RenderWriter {
            output,
            variance,
            info,
            checkpoint_warned: false,
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
        let partial = self.partial(renderer)?;
        if let Err(e) = write_image(&self.output, &partial) {
            if !self.checkpoint_warned {
                crate::errln!(
                    "glint: warning: cannot write the checkpoint {}: {e:#}; rendering on and trying again at the next checkpoint",
                    self.output.display()
                );
                self.checkpoint_warned = true;
            }
        }
        Ok(())
    }

    /// Writes the image and the variance image; returns both.
    pub fn finish(&mut self, renderer: &mut dyn Renderer) -> Result<(Image, Image)> {
        let partial = self.partial(renderer)?;
        write_image(&self.output, &partial)
            .with_context(|| format!("writing {}", self.output.display()))?;
        let variance = partial.accumulation.variance_image();
        if let Some(path) = &self.variance {
            variance
                .write(path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok((partial.accumulation.mean_image(), variance))
    }
}
