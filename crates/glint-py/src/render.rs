//! `Session`: renders a scene pass by pass into a film, with the GIL released, Ctrl-C,
//! a time limit, a progress callback and a thread count.

use crate::convert::{guard, panic_message, scene_error, thread_pool};
use crate::images::{image_array, load_denoiser};
use crate::preview::Preview;
use crate::scene::Scene;
use glint::denoise::with_guides;
use glint::error::SourceLoc;
use glint::io::image_io::ImageFormat;
use glint::preview::{FilmSink, PreviewServer, RenderProgress};
use glint::render::checkpoint::{decode_film, encode_film};
use glint::render::{write_film, Aov, Film, FilmMeta, Rect, RenderStats, Silent};
use glint::session::{
    check_output, layer_names, output_files, read_film_and_job, FilmOptions, Outputs, Overrides, RenderControl,
    RenderJob, RenderReport,
};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// How often the waiting thread takes the GIL to look for Ctrl-C (and maybe call the
/// progress callback): short enough that Ctrl-C feels immediate.
pub(crate) const SIGNAL_POLL: Duration = Duration::from_millis(50);
/// The progress callback is called no more often than this.
const PROGRESS_INTERVAL: Duration = Duration::from_millis(250);

/// Renders a scene pass by pass into a film of `spp` samples per pixel.
#[pyclass(module = "glint._glint")]
pub struct Session {
    scene: Py<Scene>,
    film: Film,
    /// Applied to the scene before each use: another session of it may have set others.
    overrides: Overrides,
    threads: Option<usize>,
    stats: RenderStats,
    /// What checkpoints record beside the sums, for the output named: worked out once, as
    /// it hashes every file of the scene.
    meta: Option<(Option<PathBuf>, FilmMeta)>,
    /// The live preview its renders feed, once asked for.
    preview: Option<Arc<PreviewServer>>,
}

impl Session {
    pub fn film(&self) -> &Film {
        &self.film
    }
}

/// A film's blocks as ((x0, y0, x1, y1), (first pass, end pass)).
type BlockTuple = ((u32, u32, u32, u32), (u32, u32));

fn block_tuples(film: &Film) -> Vec<BlockTuple> {
    film.blocks()
        .iter()
        .map(|b| ((b.region.x0, b.region.y0, b.region.x1, b.region.y1), (b.passes.start, b.passes.end)))
        .collect()
}

/// Set when the render thread is done; the waiting thread sleeps on it.
#[derive(Default)]
pub(crate) struct DoneSignal {
    done: Mutex<bool>,
    cv: Condvar,
}

impl DoneSignal {
    pub(crate) fn set(&self) {
        *self.done.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.cv.notify_all();
    }
    /// Waits up to `t`; true once done.
    pub(crate) fn wait(&self, t: Duration) -> bool {
        let g = self.done.lock().unwrap_or_else(|e| e.into_inner());
        let (g, _) = self.cv.wait_timeout_while(g, t, |d| !*d).unwrap_or_else(|e| e.into_inner());
        *g
    }
}

/// Samples per pixel in the film's leading complete passes.
fn samples_done(film: &Film) -> u32 {
    match film.passes_done() {
        0 => 0,
        n => film.pass_samples(n - 1).end,
    }
}

fn add(total: &mut RenderStats, s: &RenderStats) {
    total.seconds += s.seconds;
    total.camera_rays += s.camera_rays;
    total.rays += s.rays;
    total.shadow_rays += s.shadow_rays;
    total.discarded_samples += s.discarded_samples;
}

