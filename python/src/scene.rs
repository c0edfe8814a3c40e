//! `glint.load`, `glint.load_string`, `glint.load_dict` and the `Scene` they return.

use crate::dict_toml::to_toml_text;
use crate::render::GpuCache;
use crate::SceneError;
use glint::scene;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// A validated scene, as `glint render` reads it. Render it with `glint.render`.
#[pyclass(module = "glint", frozen)]
pub struct Scene {
    pub scene: scene::Scene,
    /// Where the scene came from: the file, or the name messages use for text and dicts.
    pub source: PathBuf,
    /// The GPU renderer of the last GPU render, kept for the next one with the same settings.
    pub gpu: Mutex<Option<GpuCache>>,
}

impl Scene {
    fn new(scene: scene::Scene, source: &Path) -> Scene {
        Scene {
            scene,
            source: source.to_owned(),
            gpu: Mutex::new(None),
        }
    }
}

#[pymethods]
impl Scene {
    /// The scene's name: its file's stem.
    #[getter]
    fn name(&self) -> &str {
        &self.scene.name
    }

    /// The file the scene was read from, or the name given to `load_string`/`load_dict`.
    #[getter]
    fn path(&self) -> PathBuf {
        self.source.clone()
    }

    /// The scene's `[render]` width.
    #[getter]
    fn width(&self) -> u32 {
        self.scene.render.width
    }

    /// The scene's `[render]` height.
    #[getter]
    fn height(&self) -> u32 {
        self.scene.render.height
    }

    /// The scene's `[render]` samples per pixel.
    #[getter]
    fn spp(&self) -> u32 {
        self.scene.render.spp
    }

    /// The scene's `[render]` seed.
    #[getter]
    fn seed(&self) -> u32 {
        self.scene.render.seed
    }

    /// The scene's `[render]` max_bounces.
    #[getter]
    fn max_bounces(&self) -> u32 {
        self.scene.render.max_bounces
    }

    /// Equal when every validated field is (name included: it is the file's stem).
    fn __eq__(&self, other: PyRef<'_, Scene>) -> bool {
        self.scene == other.scene
    }

    fn __repr__(&self) -> String {
        let r = &self.scene.render;
        format!(
            "<glint.Scene {:?} from {:?}: {}×{}, {} spp, {} materials, {} spheres, {} quads, {} triangles>",
            self.scene.name,
            self.source.display().to_string(),
            r.width,
            r.height,
            r.spp,
            self.scene.materials.len(),
            self.scene.spheres.len(),
            self.scene.quads.len(),
            self.scene.triangles.len()
        )
    }
}

fn scene_error(e: scene::SceneError) -> PyErr {
    SceneError::new_err(e.to_string())
}

/// load(path) -> Scene
///
/// Reads and validates a scene file (TOML) as `glint render` does. Raises glint.SceneError
/// with the CLI's message (file, line and column, field) for a bad scene.
#[pyfunction]
pub fn load(py: Python<'_>, path: PathBuf) -> PyResult<Scene> {
    let scene = py
        .detach(|| scene::Scene::load(&path))
        .map_err(scene_error)?;
    Ok(Scene::new(scene, &path))
}

/// load_string(text, path="<string>") -> Scene
///
/// Parses and validates scene text (TOML). `path` names the text in error messages and gives
/// the scene its name; relative mesh and texture files are found from its folder.
#[pyfunction]
#[pyo3(signature = (text, path = PathBuf::from("<string>")))]
pub fn load_string(py: Python<'_>, text: &str, path: PathBuf) -> PyResult<Scene> {
    let scene = py
        .detach(|| scene::Scene::parse(text, &path))
        .map_err(scene_error)?;
    Ok(Scene::new(scene, &path))
}

/// load_dict(scene, path="<dict>") -> Scene
///
/// A scene given as the TOML file's structure in Python: a dict of tables (`camera`,
/// `render`, `materials`, ...), lists for arrays (of tables too), and str, int, float and bool
/// values; NumPy arrays and scalars count as lists and numbers. It is written out as TOML and
/// read by glint's own parser, so it is checked as a file is: a bad scene raises
/// glint.SceneError with the CLI's message (its line numbers are those of the TOML text).
/// `path` is as in load_string.
#[pyfunction]
#[pyo3(signature = (scene, path = PathBuf::from("<dict>")))]
pub fn load_dict(py: Python<'_>, scene: &Bound<'_, PyAny>, path: PathBuf) -> PyResult<Scene> {
    let text = to_toml_text(scene)?;
    load_string(py, &text, path)
}
