//! Scheduling: each pass is cut into bands of rows (rendered tile by tile) that rayon renders
//! in parallel, straight into a [`Film`]. Every camera sample draws its random numbers from a
//! generator keyed by (seed, pixel, sample index), and the film's sums are exact (fixed
//! point), so the image is bit-identical whatever the number of threads, passes, regions or
//! merges.

mod aov;
pub mod checkpoint;
pub mod film;
mod passes;
pub mod splat;

pub use crate::sampling::PixelFilter;
pub use aov::{Aov, AovImage};
pub use checkpoint::{content_hash, read_film, write_film, ContentHash, FilmMeta};
pub use film::{Block, Film, PixelSums, Rect};
pub(crate) use passes::camera_sample;
pub use passes::{relative_error, render_passes, Adaptive, PassOutcome, PassRequest};

use crate::integrators::{Integrator, PathShading};
use crate::io::Image;
use crate::sampling::SamplerKind;
use crate::world::{BatchTraversal, World};
use std::sync::atomic::AtomicBool;

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub spp: u32,
    pub seed: u64,
    pub filter: PixelFilter,
    pub sampler: SamplerKind,
    /// Also return the per-pixel variance of the mean (for statistical tests).
    pub variance: bool,
    pub tile_size: usize,
    /// How paths are scheduled; the image is the same bits under every schedule.
    pub schedule: Schedule,
}

/// How a thread schedules its camera samples' paths. The integrators' answers are the same
/// bits under every schedule, so this trades only speed (BENCHMARKS.md, "Many paths in flight").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Schedule {
    /// Each path traced to its end before the next starts (the reference the tests compare
    /// the others against).
    OnePath,
    /// Up to [`WAVEFRONT_PATHS`] paths of a tile advanced together, a bounce at a time, each
    /// batch of rays traced through the single-ray kernels (only the path tracer batches;
    /// other integrators run one path at a time).
    Wavefront,
    /// As `Wavefront`, the batches traced by the interleaved batch traversal (several rays in
    /// flight per thread): 3 to 5% slower than `Wavefront` on Zen 5 (BENCHMARKS.md).
    WavefrontInterleaved,
    /// As `Wavefront`, the shadow rays and the camera rays' closest hits traced in packets
    /// (8 or 16 rays per instruction, `accel::packet`): 1.07 to 1.36x the single rays'
    /// occlusion on the bunny and dragon ray sets, 0.8 to 0.9x on the room, about even in
    /// renders (BENCHMARKS.md), so not the default.
    WavefrontPackets,
    /// As `WavefrontPackets`, the path tracer's vertices of the common BSDFs (Lambertian,
    /// conductors, dielectrics, plastics, principled) shaded 8 or 16 paths per instruction
    /// (`integrators::vertex_lanes`; the other BSDFs one path at a time). The default: the
    /// fastest measured (BENCHMARKS.md, "The vertex in SIMD lanes").
    #[default]
    WavefrontSimd,
}

impl Schedule {
    /// Every schedule (the tests render each and compare the bits).
    pub const ALL: [Schedule; 5] = [
        Schedule::OnePath,
        Schedule::Wavefront,
        Schedule::WavefrontInterleaved,
        Schedule::WavefrontPackets,
        Schedule::WavefrontSimd,
    ];

    /// How the wavefront schedules trace their batches (`None`: one path at a time).
    pub fn batch_traversal(self) -> Option<BatchTraversal> {
        match self {
            Schedule::OnePath => None,
            Schedule::Wavefront => Some(BatchTraversal::OneByOne),
            Schedule::WavefrontInterleaved => Some(BatchTraversal::Interleaved),
            Schedule::WavefrontPackets | Schedule::WavefrontSimd => Some(BatchTraversal::Packets),
        }
    }

    /// How the wavefront schedules step their paths.
    pub fn path_shading(self) -> PathShading {
        match self {
            Schedule::WavefrontSimd => PathShading::Lanes,
            Schedule::OnePath | Schedule::Wavefront | Schedule::WavefrontInterleaved | Schedule::WavefrontPackets => {
                PathShading::OneByOne
            }
        }
    }

    /// The name on the command line and in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Schedule::OnePath => "one-path",
            Schedule::Wavefront => "wavefront",
            Schedule::WavefrontInterleaved => "wavefront-interleaved",
            Schedule::WavefrontPackets => "wavefront-packets",
            Schedule::WavefrontSimd => "wavefront-simd",
        }
    }
}

impl std::str::FromStr for Schedule {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Schedule::ALL.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Schedule::ALL.iter().map(|k| k.name()).collect();
            format!("unknown schedule '{s}' (expected {})", names.join(", "))
        })
    }
}

/// Paths a thread advances together under [`Schedule::Wavefront`]: enough to keep the batch
/// traversal's lanes busy until the last bounces, few enough that their state stays in L2.
pub const WAVEFRONT_PATHS: usize = 1024;

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            seed: 0,
            filter: PixelFilter::Box,
            sampler: SamplerKind::Sobol,
            variance: false,
            tile_size: 16,
            schedule: Schedule::WavefrontSimd,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    pub seconds: f64,
    pub camera_rays: u64,
    pub rays: u64,
    pub shadow_rays: u64,
    /// Samples whose radiance was NaN or infinite and were dropped (counted as black).
    pub discarded_samples: u64,
}

impl RenderStats {
    pub fn mrays_per_second(&self) -> f64 {
        (self.rays + self.shadow_rays) as f64 / self.seconds.max(1e-9) / 1e6
    }
}

pub struct RenderOutput {
    pub image: Image,
    /// Variance of each pixel's mean estimate, when requested.
    pub variance: Option<Image>,
    pub stats: RenderStats,
}

/// Told about progress as tiles finish; implementations must be cheap and thread-safe.
pub trait Progress: Sync {
    fn advance(&self, _pixels: u64, _rays: u64) {}
}

/// No progress reporting.
pub struct Silent;
impl Progress for Silent {}

/// Renders every sample of every pixel in one call: one pass of `settings.spp` samples
/// into a film over the whole image (see [`render_passes`] for passes, regions and
/// cancelling).
pub fn render(
    scene: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> RenderOutput {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let spp = settings.spp.max(1);
    let mut film = Film::with_filter(w, h, Rect::full(w, h), spp, spp, &[], settings.filter)
        .expect("the camera has a valid resolution and the filter a validated radius");
    let request = PassRequest { passes: 0..1, adaptive: None };
    let outcome = render_passes(scene, integrator, settings, &mut film, &request, &AtomicBool::new(false), progress)
        .expect("a new film takes its first pass");
    RenderOutput {
        image: film.image(),
        variance: settings.variance.then(|| film.variance_image()),
        stats: outcome.stats,
    }
}
