//! Reading and writing images (PNG, EXR, PFM) as numpy arrays.

use crate::convert::guard;
use glint::io::layers::{write_exr_channels, Channel};
use glint::io::Image;
use glint::math::Rgb;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray3};
use pyo3::exceptions::{PyOSError, PyValueError};
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

/// Writes `image` (height, width, 3); `layers` (name, channel names, (h, w, c) array) go
/// beside it in an EXR file.
#[pyfunction]
#[pyo3(signature = (path, image, layers))]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    image: PyReadonlyArray3<'_, f32>,
    layers: Vec<(Vec<String>, PyReadonlyArray3<'_, f32>)>,
) -> PyResult<()> {
    guard(|| {
        let a = image.as_array();
        let (h, w, c) = a.dim();
        if c != 3 {
            return Err(PyValueError::new_err(format!(
                "image: expected shape (height, width, 3), got ({h}, {w}, {c})"
            )));
        }
        if layers.is_empty() {
            let pixels = a
                .outer_iter()
                .flat_map(|row| row.outer_iter().map(|p| Rgb { r: p[0], g: p[1], b: p[2] }).collect::<Vec<_>>())
                .collect();
            let img = Image { width: w, height: h, pixels };
            return py.detach(|| glint::io::write_image(&img, &path)).map_err(PyOSError::new_err);
        }
        // Planar channels, as the EXR writer takes them.
        let mut planes: Vec<(String, Vec<f32>)> = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(i, n)| {
                (n.to_string(), a.outer_iter().flat_map(|r| r.outer_iter().map(|p| p[i]).collect::<Vec<_>>()).collect())
            })
            .collect();
        for (names, layer) in &layers {
            let l = layer.as_array();
            if l.dim().0 != h || l.dim().1 != w || l.dim().2 != names.len() {
                return Err(PyValueError::new_err(format!(
                    "layers: a layer of shape {:?} for a {w}x{h} image with channels {names:?}",
                    l.dim()
                )));
            }
            for (i, n) in names.iter().enumerate() {
                planes.push((
                    n.clone(),
                    l.outer_iter().flat_map(|r| r.outer_iter().map(|p| p[i]).collect::<Vec<_>>()).collect(),
                ));
            }
        }
        let channels: Vec<Channel> = planes.iter().map(|(n, v)| Channel { name: n.clone(), values: v }).collect();
        py.detach(|| write_exr_channels(&path, w, h, &channels)).map_err(PyOSError::new_err)
    })
}
