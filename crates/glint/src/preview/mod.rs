//! Live views of a render in progress: sinks the session feeds after each pass. The browser
//! preview ([`PreviewServer`]: a small HTTP server in the process, one page, updates pushed
//! as server-sent events) and tev's TCP protocol ([`TevSink`]) are the two kinds.
//!
//! A sink only reads the film; the image is the same bits with or without one. Copying the
//! film out costs time on the render thread, so each sink keeps within a budget of the
//! render's time ([`Budget`]) and sends nothing while no one watches.

mod http;
mod server;
mod snapshot;
mod tev;

pub use server::{PreviewServer, WorkerProgress};
pub use snapshot::{Layer, LayerKind, Snapshot, ToneMap, View};
pub use tev::TevSink;

use crate::render::Film;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How far a render has come, as the page and the progress bar show it.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct RenderProgress {
    /// Samples per pixel the film holds (over its region).
    pub spp: u32,
    pub target_spp: u32,
    pub passes_done: u32,
    pub pass_count: u32,
    /// Seconds since this render (call) began.
    pub elapsed: f64,
    /// Seconds left at the rate so far (None before the first pass).
    pub eta: Option<f64>,
    pub mrays_per_second: f64,
    /// "rendering", "done" or "stopped".
    pub state: &'static str,
}

/// Something fed the film as passes land (a live view). Implementations must be quick: they
/// run on the render's thread between passes.
pub trait FilmSink: Send + Sync {
    /// When a render call begins, before its first pass.
    fn started(&self, _film: &Film) {}
    /// After each pass.
    fn pass_done(&self, film: &Film, progress: &RenderProgress);
    /// Once, when the render call ends (finished, stopped or timed out).
    fn finished(&self, film: &Film, progress: &RenderProgress) {
        self.pass_done(film, progress);
    }
    /// Whether the viewer asked the render to stop (the Stop button): the session then stops
    /// after the current pass, as after Ctrl-C.
    fn stop_requested(&self) -> bool {
        false
    }
}

/// The samples per pixel a film holds (over its region, for the passes it has).
pub fn film_spp(film: &Film) -> u32 {
    let mut passes: Vec<u32> = film.blocks().iter().flat_map(|b| b.passes.clone()).collect();
    passes.sort_unstable();
    passes.dedup();
    passes.iter().map(|&p| film.pass_samples(p).len() as u32).sum()
}

/// The share of the render's time a live view may take: copying the film and encoding it
/// are done only while the time they took so far stays under this fraction of the time
/// since the render began (BENCHMARKS.md, "Live preview", measures the cost).
pub const PREVIEW_TIME_SHARE: f64 = 0.01;

/// The least time between two updates (a faster page only costs more).
pub const MIN_UPDATE_INTERVAL: Duration = Duration::from_millis(100);

/// Keeps a live view's work within [`PREVIEW_TIME_SHARE`] of the elapsed time.
pub struct Budget {
    inner: Mutex<BudgetState>,
}

struct BudgetState {
    start: Instant,
    spent: Duration,
    last: Option<Instant>,
}

impl Default for Budget {
    fn default() -> Self {
        Budget { inner: Mutex::new(BudgetState { start: Instant::now(), spent: Duration::ZERO, last: None }) }
    }
}

impl Budget {
    /// True when an update may be made now.
    pub fn allows(&self) -> bool {
        let s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        let now = Instant::now();
        if s.last.is_some_and(|l| now - l < MIN_UPDATE_INTERVAL) {
            return false;
        }
        s.spent.as_secs_f64() <= PREVIEW_TIME_SHARE * (now - s.start).as_secs_f64()
    }

    /// Counts work done for the view (on whichever thread).
    pub fn spend(&self, t: Duration) {
        let mut s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        s.spent += t;
        s.last = Some(Instant::now());
    }

    /// The time spent on the view since the clock started.
    pub fn spent(&self) -> Duration {
        self.inner.lock().unwrap_or_else(|e| e.into_inner()).spent
    }

    /// Starts the clock again (a new render call on the same view).
    pub fn restart(&self) {
        let mut s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        *s = BudgetState { start: Instant::now(), spent: Duration::ZERO, last: None };
    }
}
