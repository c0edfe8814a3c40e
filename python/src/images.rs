//! Images between NumPy and glint: `glint.write`, `glint.read` and `glint.compare`.

use glint::compare::{compare as compare_images, Z_TEST_ALPHA};
use glint::output::{check_output_path, Image, ImageFormat};
use glint::tonemap::{DisplayTransform, Tonemap};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict};
use std::path::PathBuf;

/// An image's pixels as native-endian float32 bytes, row by row, RGB.
pub fn image_bytes(image: &Image) -> Vec<u8> {
    image
        .pixels
        .iter()
        .flatten()
        .flat_map(|v| v.to_ne_bytes())
        .collect()
}

/// An image from [`image_bytes`]' layout; `what` names it in the error.
fn image_from_bytes(what: &str, data: &[u8], height: usize, width: usize) -> PyResult<Image> {
    if data.len() != height * width * 12 {
        return Err(PyValueError::new_err(format!(
            "{what}: {} bytes is not a {height}×{width}×3 float32 image",
            data.len()
        )));
    }
    let floats: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes(b.try_into().expect("4 bytes")))
        .collect();
    Ok(Image {
        width: width as u32,
        height: height as u32,
        pixels: floats.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
    })
}

/// The compiled half of `glint.write`: a .png through the display transform, an .exr linear.
#[pyfunction]
#[pyo3(signature = (path, data, height, width, tonemap="clamp", exposure=0.0))]
pub fn write(
    py: Python<'_>,
    path: PathBuf,
    data: &[u8],
    height: usize,
    width: usize,
    tonemap: &str,
    exposure: f64,
) -> PyResult<()> {
    let image = image_from_bytes("image", data, height, width)?;
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

/// The compiled half of `glint.read`: a linear .exr as bytes, height and width.
#[pyfunction]
pub fn read<'py>(py: Python<'py>, path: PathBuf) -> PyResult<(Bound<'py, PyByteArray>, u32, u32)> {
    let image = py
        .detach(|| Image::read_exr(&path))
        .map_err(|e| PyOSError::new_err(format!("{e:#}")))?;
    Ok((
        PyByteArray::new(py, &image_bytes(&image)),
        image.height,
        image.width,
    ))
}

/// An image as (bytes, height, width), as the Python half passes it.
type Packed<'a> = (&'a [u8], usize, usize);

/// The compiled half of `glint.compare`: `glint compare --json`'s figures.
#[pyfunction]
#[pyo3(signature = (a, b, variance_a=None, variance_b=None))]
pub fn compare<'py>(
    py: Python<'py>,
    a: Packed<'_>,
    b: Packed<'_>,
    variance_a: Option<Packed<'_>>,
    variance_b: Option<Packed<'_>>,
) -> PyResult<Bound<'py, PyDict>> {
    let unpack = |what: &str, p: Packed<'_>| image_from_bytes(what, p.0, p.1, p.2);
    let (a, b) = (unpack("a", a)?, unpack("b", b)?);
    let variances = match (variance_a, variance_b) {
        (Some(va), Some(vb)) => Some((unpack("variance_a", va)?, unpack("variance_b", vb)?)),
        (None, None) => None,
        _ => {
            return Err(PyValueError::new_err(
                "variance_a and variance_b go together: the Z-test needs both",
            ))
        }
    };
    let c = compare_images(&a, &b, variances.as_ref().map(|(va, vb)| (va, vb)))
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
