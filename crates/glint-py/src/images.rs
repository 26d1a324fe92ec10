//! Reading and writing images (PNG, EXR, PFM) as numpy arrays.

use crate::convert::guard;
use glint::denoise::Denoiser;
use glint::io::Image;
use glint::math::Rgb;
use glint::render::AovImage;
use glint::session::{layer_channels, Outputs};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray3};
use pyo3::exceptions::{PyImportError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;

/// An image as a float32 array of shape (height, width, 3).
pub fn image_array<'py>(py: Python<'py>, img: &Image) -> Bound<'py, PyArray3<f32>> {
    let data: Vec<f32> = img.pixels.iter().flat_map(|p| [p.r, p.g, p.b]).collect();
    Array3::from_shape_vec((img.height, img.width, 3), data).expect("pixels fill the image").into_pyarray(py)
}

/// Reads a PNG (decoded from sRGB), EXR or PFM file as linear RGB.
#[pyfunction]
pub fn read_image<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray3<f32>>> {
    guard(|| {
        let img = py.detach(|| glint::io::read_image(&path)).map_err(PyOSError::new_err)?;
        Ok(image_array(py, &img))
    })
}

/// An array (height, width, 3) as an image.
pub fn array_image(name: &str, image: &PyReadonlyArray3<'_, f32>) -> PyResult<Image> {
    let a = image.as_array();
    let (h, w, c) = a.dim();
    if c != 3 {
        return Err(PyValueError::new_err(format!("{name}: expected shape (height, width, 3), got ({h}, {w}, {c})")));
    }
    let pixels =
        a.outer_iter().flat_map(|row| row.outer_iter().map(|p| Rgb { r: p[0], g: p[1], b: p[2] }).collect::<Vec<_>>());
    Ok(Image { width: w, height: h, pixels: pixels.collect() })
}

/// Writes `image` (height, width, 3) and `layers` (name, (h, w, c) array) as the library
/// writes a render's outputs: beside it in an EXR file, else each as `OUT.NAME.png`.
#[pyfunction]
#[pyo3(signature = (path, image, layers))]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    image: PyReadonlyArray3<'_, f32>,
    layers: Vec<(String, PyReadonlyArray3<'_, f32>)>,
) -> PyResult<()> {
    guard(|| {
        let image = array_image("image", &image)?;
        let (w, h) = (image.width, image.height);
        let mut aovs = Vec::with_capacity(layers.len());
        for (name, layer) in &layers {
            let l = layer.as_array();
            let (lh, lw, c) = l.dim();
            if (lh, lw) != (h, w) {
                return Err(PyValueError::new_err(format!(
                    "aovs: the layer {name} of shape {:?} for a {w}x{h} image",
                    l.dim()
                )));
            }
            aovs.push(AovImage {
                name: name.clone(),
                channels: layer_channels(name, c),
                width: w,
                height: h,
                data: l.iter().copied().collect(),
            });
        }
        let outputs = Outputs { image, layers: aovs };
        outputs.check(&path).map_err(PyValueError::new_err)?;
        py.detach(|| outputs.write(&path)).map_err(PyOSError::new_err)
    })
}

/// Denoises `image` with Open Image Denoise, guided by `albedo` and `normal` where given
/// (arrays of its shape).
#[pyfunction]
#[pyo3(signature = (image, albedo=None, normal=None))]
pub fn denoise<'py>(
    py: Python<'py>,
    image: PyReadonlyArray3<'py, f32>,
    albedo: Option<PyReadonlyArray3<'py, f32>>,
    normal: Option<PyReadonlyArray3<'py, f32>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    guard(|| {
        let image = array_image("image", &image)?;
        let albedo = albedo.map(|a| array_image("albedo", &a)).transpose()?;
        let normal = normal.map(|n| array_image("normal", &n)).transpose()?;
        let denoiser = load_denoiser(py)?;
        let clean = py
            .detach(|| denoiser.denoise(&image, albedo.as_ref(), normal.as_ref()))
            .map_err(|e| PyRuntimeError::new_err(e.message))?;
        Ok(image_array(py, &clean))
    })
}

/// Finds the denoiser now (it is loaded once per process), so that a render asked to
/// denoise fails before its first sample where there is none: ImportError saying how to
/// install it.
#[pyfunction]
pub fn find_denoiser(py: Python<'_>) -> PyResult<()> {
    guard(|| load_denoiser(py).map(|_| ()))
}

/// The library's denoiser, looked for first in this interpreter's `pyoidn` package; a
/// missing one is an ImportError saying how to install it.
pub fn load_denoiser(py: Python<'_>) -> PyResult<Denoiser> {
    let python: Option<PathBuf> = py.import("sys")?.getattr("executable")?.extract().ok();
    let python = python.filter(|p| !p.as_os_str().is_empty());
    py.detach(|| Denoiser::load(python.as_deref())).map_err(|e| PyImportError::new_err(e.message))
}
