//! `glint._glint`: the compiled half of glint's Python package, a thin layer over the
//! library's session API. The pure-Python package `glint` (python/glint) wraps it with
//! argument checks, dict scenes, `traverse` and the denoiser; see its docstrings.

mod convert;
mod gradient;
mod images;
mod overrides;
mod preview;
mod render;
mod scene;

use pyo3::prelude::*;

#[pymodule]
fn _glint(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::Scene>()?;
    m.add_class::<render::Session>()?;
    m.add_class::<preview::Preview>()?;
    m.add_function(wrap_pyfunction!(scene::load_file, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_json, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_description, m)?)?;
    m.add_function(wrap_pyfunction!(gradient::render_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(images::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(images::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(images::denoise, m)?)?;
    m.add_function(wrap_pyfunction!(images::find_denoiser, m)?)?;
    m.add("DEFAULT_PASS_SPP", glint::session::DEFAULT_PASS_SPP)?;
    m.add("INTEGRATORS", glint::session::integrator_names().to_vec())?;
    m.add("AOV_NAMES", glint::render::Aov::ALL.iter().map(|a| a.name()).collect::<Vec<_>>())?;
    Ok(())
}
