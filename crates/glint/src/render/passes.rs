//! Rendering passes into a [`Film`]: bands of rows in parallel, each added straight into the
//! film's sums. A cancel flag is checked between passes, so a film only ever holds whole
//! passes; with passes of one sample (the default) a cancel takes effect within one pass.

use super::film::{to_fixed, Block, Film, PixelSums, Rect};
use super::splat::{splat_margin, SplatBuffer};
use super::{Aov, Progress, RenderSettings, RenderStats, WAVEFRONT_PATHS};
use crate::integrators::{closest_hit_cost, first_hit, CameraSample, Counters, Integrator};
use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::world::{BatchTraversal, World};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
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
    if settings.filter != film.filter() {
        return Err(format!(
            "the film was made for the {:?} filter but the render uses {:?}",
            film.filter(),
            settings.filter
        ));
    }
    if !request.passes.is_empty() {
        film.check_free(&Block { region: film.region(), passes: request.passes.clone() })?;
    }
    let mut stats = RenderStats::default();
    let mut done = request.passes.start..request.passes.start;
    for pass in request.passes.clone() {
        // Checked between passes only: a pass, once started, is added whole.
        if cancel.load(Ordering::Relaxed) {
            stats.seconds = start.elapsed().as_secs_f64();
            return Ok(PassOutcome { passes_rendered: done, cancelled: true, stats });
        }
        let counts = render_pass(scene, integrator, settings, film, pass, progress);
        stats.camera_rays += counts.camera_rays;
        stats.rays += counts.counters.rays;
        stats.shadow_rays += counts.counters.shadow_rays;
        stats.discarded_samples += counts.discarded;
        film.record_block(Block { region: film.region(), passes: pass..pass + 1 })?;
        if let Some(a) = &request.adaptive {
            mark_converged(film, a);
        }
        done.end = pass + 1;
    }
    stats.seconds = start.elapsed().as_secs_f64();
    Ok(PassOutcome { passes_rendered: done, cancelled: false, stats })
}

/// One pass, added straight into the film: the region is cut into bands of `tile_size`
/// rows that threads take in parallel (each owns its rows of the film's sums), and each band
/// is rendered tile by tile for locality. The sums are exact, so the order does not matter.
fn render_pass(
    scene: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
    film: &mut Film,
    pass: u32,
    progress: &dyn Progress,
) -> TileCounts {
    let samples = film.pass_samples(pass);
    let tile = settings.tile_size.clamp(1, u32::MAX as usize) as u32;
    let region = film.region();
    let stride = film.aov_stride();
    let layers: Vec<(Aov, usize)> =
        film.aovs().iter().filter_map(|&a| film.aov_offset(a).map(|off| (a, off))).collect();
    let band_pixels = (tile * region.width()) as usize;
    let filter = film.filter();
    let sums = film.sums_mut();
    let (pixels, aov_sums, converged) = (sums.pixels, sums.aov_sums, sums.converged);
    // Bands splat into buffers of their own, added into the film's under this lock as each
    // band ends: the sums are exact, so the order bands finish in does not matter.
    let splat = sums.splat.map(Mutex::new);
    let bands = pixels.len().div_ceil(band_pixels);
    let aov_bands: Vec<&mut [i128]> = if stride == 0 {
        (0..bands).map(|_| <&mut [i128]>::default()).collect()
    } else {
        aov_sums.chunks_mut(band_pixels * stride).collect()
    };
    let wants_first_hit = layers.iter().any(|(a, _)| *a != Aov::BvhCost);
    let job = PassJob {
        scene,
        integrator,
        settings,
        region,
        tile,
        samples,
        layers: &layers,
        wants_first_hit,
        stride,
        progress,
        splat: splat.as_ref(),
        filter,
    };
    pixels
        .par_chunks_mut(band_pixels)
        .zip(aov_bands.into_par_iter())
        .zip(converged.par_chunks(band_pixels))
        .enumerate()
        .map(|(b, ((px, aov), done))| job.band(region.y0 + b as u32 * tile, px, aov, done))
        .reduce(TileCounts::default, |mut a, b| {
            a.add(&b);
            a
        })
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

/// What every band of a pass shares.
struct PassJob<'a> {
    scene: &'a World,
    integrator: &'a Integrator,
    settings: &'a RenderSettings,
    region: Rect,
    tile: u32,
    samples: Range<u32>,
    layers: &'a [(Aov, usize)],
    /// Some layer needs the camera ray's first hit (every one but bvh-cost).
    wants_first_hit: bool,
    stride: usize,
    progress: &'a dyn Progress,
    /// The film's splat sums, when its filter splats.
    splat: Option<&'a Mutex<&'a mut SplatBuffer>>,
    filter: crate::sampling::PixelFilter,
}

