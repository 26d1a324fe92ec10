//! `render_gradient`: the gradient of a loss on the image with respect to scene parameters
//! (the library's `Session::render_gradient`), computed without the GIL and stopped by
//! Ctrl-C.

use crate::convert::{panic_message, scene_error, thread_pool};
use crate::render::{DoneSignal, SIGNAL_POLL};
use crate::scene::Scene;
use glint::math::rgb;
use numpy::ndarray::ArrayD;
use numpy::{IntoPyArray, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};

/// The gradient of `sum(grad_image * image)` with respect to each parameter in `params`,
/// as a dict of float64 arrays shaped like the parameters.
#[pyfunction]
#[pyo3(signature = (scene, params, grad_image, spp, seed=0, threads=None))]
pub fn render_gradient<'py>(
    py: Python<'py>,
    scene: &Bound<'py, Scene>,
    params: Vec<String>,
    grad_image: PyReadonlyArray3<'py, f32>,
    spp: u32,
    seed: u64,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let shape = grad_image.shape().to_vec();
    let (w, h) = {
        let s = scene.borrow();
        let film = &s.session.description().film;
        (film.width as usize, film.height as usize)
    };
    if shape != [h, w, 3] {
        return Err(PyValueError::new_err(format!(
            "grad_image: expected shape ({h}, {w}, 3) (the image's), got {shape:?}"
        )));
    }
    let g: Vec<_> = grad_image
        .as_array()
        .outer_iter()
        .flat_map(|row| row.outer_iter().map(|p| rgb(p[0], p[1], p[2])).collect::<Vec<_>>())
        .collect();
    if g.iter().any(|c| !c.is_finite()) {
        return Err(PyValueError::new_err("grad_image: holds values that are not finite"));
    }
    if threads == Some(0) {
        return Err(PyValueError::new_err("threads: must be at least 1"));
    }
    let pool = thread_pool(threads)?;
    let mut s = scene.try_borrow_mut()?;
    let session = &mut s.session;
    let cancel = AtomicBool::new(false);
    let signal = DoneSignal::default();
    let mut interrupt = None;
    let outcome = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let mut work = || session.render_gradient(&params, &g, spp, seed, &cancel);
                match &pool {
                    Some(p) => p.install(work),
                    None => work(),
                }
            }));
            signal.set();
            r
        });
        // Waits without the GIL, taking it briefly to run Python's signal handlers (Ctrl-C).
        while !py.detach(|| signal.wait(SIGNAL_POLL)) {
            if let Err(e) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                interrupt = Some(e);
                break;
            }
        }
        py.detach(|| worker.join())
    });
    drop(s);
    if let Some(e) = interrupt {
        return Err(e);
    }
    let grads = match outcome {
        Ok(Ok(Ok(g))) => g,
        Ok(Ok(Err(e))) => return Err(scene_error(py, e)),
        Ok(Err(p)) | Err(p) => {
            return Err(PyRuntimeError::new_err(format!("glint: internal error: {}", panic_message(p))))
        }
    };
    let out = PyDict::new(py);
    for g in grads {
        let array = ArrayD::from_shape_vec(g.shape.clone(), g.values)
            .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", g.name)))?;
        out.set_item(g.name, array.into_pyarray(py))?;
    }
    Ok(out)
}