#[pymethods]
impl Session {
    /// `region` (x0, y0, x1, y1), x1 and y1 exclusive: the pixels this film holds (default
    /// all), for a render farm's worker. `overrides`: name -> value of the scene settings
    /// this session's renders override (integrator, max_depth, strategy, light_selection,
    /// sampler, width, height). `denoise`: the film keeps the layers that guide the
    /// denoiser (see `outputs`).
    #[new]
    #[pyo3(signature = (scene, spp=None, seed=0, aovs=Vec::new(), threads=None, region=None, overrides=None, denoise=false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: Py<Scene>,
        spp: Option<u32>,
        seed: u64,
        aovs: Vec<String>,
        threads: Option<usize>,
        region: Option<(u32, u32, u32, u32)>,
        overrides: Option<Bound<'_, PyDict>>,
        denoise: bool,
    ) -> PyResult<Session> {
        guard(|| {
            let aovs = aovs
                .iter()
                .map(|a| a.parse::<Aov>().map_err(|e| PyValueError::new_err(format!("aovs: {e}"))))
                .collect::<PyResult<Vec<_>>>()?;
            if threads == Some(0) {
                return Err(PyValueError::new_err("threads: must be at least 1"));
            }
            let mut overrides = crate::overrides::overrides(spp, Some(seed), overrides.as_ref())?;
            let mut s = scene.borrow_mut(py);
            s.session.set_overrides(&overrides).map_err(|e| PyValueError::new_err(e.message))?;
            let region = region.map(|(x0, y0, x1, y1)| Rect { x0, y0, x1, y1 });
            let film = s
                .session
                .new_film(&FilmOptions { pass_spp: None, region, aovs: with_guides(&aovs, denoise) })
                .map_err(|e| PyValueError::new_err(e.message))?;
            drop(s);
            overrides.spp = Some(film.spp());
            Ok(Session { scene, film, overrides, threads, stats: RenderStats::default(), meta: None, preview: None })
        })
    }

    /// Renders `passes` more passes (all that are left by default) from pass `first` (by
    /// default the first the film lacks), stopping early at `time_limit` seconds.
    /// `progress(done_spp, total_spp)` is called from this thread at most four times a
    /// second and once at the end. Returns the passes rendered. Ctrl-C raises
    /// KeyboardInterrupt within a pass's time, keeping the passes done.
    #[pyo3(signature = (passes=None, time_limit=None, progress=None, first=None))]
    fn render_passes(
        &mut self,
        py: Python<'_>,
        passes: Option<u32>,
        time_limit: Option<f64>,
        progress: Option<Py<PyAny>>,
        first: Option<u32>,
    ) -> PyResult<u32> {
        guard(|| self.render_inner(py, passes, time_limit, progress, first))
    }

    /// Serves a live preview of this session's renders (the page `glint render --preview`
    /// serves) at `address` ("HOST:PORT" or a port; default 127.0.0.1 at a free port) and
    /// returns it (its `url`; shown inline in Jupyter). Its Stop button ends a render after
    /// the current pass, keeping the passes done. Called again, returns the same preview.
    #[pyo3(signature = (address=None))]
    fn preview(&mut self, py: Python<'_>, address: Option<String>) -> PyResult<Preview> {
        if let Some(server) = &self.preview {
            return Ok(Preview { server: server.clone() });
        }
        let title = self.scene.borrow(py).title();
        let p = Preview::start(address.as_deref(), &title)?;
        let progress = RenderProgress {
            spp: glint::preview::film_spp(&self.film),
            target_spp: self.film.spp(),
            passes_done: self.film.passes_done(),
            pass_count: self.film.pass_count(),
            state: if self.film.passes_done() == self.film.pass_count() { "done" } else { "rendering" },
            ..Default::default()
        };
        p.server.publish(&self.film, &progress);
        self.preview = Some(p.server.clone());
        Ok(p)
    }

    /// The film as bytes in the checkpoint format (GLINTFLM), with no scene hash or
    /// settings: a block that a render farm's worker sends back.
    fn film_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let bytes = py.detach(|| encode_film(&self.film, &FilmMeta::default()));
        PyBytes::new(py, &bytes)
    }

    /// Adds a film given as bytes (`film_bytes` of a session of the same scene and
    /// settings) to this one; returns its blocks. Films of another size, spp, pass size or
    /// AOVs, and overlapping work, are refused (ValueError), leaving this film as it was.
    fn merge_film(&mut self, py: Python<'_>, data: &[u8]) -> PyResult<Vec<BlockTuple>> {
        guard(|| {
            let film = &mut self.film;
            py.detach(|| {
                let (part, _) = decode_film(data)?;
                film.merge(&part)?;
                Ok(block_tuples(&part))
            })
            .map_err(|e: String| PyValueError::new_err(format!("merge_film: {e}")))
        })
    }

    /// The film's blocks: ((x0, y0, x1, y1), (first pass, end pass)) for each, the pixels
    /// and passes it holds.
    fn blocks(&self) -> Vec<BlockTuple> {
        block_tuples(&self.film)
    }

    /// Writes the film as a checkpoint (atomically) that `glint resume` continues, naming
    /// `output` as the image to write.
    #[pyo3(signature = (path, output=None))]
    fn save_film(&mut self, py: Python<'_>, path: PathBuf, output: Option<PathBuf>) -> PyResult<()> {
        guard(|| {
            let meta = self.meta_for(py, output)?;
            let film = &self.film;
            py.detach(|| write_film(&path, film, &meta)).map_err(PyOSError::new_err)
        })
    }

    /// Adds the checkpoint at `path` to this film; it must be of this scene and these
    /// settings (SceneError otherwise, naming the file). Returns the output it names.
    fn load_film(&mut self, py: Python<'_>, path: PathBuf) -> PyResult<Option<PathBuf>> {
        guard(|| {
            let (film, job, hash) = py.detach(|| read_film_and_job(&path)).map_err(|e| scene_error(py, e))?;
            let mine = self.meta_for(py, None)?;
            let loc = SourceLoc::file(&path);
            let ours = RenderJob::from_json(&mine.settings).map_err(|e| scene_error(py, e))?;
            if hash != mine.scene_hash {
                let e = "the scene or a file it reads has changed since this film was written";
                return Err(scene_error(py, glint::Error::at(&loc, e)));
            }
            if !job.same_render(&ours) {
                let e = "the film was rendered with other settings (spp, seed, size, AOVs or scene edits)";
                return Err(scene_error(py, glint::Error::at(&loc, e)));
            }
            self.film.merge(&film).map_err(|e| scene_error(py, glint::Error::at(&loc, e)))?;
            Ok(job.output)
        })
    }

    /// The image so far: float32 (height, width, 3), linear RGB.
    fn image<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        image_array(py, &self.film.image())
    }

    /// What a render of this film writes: the image and its layers (name -> float32
    /// (height, width, channels)), the image denoised if asked (the image as rendered is
    /// then the layer `noisy`, first), as the command line writes them.
    #[pyo3(signature = (denoise=false))]
    fn outputs<'py>(
        &self,
        py: Python<'py>,
        denoise: bool,
    ) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyDict>)> {
        guard(|| {
            let film = &self.film;
            let mut outputs = py.detach(|| Outputs::of_film(film));
            if denoise {
                let denoiser = load_denoiser(py)?;
                outputs = py.detach(|| outputs.denoised(&denoiser)).map_err(|e| PyRuntimeError::new_err(e.message))?;
            }
            let d = PyDict::new(py);
            for l in outputs.layers {
                let arr = Array3::from_shape_vec((l.height, l.width, l.channels.len()), l.data)
                    .expect("a layer fills the image");
                d.set_item(l.name, arr.into_pyarray(py))?;
            }
            Ok((image_array(py, &outputs.image), d))
        })
    }

    /// Checks, before any sample is taken, that the outputs of this film written to `path`
    /// (the image and, unless it is EXR, a PNG per layer) can be: a known format, an
    /// existing writable folder, none of them a file of the scene.
    #[pyo3(signature = (path, denoise=false))]
    fn check_outputs(&self, py: Python<'_>, path: PathBuf, denoise: bool) -> PyResult<()> {
        guard(|| {
            ImageFormat::from_path(&path).map_err(PyValueError::new_err)?;
            let scene = self.scene.borrow(py);
            for out in output_files(&path, &layer_names(self.film.aovs(), denoise)) {
                check_output(&out, scene.session.description()).map_err(|e| scene_error(py, e))?;
            }
            Ok(())
        })
    }

    /// The AOV layers so far: name -> float32 (height, width, channels).
    fn aovs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for a in self.film.aovs() {
            if let Some(img) = self.film.aov(*a) {
                let c = img.channels.len();
                let arr =
                    Array3::from_shape_vec((img.height, img.width, c), img.data).expect("a layer fills the image");
                d.set_item(img.name, arr.into_pyarray(py))?;
            }
        }
        Ok(d)
    }

    /// Channel names of each AOV layer, as an EXR file names them.
    fn aov_channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for a in self.film.aovs() {
            d.set_item(a.name(), a.channels())?;
        }
        Ok(d)
    }

    /// Samples per pixel rendered so far.
    #[getter]
    fn spp(&self) -> u32 {
        samples_done(&self.film)
    }

    /// Samples per pixel of the finished film.
    #[getter]
    fn target_spp(&self) -> u32 {
        self.film.spp()
    }

    /// Image width in pixels (the scene's, or the override's).
    #[getter]
    fn width(&self) -> u32 {
        self.film.width()
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.film.height()
    }

    #[getter]
    fn passes_done(&self) -> u32 {
        self.film.passes_done()
    }

    #[getter]
    fn pass_count(&self) -> u32 {
        self.film.pass_count()
    }

    /// The scene rendered.
    #[getter]
    fn scene(&self, py: Python<'_>) -> Py<Scene> {
        self.scene.clone_ref(py)
    }

    /// Rays and seconds of this session's renders so far, and the scene's build counters.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.stats;
        let d = self.scene.borrow(py).build_counters(py)?;
        d.set_item("seconds", s.seconds)?;
        d.set_item("camera_rays", s.camera_rays)?;
        d.set_item("rays", s.rays)?;
        d.set_item("shadow_rays", s.shadow_rays)?;
        d.set_item("discarded_samples", s.discarded_samples)?;
        Ok(d)
    }
}

