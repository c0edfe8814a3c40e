//! `glint.load`, `glint.load_string`, `glint.load_dict` and the `Scene` they return.

use crate::dict_toml::{from_toml_text, to_toml_text};
use crate::gpu_cache::GpuCache;
use crate::SceneError;
use glint::input_file::{read_regular_file, SCENE_FILE_LIMIT};
use glint::scene;
use glint::scene::model;
use glint::scene::model_toml::model_toml;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// A validated scene, as `glint render` reads it: the compiled half of `glint.Scene`
/// (python/glint/scene.py), which edits it.
#[pyclass(module = "glint._glint", frozen)]
pub struct Scene {
    pub scene: scene::Scene,
    /// Where the scene came from: the file, or the name messages use for text and dicts.
    pub source: PathBuf,
    /// The TOML text it was validated from.
    text: String,
    /// The GPU renderer of the last GPU render, kept for the next one with the same settings.
    pub gpu: Mutex<Option<GpuCache>>,
}

impl Scene {
    fn new(scene: scene::Scene, source: &Path, text: String) -> Scene {
        Scene {
            scene,
            source: source.to_owned(),
            text,
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

    /// The TOML it was validated from, as dictionaries and lists (as tomllib reads it).
    fn table<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        from_toml_text(py, &self.text)
    }

    /// Takes over `other`'s GPU renderer, for an edit of `other`: the next render reuses its
    /// compiled kernel where the edit left the objects alone (a camera or [render] change).
    fn adopt_renderer(&self, other: PyRef<'_, Scene>) {
        if std::ptr::eq(self, &*other) {
            return;
        }
        let taken = other.gpu.lock().unwrap_or_else(|e| e.into_inner()).take();
        *self.gpu.lock().unwrap_or_else(|e| e.into_inner()) = taken;
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

/// glint.SceneError with the CLI's message, and its parts as attributes: path, line and
/// column (None where the problem has no place in the text), field (None where it is not
/// about one field) and message.
pub fn scene_error(e: scene::SceneError) -> PyErr {
    let err = SceneError::new_err(e.to_string());
    Python::attach(|py| {
        let value = err.value(py);
        let (line, column) = e.position.unzip();
        let parts = [
            (
                "path",
                e.path.display().to_string().into_pyobject(py)?.into_any(),
            ),
            ("line", line.into_pyobject(py)?.into_any()),
            ("column", column.into_pyobject(py)?.into_any()),
            ("field", e.field.clone().into_pyobject(py)?.into_any()),
            ("message", e.message.clone().into_pyobject(py)?.into_any()),
        ];
        for (name, part) in parts {
            value.setattr(name, part)?;
        }
        PyResult::Ok(())
    })
    .map(|()| err)
    .unwrap_or_else(|e| e)
}

/// load(path, camera=None) -> Scene
///
/// Reads and validates a scene file (TOML) as `glint render` does, or builds the scene of a
/// model file (.glb, .gltf, .obj, .ply) as `glint render model.glb` does: the file's camera
/// (`camera`: `--camera N`) or a framing one, its lights, the studio environment. Raises
/// glint.SceneError with the CLI's message (file, line and column, field) for a bad scene.
#[pyfunction]
#[pyo3(signature = (path, camera = None))]
pub fn load(py: Python<'_>, path: PathBuf, camera: Option<usize>) -> PyResult<Scene> {
    let unreadable = |path: &Path, message: String| scene::SceneError {
        path: path.to_owned(),
        position: None,
        field: None,
        message,
    };
    let (scene, text) = py
        .detach(|| {
            if model::is_model_file(&path) {
                let options = model::ModelOptions {
                    camera,
                    ..Default::default()
                };
                let built = model::load_model(&path, &options)?;
                // The scene file `--print-scene` writes, which renders the same scene.
                let text = model_toml(&built);
                return Ok((built.scene, text));
            }
            if camera.is_some() {
                return Err(unreadable(
                    &path,
                    "camera applies to a model file, not to a scene file: set [camera] in it"
                        .into(),
                ));
            }
            let scene = scene::Scene::load(&path)?;
            // Read again for Scene.table: it passed, so it is UTF-8 text within the limit,
            // unless it changed in between.
            let text = read_regular_file(&path, SCENE_FILE_LIMIT, "scene file")
                .and_then(|b| String::from_utf8(b).map_err(|e| e.to_string()))
                .map_err(|message| unreadable(&path, message))?;
            Ok((scene, text))
        })
        .map_err(scene_error)?;
    Ok(Scene::new(scene, &path, text))
}

/// load_string(text, path="<string>") -> Scene
///
/// Parses and validates scene text (TOML). `path` names the text in error messages and gives
/// the scene its name; relative mesh and texture files are found from its folder.
#[pyfunction]
#[pyo3(signature = (text, path = PathBuf::from("<string>")))]
pub fn load_string(py: Python<'_>, text: String, path: PathBuf) -> PyResult<Scene> {
    let scene = py
        .detach(|| scene::Scene::parse(&text, &path))
        .map_err(scene_error)?;
    Ok(Scene::new(scene, &path, text))
}

/// load_dict(scene, path="<dict>") -> Scene
///
/// The compiled half of `glint.load_dict` (python/glint/scene.py, which takes meshes as
/// arrays too): the dict is written out as TOML and read as load_string reads text.
#[pyfunction]
#[pyo3(signature = (scene, path = PathBuf::from("<dict>")))]
pub fn load_dict(py: Python<'_>, scene: &Bound<'_, PyAny>, path: PathBuf) -> PyResult<Scene> {
    let text = to_toml_text(scene)?;
    load_string(py, text, path)
}
