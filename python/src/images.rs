//! Images between NumPy and glint: `glint.write`, `glint.read` and `glint.compare`.

use glint::image::compare::{compare as compare_images, Z_TEST_ALPHA};
use glint::image::format::ImageFormat;
use glint::image::output::{check_output_path, Image};
use glint::image::tonemap::{DisplayTransform, Tonemap};
use numpy::ndarray::{Array3, Axis};
use numpy::{IntoPyArray, PyArray3, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// An image as an H×W×3 float32 NumPy array, which takes over the pixels without a copy.
pub fn to_numpy<'py>(py: Python<'py>, image: Image) -> Bound<'py, PyArray3<f32>> {
    let shape = (image.height as usize, image.width as usize, 3);
    let floats: Vec<f32> = image.pixels.into_iter().flatten().collect();
    Array3::from_shape_vec(shape, floats)
        .expect("an Image holds width × height pixels")
        .into_pyarray(py)
}

/// The image in `array`: anything `numpy.asarray(array, dtype=float32)` takes, of shape
/// H×W×3, whatever its strides; `what` names it in the error.
pub fn from_numpy(what: &str, array: &Bound<'_, PyAny>) -> PyResult<Image> {
    let numpy = array.py().import("numpy")?;
    let converted = numpy.call_method1("asarray", (array, "float32"))?;
    let array: PyReadonlyArrayDyn<'_, f32> = converted.extract()?;
    let shape = array.shape();
    if shape.len() != 3 || shape[2] != 3 || shape[0] == 0 || shape[1] == 0 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a non-empty H×W×3 array, got shape {shape:?}"
        )));
    }
    let (Ok(height), Ok(width)) = (u32::try_from(shape[0]), u32::try_from(shape[1])) else {
        return Err(PyValueError::new_err(format!(
            "{what}: shape {shape:?} is too large"
        )));
    };
    let view = array.as_array();
    let mut pixels = Vec::with_capacity(shape[0] * shape[1]);
    for row in view.axis_iter(Axis(0)) {
        for p in row.axis_iter(Axis(0)) {
            pixels.push([p[0], p[1], p[2]]);
        }
    }
    Ok(Image {
        width,
        height,
        pixels,
    })
}

/// write(path, image, *, tonemap="clamp", exposure=0.0)
///
/// Writes an H×W×3 linear image as `glint render -o` does: .exr as float32 radiance, .png
/// through the display transform (exposure in stops, then tonemap "clamp", "aces" or "agx",
/// then sRGB). The write is atomic: the file is complete or absent.
#[pyfunction]
#[pyo3(signature = (path, image, *, tonemap="clamp", exposure=0.0))]
pub fn write(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    tonemap: &str,
    exposure: f64,
) -> PyResult<()> {
    let image = from_numpy("image", image)?;
    let tonemap =
        Tonemap::parse(tonemap).map_err(|m| PyValueError::new_err(format!("tonemap: {m}")))?;
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        return Err(PyValueError::new_err(format!(
            "exposure: must be a finite number of stops in [-64, 64], got {exposure}"
        )));
    }
    check_output_path(&path).map_err(PyValueError::new_err)?;
    let transform = DisplayTransform {
        tonemap,
        exposure: exposure as f32,
    };
    py.detach(|| {
        let shown = match ImageFormat::from_path(&path) {
            Ok(ImageFormat::Png) => transform.image(&image),
            _ => image,
        };
        shown.write(&path)
    })
    .map_err(|e| PyOSError::new_err(format!("{e:#}")))
}

/// read(path) -> numpy.ndarray
///
/// Reads a linear .exr (as `glint render -o out.exr` writes it) as an H×W×3 float32 array.
#[pyfunction]
pub fn read<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let image = py
        .detach(|| Image::read_exr(&path))
        .map_err(|e| PyOSError::new_err(format!("{e:#}")))?;
    Ok(to_numpy(py, image))
}

/// compare(a, b, *, variance_a=None, variance_b=None) -> dict
///
/// Compares image a against the reference b with `glint compare --json`'s figures: rmse,
/// relative_mse, mean_a, mean_b, max_difference, nonfinite_a, nonfinite_b and, given both
/// variance images (σ²/n, as render(variance=True) returns them), z_test (pass_rate, tested,
/// alpha, z_of_means, variance_ratio).
#[pyfunction]
#[pyo3(signature = (a, b, *, variance_a=None, variance_b=None))]
pub fn compare<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    variance_a: Option<&Bound<'py, PyAny>>,
    variance_b: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (from_numpy("a", a)?, from_numpy("b", b)?);
    let variances = match (variance_a, variance_b) {
        (Some(va), Some(vb)) => {
            Some((from_numpy("variance_a", va)?, from_numpy("variance_b", vb)?))
        }
        (None, None) => None,
        _ => {
            return Err(PyValueError::new_err(
                "variance_a and variance_b go together: the Z-test needs both",
            ))
        }
    };
    let c = py
        .detach(|| compare_images(&a, &b, variances.as_ref().map(|(va, vb)| (va, vb))))
        .map_err(PyValueError::new_err)?;
    let out = PyDict::new(py);
    out.set_item("width", a.width)?;
    out.set_item("height", a.height)?;
    out.set_item("rmse", c.rmse)?;
    out.set_item("relative_mse", c.relative_mse)?;
    out.set_item("mean_a", c.mean_a.to_vec())?;
    out.set_item("mean_b", c.mean_b.to_vec())?;
    out.set_item("max_difference", c.max_difference)?;
    out.set_item("nonfinite_a", c.nonfinite_a)?;
    out.set_item("nonfinite_b", c.nonfinite_b)?;
    let z = match &c.z_test {
        Some(z) => {
            let d = PyDict::new(py);
            d.set_item("pass_rate", z.pass_rate)?;
            d.set_item("tested", z.tested)?;
            d.set_item("alpha", Z_TEST_ALPHA)?;
            d.set_item("z_of_means", z.z_of_means)?;
            d.set_item("variance_ratio", z.variance_ratio)?;
            Some(d)
        }
        None => None,
    };
    out.set_item("z_test", z)?;
    Ok(out)
}