impl Session {
    /// The checkpoint metadata for `output`, with this session's sampling in the job.
    fn meta_for(&mut self, py: Python<'_>, output: Option<PathBuf>) -> PyResult<FilmMeta> {
        if let Some((o, m)) = &self.meta {
            if *o == output {
                return Ok(m.clone());
            }
        }
        let mut scene = self.scene.try_borrow_mut(py)?;
        scene.session.set_overrides(&self.overrides).map_err(|e| scene_error(py, e))?;
        let (session, film) = (&scene.session, &self.film);
        let meta = py.detach(|| session.film_meta(film, output.as_deref())).map_err(|e| scene_error(py, e))?;
        self.meta = Some((output, meta.clone()));
        Ok(meta)
    }

    fn render_inner(
        &mut self,
        py: Python<'_>,
        passes: Option<u32>,
        time_limit: Option<f64>,
        progress: Option<Py<PyAny>>,
        first: Option<u32>,
    ) -> PyResult<u32> {
        let time_limit = match time_limit {
            Some(t) if !(t >= 0.0 && t.is_finite()) => {
                return Err(PyValueError::new_err(format!("time_limit: {t} is not a number of seconds")))
            }
            t => t.map(Duration::from_secs_f64),
        };
        let first = first.unwrap_or(self.film.passes_done());
        if first > self.film.pass_count() {
            return Err(PyValueError::new_err(format!("first: pass {first} of {}", self.film.pass_count())));
        }
        let end = match passes {
            Some(n) => first.saturating_add(n).min(self.film.pass_count()),
            None => self.film.pass_count(),
        };
        let pool = thread_pool(self.threads)?;
        let mut scene = self.scene.try_borrow_mut(py)?;
        // Another session of this scene may have set other overrides.
        scene.session.set_overrides(&self.overrides).map_err(|e| scene_error(py, e))?;
        let session = &mut scene.session;
        let film = &mut self.film;
        if let Some(p) = &self.preview {
            p.clear_stop();
        }
        let sinks: Vec<&dyn FilmSink> = self.preview.iter().map(|p| p.as_ref() as &dyn FilmSink).collect();
        let total = film.spp();
        let cancel = AtomicBool::new(false);
        let done_spp = AtomicU32::new(samples_done(film));
        let signal = DoneSignal::default();

        let mut interrupt: Option<PyErr> = None;
        let outcome = std::thread::scope(|s| {
            let worker = s.spawn(|| {
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    let control = RenderControl {
                        passes: Some(first..end),
                        time_limit,
                        sinks: &sinks,
                        ..RenderControl::new(&cancel, &Silent)
                    };
                    let mut work = || {
                        session.render(film, &control, &mut |f: &Film| {
                            done_spp.store(samples_done(f), Ordering::Relaxed);
                            Ok(())
                        })
                    };
                    match &pool {
                        Some(p) => p.install(work),
                        None => work(),
                    }
                }));
                signal.set();
                r
            });
            // This thread waits without the GIL, taking it briefly to run Python's signal
            // handlers (Ctrl-C) and the progress callback.
            let mut last_progress = Instant::now();
            while !py.detach(|| signal.wait(SIGNAL_POLL)) {
                if let Err(e) = py.check_signals() {
                    cancel.store(true, Ordering::Relaxed);
                    interrupt = Some(e);
                    break;
                }
                if let Some(cb) = &progress {
                    if last_progress.elapsed() >= PROGRESS_INTERVAL {
                        last_progress = Instant::now();
                        if let Err(e) = cb.call1(py, (done_spp.load(Ordering::Relaxed), total)) {
                            cancel.store(true, Ordering::Relaxed);
                            interrupt = Some(e);
                            break;
                        }
                    }
                }
            }
            py.detach(|| worker.join())
        });
        drop(scene);
        let report: RenderReport = match outcome {
            Ok(Ok(Ok(r))) => r,
            Ok(Ok(Err(e))) => return Err(scene_error(py, e)),
            Ok(Err(p)) | Err(p) => {
                return Err(PyRuntimeError::new_err(format!("glint: internal error: {}", panic_message(p))))
            }
        };
        add(&mut self.stats, &report.stats);
        if let Some(p) = self.preview.as_ref().filter(|p| p.watchers() == 0) {
            // A notebook's page opened after the render shows where it ended.
            let progress = glint::preview::RenderProgress {
                spp: glint::preview::film_spp(&self.film),
                target_spp: self.film.spp(),
                passes_done: self.film.passes_done(),
                pass_count: self.film.pass_count(),
                elapsed: report.stats.seconds,
                mrays_per_second: report.stats.mrays_per_second(),
                state: if report.stopped_by_viewer { "stopped" } else { "done" },
                ..Default::default()
            };
            let film = &self.film;
            py.detach(|| p.publish(film, &progress));
        }
        if let Some(e) = interrupt {
            return Err(e);
        }
        if let Some(cb) = &progress {
            cb.call1(py, (samples_done(&self.film), total))?;
        }
        Ok(report.passes.end - report.passes.start)
    }
}
