//! `glint._glint`: the compiled half of the `glint` Python package (python/glint/). It calls
//! the `glint` crate for everything: scene loading and validation, the renderers, image files
//! and comparisons. Images cross the boundary as H×W×3 float32 NumPy arrays (the numpy crate):
//! a render's pixels become the array without a copy.

mod dict_toml;
mod gpu_cache;
mod images;
mod render;
mod scene;

use pyo3::prelude::*;

pyo3::create_exception!(
    glint,
    SceneError,
    pyo3::exceptions::PyValueError,
    "A bad scene: the message is the CLI's (file, line and column, field, what is wrong)."
);

#[pymodule]
fn _glint(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add_class::<scene::Scene>()?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_string, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_dict, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(images::write, m)?)?;
    m.add_function(wrap_pyfunction!(images::read, m)?)?;
    m.add_function(wrap_pyfunction!(images::compare, m)?)?;
    Ok(())
}
