//! Rendering passes into a [`Film`]: tiles in parallel, per-pixel sums within a tile, then
//! added to the film. A cancel flag is checked between tiles; a cancelled pass is dropped
//! whole, so a film only ever holds whole passes.

use super::film::{to_fixed, Block, Film, PixelSums, Rect, TileSums};
use super::{Aov, Progress, RenderSettings, RenderStats};
use crate::integrators::{closest_hit_cost, first_hit, Counters, Integrator};
use crate::math::Rgb;
use crate::sampling::Sampler;
use crate::world::World;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Adaptive sampling: a pixel stops taking samples once the relative standard error of its
/// mean is under `threshold` and it has had at least `min_passes` passes. The decision
/// reads only that pixel's sums, so regions and threads still give the same bits; films
/// split by pass ranges do not (the later range cannot see the earlier one's sums).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Adaptive {
    pub threshold: f32,
    pub min_passes: u32,
}

/// Mean luminance below which a pixel counts as this bright when judging relative error
/// (a black pixel with no variance is converged; a dark noisy one is not).
const ADAPTIVE_MIN_LUMINANCE: f64 = 1e-3;

/// Which passes to render.
#[derive(Clone, Debug, PartialEq)]
pub struct PassRequest {
    pub passes: Range<u32>,
    pub adaptive: Option<Adaptive>,
}

#[derive(Clone, Debug)]
pub struct PassOutcome {
    /// Passes now in the film (a prefix of the request; shorter when cancelled).
    pub passes_rendered: Range<u32>,
    pub cancelled: bool,
    pub stats: RenderStats,
}

/// Renders `request.passes` over the film's whole region, one pass after another.
/// `settings.spp` is ignored (the film knows its spp); seed, sampler, filter and tile size
/// are used. Errors when the passes are outside the film or already in it.
pub fn render_passes(
    scene: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
    film: &mut Film,
    request: &PassRequest,
    cancel: &AtomicBool,
    progress: &dyn Progress,
) -> Result<PassOutcome, String> {
    let start = Instant::now();
    if (film.width(), film.height()) != (scene.camera.width, scene.camera.height) {
        return Err(format!(
            "film is {}x{} but the camera renders {}x{}",
            film.width(),
            film.height(),
            scene.camera.width,
            scene.camera.height
        ));
    }
    if !request.passes.is_empty() {
        film.check_free(&Block { region: film.region(), passes: request.passes.clone() })?;
    }
    let mut stats = RenderStats::default();
    let mut done = request.passes.start..request.passes.start;
    for pass in request.passes.clone() {
        let Some(tiles) = render_pass(scene, integrator, settings, film, pass, cancel, progress, &mut stats) else {
            stats.seconds = start.elapsed().as_secs_f64();
            return Ok(PassOutcome { passes_rendered: done, cancelled: true, stats });
        };
        for t in &tiles {
            film.add_tile(t);
        }
        film.record_block(Block { region: film.region(), passes: pass..pass + 1 })?;
        if let Some(a) = &request.adaptive {
            mark_converged(film, a);
        }
        done.end = pass + 1;
    }
    stats.seconds = start.elapsed().as_secs_f64();
    Ok(PassOutcome { passes_rendered: done, cancelled: false, stats })
}

/// Tiles of the region, row-major.
fn tiles(region: Rect, size: u32) -> Vec<Rect> {
    let size = size.max(1);
    let mut out = Vec::new();
    let mut y0 = region.y0;
    while y0 < region.y1 {
        let y1 = (y0 + size).min(region.y1);
        let mut x0 = region.x0;
        while x0 < region.x1 {
            let x1 = (x0 + size).min(region.x1);
            out.push(Rect { x0, y0, x1, y1 });
            x0 = x1;
        }
        y0 = y1;
    }
    out
}

/// One pass: the tiles' sums, or `None` when cancelled.
#[allow(clippy::too_many_arguments)]
fn render_pass(
    scene: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
    film: &Film,
    pass: u32,
    cancel: &AtomicBool,
    progress: &dyn Progress,
    stats: &mut RenderStats,
) -> Option<Vec<TileSums>> {
    let samples = film.pass_samples(pass);
    let tile_size = settings.tile_size.clamp(1, u32::MAX as usize) as u32;
    let results: Vec<Option<(TileSums, TileCounts)>> = tiles(film.region(), tile_size)
        .par_iter()
        .map(|&rect| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            Some(render_tile(scene, integrator, settings, film, rect, samples.clone(), progress))
        })
        .collect();
    let mut out = Vec::with_capacity(results.len());
    let mut pass_counts = TileCounts::default();
    for r in results {
        let (sums, counts) = r?;
        pass_counts.add(&counts);
        out.push(sums);
    }
    if cancel.load(Ordering::Relaxed) {
        return None;
    }
    stats.camera_rays += pass_counts.camera_rays;
    stats.rays += pass_counts.counters.rays;
    stats.shadow_rays += pass_counts.counters.shadow_rays;
    stats.discarded_samples += pass_counts.discarded;
    Some(out)
}

