//! `Preview`: the library's live preview server (the same page as `glint render --preview`)
//! for Python: a session's renders feed it; the distributed driver publishes its merged
//! film to it. Shown inline in Jupyter (an iframe of the page).

use crate::render::Session;
use glint::preview::{PreviewServer, RenderProgress, WorkerProgress};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use std::sync::Arc;

/// A live preview page served by this process: its `url`; in Jupyter it shows inline.
#[pyclass(module = "glint._glint")]
pub struct Preview {
    pub server: Arc<PreviewServer>,
}

impl Preview {
    pub fn start(address: Option<&str>, title: &str) -> PyResult<Preview> {
        let server = PreviewServer::start(address, title).map_err(|e| PyOSError::new_err(e.to_string()))?;
        Ok(Preview { server: Arc::new(server) })
    }
}

#[pymethods]
impl Preview {
    /// Listens at `address` ("HOST:PORT" or a port; default 127.0.0.1 at a free port).
    #[new]
    #[pyo3(signature = (address=None, title="glint".to_string()))]
    fn new(address: Option<String>, title: String) -> PyResult<Preview> {
        Preview::start(address.as_deref(), &title)
    }

    #[getter]
    fn url(&self) -> String {
        self.server.url()
    }

    fn __repr__(&self) -> String {
        format!("glint.Preview({})", self.server.url())
    }

    fn _repr_html_(&self) -> String {
        let url = self.server.url();
        format!(
            "<iframe src=\"{url}\" width=\"100%\" height=\"640\" style=\"border:0\"></iframe>\
             <div><a href=\"{url}\" target=\"_blank\">{url}</a></div>"
        )
    }

    /// Shows `session`'s film now: `elapsed` seconds since the render began, `mrays` its
    /// rate, `state` "rendering", "done" or "stopped".
    #[pyo3(signature = (session, elapsed=0.0, mrays=0.0, state="rendering"))]
    fn publish(
        &self,
        py: Python<'_>,
        session: PyRef<'_, Session>,
        elapsed: f64,
        mrays: f64,
        state: &str,
    ) -> PyResult<()> {
        let state = match state {
            "rendering" => "rendering",
            "done" => "done",
            "stopped" => "stopped",
            s => return Err(PyValueError::new_err(format!("state: {s:?} is not rendering, done or stopped"))),
        };
        let film = session.film();
        let spp = glint::preview::film_spp(film);
        let progress = RenderProgress {
            spp,
            target_spp: film.spp(),
            passes_done: film.passes_done(),
            pass_count: film.pass_count(),
            elapsed,
            eta: (spp > 0).then(|| elapsed * (film.spp() - spp.min(film.spp())) as f64 / spp as f64),
            mrays_per_second: mrays,
            state,
        };
        let server = &self.server;
        py.detach(|| server.publish(film, &progress));
        Ok(())
    }

    /// The per-worker table of a distributed render: (name, tasks done, tasks in all, status).
    fn set_workers(&self, workers: Vec<(String, u64, u64, String)>) {
        self.server.set_workers(
            workers
                .into_iter()
                .map(|(name, done, total, status)| WorkerProgress { name, done, total, status })
                .collect(),
        );
    }

    /// Whether the page's Stop button was pressed.
    fn stop_requested(&self) -> bool {
        use glint::preview::FilmSink;
        self.server.stop_requested()
    }
}
