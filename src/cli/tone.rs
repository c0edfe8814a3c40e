//! `--tonemap` and `--exposure`: how radiance is shown, shared by `glint render` (PNG output)
//! and `glint view` (the window and its PNG screenshots).

use crate::image::tonemap::{parse_exposure, DisplayTransform, Tonemap};
use clap::Args;

#[derive(Args, Debug, Default)]
pub struct ToneArgs {
    /// Tone curve for PNG output (and `glint view`'s window): clamp (default), aces (Narkowicz's
    /// fit) or agx (minimal AgX). EXR output stays linear.
    #[arg(long, value_name = "clamp|aces|agx", value_parser = Tonemap::parse)]
    pub tonemap: Option<Tonemap>,
    /// Exposure for PNG output (and the window's start), in stops (radiance × 2^EV before the tone curve).
    #[arg(long, value_name = "EV", value_parser = parse_exposure, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
}

impl ToneArgs {
    pub fn transform(&self) -> DisplayTransform {
        DisplayTransform {
            tonemap: self.tonemap.unwrap_or_default(),
            exposure: self.exposure.unwrap_or(0.0),
        }
    }
}