#[derive(Default)]
struct TileCounts {
    counters: Counters,
    camera_rays: u64,
    discarded: u64,
}

impl TileCounts {
    fn add(&mut self, o: &TileCounts) {
        self.counters.rays += o.counters.rays;
        self.counters.shadow_rays += o.counters.shadow_rays;
        self.camera_rays += o.camera_rays;
        self.discarded += o.discarded;
    }
}

fn render_tile(
    scene: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
    film: &Film,
    rect: Rect,
    samples: Range<u32>,
    progress: &dyn Progress,
) -> (TileSums, TileCounts) {
    let n = rect.area() as usize;
    let stride = film.aov_stride();
    let mut tile = TileSums { rect, pixels: vec![PixelSums::default(); n], aov_sums: vec![0; n * stride] };
    let mut counts = TileCounts::default();
    let layers: Vec<(Aov, usize)> =
        film.aovs().iter().filter_map(|&a| film.aov_offset(a).map(|off| (a, off))).collect();
    let wants_first_hit = layers.iter().any(|(a, _)| *a != Aov::BvhCost);
    let width = scene.camera.width as u64;
    let mut i = 0;
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            if film.is_converged(x, y) {
                i += 1;
                continue;
            }
            let pixel = y as u64 * width + x as u64;
            let sums = &mut tile.pixels[i];
            let aov_sums = &mut tile.aov_sums[i * stride..(i + 1) * stride];
            for s in samples.clone() {
                let mut rng = Sampler::new(settings.sampler, settings.seed, pixel, s);
                let off = settings.filter.sample(rng.next_2d());
                let lens = rng.next_2d();
                let ray = scene.camera.generate_ray(x as f32 + 0.5 + off[0], y as f32 + 0.5 + off[1], lens);
                let mut l = integrator.li(scene, &ray, &mut rng, &mut counts.counters);
                if !l.is_finite() || l.r < 0.0 || l.g < 0.0 || l.b < 0.0 {
                    counts.discarded += 1;
                    l = Rgb::BLACK;
                }
                sums.add_sample(l);
                counts.camera_rays += 1;
                if layers.is_empty() {
                    continue;
                }
                let hit = if wants_first_hit { first_hit(scene, &ray) } else { crate::integrators::FirstHit::NONE };
                for &(aov, off) in &layers {
                    let values: [f32; 3] = match aov {
                        Aov::Albedo => hit.albedo.to_array(),
                        Aov::Normal => hit.normal.to_array(),
                        Aov::Position => hit.position.to_array(),
                        Aov::Depth => [hit.depth, 0.0, 0.0],
                        Aov::BvhCost => [closest_hit_cost(scene, &ray) as f32, 0.0, 0.0],
                        Aov::Variance | Aov::Spp => continue,
                    };
                    for c in 0..aov.stored_channels() {
                        aov_sums[off + c] = aov_sums[off + c].saturating_add(to_fixed(values[c] as f64));
                    }
                }
            }
            i += 1;
        }
    }
    progress.advance(n as u64, counts.counters.rays + counts.counters.shadow_rays);
    (tile, counts)
}

/// After a pass, stops the pixels whose mean is known well enough.
fn mark_converged(film: &mut Film, adaptive: &Adaptive) {
    let min_samples = film.pass_samples(adaptive.min_passes.saturating_sub(1)).end as u64;
    let stop: Vec<usize> = film
        .region_sums()
        .iter()
        .zip(film.converged_flags())
        .enumerate()
        .filter(|(_, (s, &c))| !c && s.count >= min_samples && relative_error(s) < adaptive.threshold as f64)
        .map(|(i, _)| i)
        .collect();
    for i in stop {
        film.set_converged(i);
    }
}

/// Standard error of the mean (of the noisiest channel) relative to the mean luminance.
pub fn relative_error(s: &PixelSums) -> f64 {
    let m = s.mean();
    let luminance = 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2];
    let var = s.variance_of_mean().into_iter().fold(0.0, f64::max);
    var.sqrt() / luminance.max(ADAPTIVE_MIN_LUMINANCE)
}
