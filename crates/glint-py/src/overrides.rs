//! Python's render keywords (`integrator=`, `max_depth=`, ...) as the library's
//! [`Overrides`], the one type every front end fills.

use glint::session::Overrides;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `spp`, `seed` and the keywords in `d` (name -> value; None values are left out) as
/// overrides; an unknown name or a value of the wrong kind is an error naming it.
pub fn overrides(spp: Option<u32>, seed: Option<u64>, d: Option<&Bound<'_, PyDict>>) -> PyResult<Overrides> {
    let mut o = Overrides { spp, seed, ..Overrides::default() };
    let Some(d) = d else { return Ok(o) };
    for (key, value) in d.iter() {
        let key: String = key.extract()?;
        if value.is_none() {
            continue;
        }
        let text = || -> PyResult<String> {
            value.extract().map_err(|_| PyTypeError::new_err(format!("{key} must be a str")))
        };
        let parsed = |t: String| PyValueError::new_err(format!("{key}: {t}"));
        let int =
            || -> PyResult<i64> { value.extract().map_err(|_| PyTypeError::new_err(format!("{key} must be an int"))) };
        let size = || -> PyResult<u32> {
            let v = int()?;
            u32::try_from(v).map_err(|_| PyValueError::new_err(format!("{key} {v} is not a number of pixels")))
        };
        match key.as_str() {
            "integrator" => o.integrator = Some(text()?),
            "max_depth" => o.max_depth = Some(int()?),
            "strategy" => o.strategy = Some(text()?.parse().map_err(parsed)?),
            "light_selection" => o.light_selection = Some(text()?.parse().map_err(parsed)?),
            "sampler" => o.sampler = Some(text()?.parse().map_err(parsed)?),
            "width" => o.width = Some(size()?),
            "height" => o.height = Some(size()?),
            other => return Err(PyTypeError::new_err(format!("unknown render override '{other}'"))),
        }
    }
    Ok(o)
}
