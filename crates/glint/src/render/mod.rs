//! Scheduling: the image is cut into tiles that rayon renders in parallel. Every camera
//! sample draws its random numbers from a generator keyed by (seed, pixel, sample index),
//! and each pixel sums its samples in order, so the image is bit-identical whatever the
//! number of threads.

pub use crate::sampling::PixelFilter;

use crate::integrators::{Counters, Integrator};
use crate::io::Image;
use crate::math::Rgb;
use crate::sampling::{Sampler, SamplerKind};
use crate::world::World;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub spp: u32,
    pub seed: u64,
    pub filter: PixelFilter,
    pub sampler: SamplerKind,
    /// Also return the per-pixel variance of the mean (for statistical tests).
    pub variance: bool,
    pub tile_size: usize,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            seed: 0,
            filter: PixelFilter::Box,
            sampler: SamplerKind::Sobol,
            variance: false,
            tile_size: 16,
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

struct Tile {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

pub fn render(
    scene: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> RenderOutput {
    let start = Instant::now();
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let ts = settings.tile_size.max(1);
    let tiles: Vec<Tile> = (0..h.div_ceil(ts))
        .flat_map(|ty| {
            (0..w.div_ceil(ts)).map(move |tx| Tile {
                x0: tx * ts,
                y0: ty * ts,
                x1: ((tx + 1) * ts).min(w),
                y1: ((ty + 1) * ts).min(h),
            })
        })
        .collect();
    let rays = AtomicU64::new(0);
    let shadow = AtomicU64::new(0);
    let discarded = AtomicU64::new(0);
    let spp = settings.spp.max(1);

    let results: Vec<(Vec<Rgb>, Vec<Rgb>)> = tiles
        .par_iter()
        .map(|tile| {
            let mut counters = Counters::default();
            let mut dropped = 0u64;
            let n = (tile.x1 - tile.x0) * (tile.y1 - tile.y0);
            let mut means = Vec::with_capacity(n);
            let mut vars = Vec::with_capacity(if settings.variance { n } else { 0 });
            for y in tile.y0..tile.y1 {
                for x in tile.x0..tile.x1 {
                    let pixel = (y * w + x) as u64;
                    let mut sum = [0.0f64; 3];
                    let mut sum2 = [0.0f64; 3];
                    for s in 0..spp {
                        let mut rng = Sampler::new(settings.sampler, settings.seed, pixel, s);
                        let off = settings.filter.sample(rng.next_2d());
                        let lens = rng.next_2d();
                        let ray = scene.camera.generate_ray(x as f32 + 0.5 + off[0], y as f32 + 0.5 + off[1], lens);
                        let mut l = integrator.li(scene, &ray, &mut rng, &mut counters);
                        if !l.is_finite() || l.r < 0.0 || l.g < 0.0 || l.b < 0.0 {
                            dropped += 1;
                            l = Rgb::BLACK;
                        }
                        for (k, v) in l.to_array().into_iter().enumerate() {
                            sum[k] += v as f64;
                            sum2[k] += v as f64 * v as f64;
                        }
                    }
                    let nf = spp as f64;
                    let mean = [sum[0] / nf, sum[1] / nf, sum[2] / nf];
                    means.push(Rgb { r: mean[0] as f32, g: mean[1] as f32, b: mean[2] as f32 });
                    if settings.variance {
                        let var = |k: usize| {
                            if spp > 1 {
                                ((sum2[k] / nf - mean[k] * mean[k]) * nf / (nf - 1.0)).max(0.0) / nf
                            } else {
                                0.0
                            }
                        };
                        vars.push(Rgb { r: var(0) as f32, g: var(1) as f32, b: var(2) as f32 });
                    }
                }
            }
            rays.fetch_add(counters.rays, Ordering::Relaxed);
            shadow.fetch_add(counters.shadow_rays, Ordering::Relaxed);
            discarded.fetch_add(dropped, Ordering::Relaxed);
            progress.advance(n as u64, counters.rays + counters.shadow_rays);
            (means, vars)
        })
        .collect();

    let mut image = Image::new(w, h);
    let mut variance = settings.variance.then(|| Image::new(w, h));
    for (tile, (means, vars)) in tiles.iter().zip(results) {
        let tw = tile.x1 - tile.x0;
        for (i, m) in means.into_iter().enumerate() {
            let (x, y) = (tile.x0 + i % tw, tile.y0 + i / tw);
            image.pixels[y * w + x] = m;
        }
        if let Some(v) = variance.as_mut() {
            for (i, m) in vars.into_iter().enumerate() {
                let (x, y) = (tile.x0 + i % tw, tile.y0 + i / tw);
                v.pixels[y * w + x] = m;
            }
        }
    }
    let stats = RenderStats {
        seconds: start.elapsed().as_secs_f64(),
        camera_rays: (w * h) as u64 * spp as u64,
        rays: rays.into_inner(),
        shadow_rays: shadow.into_inner(),
        discarded_samples: discarded.into_inner(),
    };
    RenderOutput { image, variance, stats }
}
