//! Errors and values between Rust and Python.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// A library error as `glint.SceneError` (defined in Python, a `ValueError` with `.file`,
/// `.line`, `.col` and `.message`).
pub fn scene_error(py: Python<'_>, e: glint::Error) -> PyErr {
    let (file, line, col) = match &e.loc {
        Some(l) => (Some(l.file.display().to_string()), l.line, l.col),
        None => (None, 0, 0),
    };
    let text = e.to_string();
    let made = py
        .import("glint._errors")
        .and_then(|m| m.getattr("SceneError"))
        .and_then(|cls| cls.call1((text.clone(), e.message, file, line, col)));
    match made {
        Ok(err) => PyErr::from_value(err),
        // The package is broken; the message still gets through.
        Err(_) => PyValueError::new_err(text),
    }
}

/// A panic's message, for the exception it becomes.
pub fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Runs `f`, turning a panic into a `RuntimeError` (not pyo3's `PanicException`, which is no
/// `Exception` and escapes `except Exception`).
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(p) => Err(PyRuntimeError::new_err(format!("glint: internal error: {}", panic_message(p)))),
    }
}

/// A pool of `threads` worker threads, or `None` for rayon's global pool (all cores).
pub fn thread_pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    threads
        .map(|n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| PyRuntimeError::new_err(format!("threads: {e}")))
        })
        .transpose()
}