impl PassJob<'_> {
    /// Renders the band of rows starting at `y0` into its slices of the film.
    fn band(&self, y0: u32, pixels: &mut [PixelSums], aov_sums: &mut [i128], converged: &[bool]) -> TileCounts {
        let w = self.region.width();
        let y1 = (y0 + self.tile).min(self.region.y1);
        let mut counts = TileCounts::default();
        let mut band_splat = self.splat.map(|film_splat| {
            let film_rect = film_splat.lock().unwrap_or_else(|e| e.into_inner()).rect;
            let m = splat_margin(&self.filter);
            SplatBuffer::new(Rect {
                x0: film_rect.x0,
                x1: film_rect.x1,
                y0: y0.saturating_sub(m).max(film_rect.y0),
                y1: y1.saturating_add(m).min(film_rect.y1),
            })
        });
        let mut wave = Wave::default();
        let mut x0 = self.region.x0;
        while x0 < self.region.x1 {
            let x1 = (x0 + self.tile).min(self.region.x1);
            let rays_before = counts.counters.rays + counts.counters.shadow_rays;
            for y in y0..y1 {
                for x in x0..x1 {
                    let i = ((y - y0) * w + (x - self.region.x0)) as usize;
                    if converged[i] {
                        continue;
                    }
                    for s in self.samples.clone() {
                        let (origin, camera) = self.camera_sample(x, y, s);
                        match self.settings.schedule.batch_traversal() {
                            None => {
                                let mut cs = camera;
                                let l = self.integrator.li(self.scene, &cs.ray, &mut cs.sampler, &mut counts.counters);
                                let aov = &mut aov_sums[i * self.stride..(i + 1) * self.stride];
                                self.record(&origin, &cs.ray, l, &mut pixels[i], aov, band_splat.as_mut(), &mut counts);
                            }
                            Some(_) => {
                                wave.origins.push(SampleOrigin { index: i, ..origin });
                                wave.cameras.push(camera);
                                if wave.cameras.len() >= WAVEFRONT_PATHS {
                                    self.flush(&mut wave, pixels, aov_sums, band_splat.as_mut(), &mut counts);
                                }
                            }
                        }
                    }
                }
            }
            self.flush(&mut wave, pixels, aov_sums, band_splat.as_mut(), &mut counts);
            let rays = counts.counters.rays + counts.counters.shadow_rays - rays_before;
            self.progress.advance(((x1 - x0) * (y1 - y0)) as u64, rays);
            x0 = x1;
        }
        if let (Some(film_splat), Some(band_splat)) = (self.splat, &band_splat) {
            film_splat.lock().unwrap_or_else(|e| e.into_inner()).add(band_splat);
        }
        counts
    }

    /// The camera ray of sample `s` of pixel (x, y), and its sampler for the integrator.
    fn camera_sample(&self, x: u32, y: u32, s: u32) -> (SampleOrigin, CameraSample) {
        let ([px, py], camera) = camera_sample(self.scene, self.settings, x, y, s);
        (SampleOrigin { index: 0, px, py }, camera)
    }

    /// Traces the wave's paths together and records them in the order they were queued.
    fn flush(
        &self,
        wave: &mut Wave,
        pixels: &mut [PixelSums],
        aov_sums: &mut [i128],
        mut splat: Option<&mut SplatBuffer>,
        counts: &mut TileCounts,
    ) {
        if wave.cameras.is_empty() {
            return;
        }
        let traversal = self.settings.schedule.batch_traversal().unwrap_or(BatchTraversal::OneByOne);
        wave.radiance.clear();
        wave.radiance.resize(wave.cameras.len(), Rgb::BLACK);
        let shading = self.settings.schedule.path_shading();
        self.integrator.li_batch(
            self.scene,
            traversal,
            shading,
            &mut wave.cameras,
            &mut wave.radiance,
            &mut counts.counters,
        );
        for ((origin, camera), &l) in wave.origins.iter().zip(&wave.cameras).zip(&wave.radiance) {
            let i = origin.index;
            let aov = &mut aov_sums[i * self.stride..(i + 1) * self.stride];
            self.record(origin, &camera.ray, l, &mut pixels[i], aov, splat.as_deref_mut(), counts);
        }
        wave.origins.clear();
        wave.cameras.clear();
    }

    /// Adds one sample's radiance (and its AOVs) to its pixel.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        origin: &SampleOrigin,
        ray: &Ray,
        mut l: Rgb,
        sums: &mut PixelSums,
        aov_sums: &mut [i128],
        splat: Option<&mut SplatBuffer>,
        counts: &mut TileCounts,
    ) {
        let scene = self.scene;
        if !l.is_finite() || l.r < 0.0 || l.g < 0.0 || l.b < 0.0 {
            counts.discarded += 1;
            l = Rgb::BLACK;
        }
        sums.add_sample(l);
        if let Some(buffer) = splat {
            buffer.splat(&self.filter, origin.px, origin.py, l);
        }
        counts.camera_rays += 1;
        if self.layers.is_empty() {
            return;
        }
        let hit = if self.wants_first_hit { first_hit(scene, ray) } else { crate::integrators::FirstHit::NONE };
        for &(aov, off) in self.layers {
            let values: [f32; 3] = match aov {
                Aov::Albedo => hit.albedo.to_array(),
                Aov::Normal => hit.normal.to_array(),
                Aov::Position => hit.position.to_array(),
                Aov::Depth => [hit.depth, 0.0, 0.0],
                Aov::BvhCost => [closest_hit_cost(scene, ray) as f32, 0.0, 0.0],
                Aov::Variance | Aov::Spp => continue,
            };
            for c in 0..aov.stored_channels() {
                aov_sums[off + c] = aov_sums[off + c].saturating_add(to_fixed(values[c] as f64));
            }
        }
    }
}

