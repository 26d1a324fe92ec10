//! Gradients of a rendered image with respect to scene parameters, by path replay
//! backpropagation (Vicini, Speierer and Jakob 2021; Mitsuba's `prb`).
//!
//! The quantity differentiated is a loss's inner product with the image: given the adjoint
//! image `G` (the loss's derivative with respect to each pixel and channel), the gradient
//! of `sum(G * I)` with respect to each parameter, where `I` is the box-filtered image (each
//! pixel the mean of its samples) that a render with the same seed and spp makes.
//!
//! For each camera sample, two passes:
//! 1. **Primal**: the path tracer's `li`, which gives the sample's radiance `L`.
//! 2. **Adjoint**: the same path replayed. The sampler is a function of (seed, pixel,
//!    sample index) alone, so making the camera sample again (`render::camera_sample`) gives
//!    the same ray and the same random numbers in the same order, and the path takes the
//!    same decisions. At each vertex the replay adds the adjoint radiance `G(pixel) / spp`
//!    times the derivative of what the vertex adds: emission and next-event estimation
//!    directly, and for the BSDF sample that continues the path, the radiance still to come
//!    (`L` minus what the replay has gathered so far) times `(df/dθ) / f` of the sampled
//!    direction. Memory does not grow with path length. Sampling is detached, as in
//!    Mitsuba's `prb`: directions, light choices, MIS weights and Russian roulette are
//!    treated as constants, which leaves the estimate unbiased for parameters that do not
//!    move geometry.
//!
//! Derivatives at a vertex (see `params`): a material parameter's by a symmetric difference
//! of the material's own BSDF value, built with the parameter moved up and down
//! ([`BsdfDifference`]), at the same texture point and directions (exact up to rounding where
//! the BSDF is affine in the parameter, as a Lambertian reflectance is); a light's radiance,
//! intensity or scale analytically (emission is linear in each).
//!
//! Gradients are summed in fixed point, as the film's samples are, so they are the same
//! bits for any thread count or order.

mod adjoint;
mod params;

pub use params::{BsdfDifference, LightParam, LightProbe, MaterialProbe, ParamSet, TextureProbe};

use crate::error::Error;
use crate::integrators::{path_li, Counters, PathSettings, PathState};
use crate::math::Rgb;
use crate::render::{camera_sample, film::to_fixed, RenderSettings};
use crate::world::World;
use adjoint::Adjoint;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Extra fractional bits of the gradient sums beyond the film's: a texel's share of one
/// sample can be far below a pixel value's resolution.
const GRADIENT_EXTRA_BITS: i32 = 24;

/// Camera samples between two looks at the cancel flag.
const CANCEL_CHECK_SAMPLES: u32 = 64;

/// One parameter's gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamGradient {
    pub name: String,
    /// Empty for a number, `[3]` for a colour, `[height, width, 3]` for an image's texels.
    pub shape: Vec<usize>,
    pub values: Vec<f64>,
}

/// A gradient render: the adjoint image (`width * height`, rows from the top), the samples
/// per pixel and the path tracer's settings.
pub struct GradientJob<'a> {
    pub world: &'a World,
    pub path: &'a PathSettings,
    pub render: &'a RenderSettings,
    pub params: &'a ParamSet,
    pub grad_image: &'a [Rgb],
    pub spp: u32,
}

/// The gradient of `sum(grad_image * image)` with respect to each of the set's scalar
/// parameters (see the module doc). `Err` when cancelled (checked every few samples).
pub fn render_gradient(job: &GradientJob<'_>, cancel: &AtomicBool) -> Result<Vec<f64>, Error> {
    let (w, h) = (job.world.camera.width, job.world.camera.height);
    if job.grad_image.len() != w as usize * h as usize {
        return Err(Error::new(format!(
            "grad_image has {} pixels but the camera renders {w}x{h}",
            job.grad_image.len()
        )));
    }
    let n = job.params.len();
    let sums = (0..h)
        .into_par_iter()
        .try_fold(
            || vec![0i128; n],
            |mut sums, y| {
                for x in 0..w {
                    let adjoint = job.grad_image[(y * w + x) as usize] / job.spp as f32;
                    if adjoint.is_black() {
                        continue;
                    }
                    for s in 0..job.spp {
                        // Checked often enough that a pixel of many samples stops soon.
                        if s % CANCEL_CHECK_SAMPLES == 0 && cancel.load(Ordering::Relaxed) {
                            return Err(Error::new("cancelled"));
                        }
                        sample_gradient(job, x, y, s, adjoint, &mut sums);
                    }
                }
                Ok(sums)
            },
        )
        .try_reduce(
            || vec![0i128; n],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x = x.saturating_add(y);
                }
                Ok(a)
            },
        )?;
    let scale = 2f64.powi(crate::render::film::FIXED_POINT_BITS as i32 + GRADIENT_EXTRA_BITS);
    Ok(sums.into_iter().map(|s| s as f64 / scale).collect())
}

/// Adds one camera sample's share of the gradient to `sums`.
fn sample_gradient(job: &GradientJob<'_>, x: u32, y: u32, s: u32, adjoint: Rgb, sums: &mut [i128]) {
    let mut counters = Counters::default();
    let (_, mut primal) = camera_sample(job.world, job.render, x, y, s);
    let l = path_li(job.path, job.world, &primal.ray, &mut primal.sampler, &mut counters);
    // The film drops such a sample (it adds black), so nothing depends on the parameters.
    if !l.is_finite() || l.r < 0.0 || l.g < 0.0 || l.b < 0.0 {
        return;
    }
    // The replay: the same camera sample made again, so the same random numbers.
    let (_, mut replay) = camera_sample(job.world, job.render, x, y, s);
    let mut observer = Adjoint::new(job.world, job.params, adjoint, l, sums);
    let mut path = PathState::new(job.path, &replay.ray);
    while path.tracing {
        let hit = path.trace(job.path, job.world, &mut counters);
        path.step_observed(job.path, job.world, hit, &mut replay.sampler, &mut counters, &mut observer);
        // The observer traced the shadow ray itself.
        path.shadow = None;
    }
}

/// `v` in the gradient sums' fixed point.
#[inline]
fn fixed(v: f64) -> i128 {
    to_fixed(v * 2f64.powi(GRADIENT_EXTRA_BITS))
}
