//! The progress bar on stderr: elapsed time, samples per pixel reached, ETA and Mrays/s.

use glint::render::Progress;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

pub struct ProgressBar {
    bar: Option<indicatif::ProgressBar>,
    rays: AtomicU64,
    start: Instant,
}

impl ProgressBar {
    /// A bar over `total` units of work (pixel samples), shown only when `show`.
    pub fn new(total: u64, show: bool) -> ProgressBar {
        let bar = show.then(|| {
            let b = indicatif::ProgressBar::new(total);
            b.set_style(
                indicatif::ProgressStyle::with_template("{elapsed_precise} {bar:40} {percent:>3}% ETA {eta:>4} {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        ProgressBar { bar, rays: AtomicU64::new(0), start: Instant::now() }
    }

    /// Says how many samples per pixel the film holds.
    pub fn set_spp(&self, spp: u32, target: u32) {
        if let Some(b) = &self.bar {
            let mrays = self.rays.load(Ordering::Relaxed) as f64 / self.start.elapsed().as_secs_f64().max(1e-9) / 1e6;
            b.set_message(format!("{spp}/{target} spp, {mrays:.1} Mrays/s"));
        }
    }

    /// Prints a line on stderr above the bar (or just the line, with no bar).
    pub fn println(&self, line: &str) {
        match &self.bar {
            Some(b) => b.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Progress for ProgressBar {
    fn advance(&self, work: u64, rays: u64) {
        self.rays.fetch_add(rays, Ordering::Relaxed);
        if let Some(b) = &self.bar {
            b.inc(work);
        }
    }
}