/// The camera ray of sample `s` of pixel (x, y), its position on the film, and its sampler
/// for the integrator, past the camera's dimensions. A function of (seed, pixel, sample
/// index) alone: calling it again gives the same ray and the same random numbers after it.
pub(crate) fn camera_sample(
    scene: &World,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    s: u32,
) -> ([f32; 2], CameraSample) {
    let pixel = y as u64 * scene.camera.width as u64 + x as u64;
    let mut rng = Sampler::new(settings.sampler, settings.seed, pixel, s);
    // Uniform in the pixel; a splatting filter spreads the sample over its neighbours.
    let u = rng.next_2d();
    let (px, py) = (x as f32 + 0.5 + (u[0] - 0.5), y as f32 + 0.5 + (u[1] - 0.5));
    let lens = rng.next_2d();
    let ray = scene.camera.generate_ray(px, py, lens);
    ([px, py], CameraSample { ray, sampler: rng })
}

/// Where a camera sample lands: its pixel (index in the band) and its film position.
#[derive(Clone, Copy, Debug)]
struct SampleOrigin {
    index: usize,
    px: f32,
    py: f32,
}

/// Camera samples queued for the wavefront schedules, and room for their radiance.
#[derive(Default)]
struct Wave {
    origins: Vec<SampleOrigin>,
    cameras: Vec<CameraSample>,
    radiance: Vec<Rgb>,
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
