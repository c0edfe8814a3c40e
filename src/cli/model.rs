//! The flags of a model file given as the scene (`glint render model.glb`, `glint view
//! model.glb`): which camera, which environment. A scene file sets these itself, so with one
//! they are an error.

use crate::error::InputError;
use crate::scene::limits::MAX_RADIANCE;
use crate::scene::model::{self, ModelOptions, ModelScene};
use crate::scene::Scene;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug, Default, Clone)]
pub struct ModelArgs {
    /// Model files: render through the file's N-th camera (0-based, in node order) instead of
    /// its first camera.
    #[arg(long, value_name = "N")]
    pub camera: Option<usize>,
    /// Model files: light the model by this equirectangular map (.hdr, .exr) instead of the
    /// generated studio environment.
    #[arg(long, value_name = "FILE.hdr|exr")]
    pub environment: Option<PathBuf>,
    /// Model files: multiply the environment's radiance by S (default 1).
    #[arg(long, value_name = "S", value_parser = parse_strength, allow_negative_numbers = true)]
    pub environment_strength: Option<f32>,
    /// Model files: turn the environment by this many degrees about +y (default 0).
    #[arg(long, value_name = "DEGREES", value_parser = parse_rotate, allow_negative_numbers = true)]
    pub environment_rotate: Option<f32>,
}

fn parse_strength(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if !(0.0..=MAX_RADIANCE as f32).contains(&v) {
        return Err(format!("must be in [0, {MAX_RADIANCE:e}], got {s}"));
    }
    Ok(v)
}

fn parse_rotate(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if !(-360.0..=360.0).contains(&v) {
        return Err(format!("must be in [-360, 360] degrees, got {s}"));
    }
    Ok(v)
}

impl ModelArgs {
    fn given(&self) -> Option<&'static str> {
        if self.camera.is_some() {
            Some("--camera")
        } else if self.environment.is_some() {
            Some("--environment")
        } else if self.environment_strength.is_some() {
            Some("--environment-strength")
        } else if self.environment_rotate.is_some() {
            Some("--environment-rotate")
        } else {
            None
        }
    }

    pub fn options(&self, width: Option<u32>, height: Option<u32>) -> ModelOptions {
        ModelOptions {
            camera: self.camera,
            environment: self.environment.clone(),
            environment_strength: self.environment_strength.unwrap_or(1.0),
            environment_rotate: self.environment_rotate.unwrap_or(0.0),
            width,
            height,
        }
    }

    /// The scene `path` names: a scene file, or a model file as a scene (then also what
    /// writing it out needs). These flags with a scene file are an error.
    pub fn load(
        &self,
        path: &Path,
        width: Option<u32>,
        height: Option<u32>,
    ) -> Result<(Scene, Option<ModelScene>)> {
        if model::is_model_file(path) {
            let m =
                model::load_model(path, &self.options(width, height)).map_err(InputError::from)?;
            return Ok((m.scene.clone(), Some(m)));
        }
        self.refuse_for_scene_file(path)?;
        Ok((Scene::load(path).map_err(InputError::from)?, None))
    }

    /// These flags given with a scene file (not a model file) are an error.
    pub fn refuse_for_scene_file(&self, path: &Path) -> Result<(), InputError> {
        match self.given() {
            Some(flag) if !model::is_model_file(path) => Err(InputError(format!(
                "{flag} applies to a model file ({}), not to a scene file ({}): set it in the \
                 scene file",
                model::MODEL_EXTENSIONS.map(|e| format!(".{e}")).join(", "),
                path.display()
            ))),
            _ => Ok(()),
        }
    }
}
