//! Estimator pieces the path tracers share: choosing a light and a point on it for
//! next-event estimation, the MIS weight of an emitter that a sampled direction reaches, and
//! what the environment lights and a hit area light send back along a path, and Russian
//! roulette. The direct
//! integrator weights by its sample counts and the Whitted integrator does not weight, so
//! they keep their own.

use crate::describe::Strategy;
use crate::lights::LightSample;
use crate::math::{Ray, Rgb, Vec3};
use crate::sampling::{power_heuristic, Sampler};
use crate::world::{SurfaceInteraction, World};

use super::observe::PathObserver;

/// The last scattering event of a path: the density its sampled direction had, whether it
/// was delta (or could not have been sampled by lights), and where it was.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrevEvent {
    pub pdf: f32,
    pub delta: bool,
    pub p: Vec3,
}

/// A light chosen by the scene's light distribution and a point on it, both from one 2D
/// point (its first coordinate picks the light and, rescaled, drives the point with the
/// second, as Mitsuba does: the sampler's 2D stratification then holds within each light's
/// share of the samples); `None` without lights, or when the sample carries nothing. The
/// second value is the probability of choosing the light, the third its index.
pub(crate) fn sample_light(scene: &World, p: Vec3, rng: &mut Sampler) -> Option<(LightSample, f32, u32)> {
    if !scene.can_choose_lights() {
        return None;
    }
    let u = rng.next_2d();
    let choice = scene.choose_light(p, u[0])?;
    let ls = scene.sample_chosen(&choice, p, u[1])?;
    if !(ls.pdf > 0.0) || ls.radiance.is_black() {
        return None;
    }
    Some((ls, choice.pmf, choice.index as u32))
}

/// MIS weight of an emitter reached by a sampled direction (`light_pdf`, the density light
/// sampling would have had, evaluated only when needed).
#[inline]
pub(crate) fn emitter_weight(strategy: Strategy, prev: &PrevEvent, light_pdf: impl FnOnce() -> f32) -> f32 {
    if prev.delta {
        return 1.0;
    }
    match strategy {
        Strategy::Bsdf => 1.0,
        Strategy::Light => 0.0,
        Strategy::Mis => power_heuristic(prev.pdf, light_pdf()),
    }
}

/// Adds to `l` what the environment lights send along an escaped `ray`, times `throughput`.
pub(crate) fn add_environment(
    scene: &World,
    ray: &Ray,
    strategy: Strategy,
    prev: &PrevEvent,
    throughput: Rgb,
    l: &mut Rgb,
    observer: &mut impl PathObserver,
) {
    for &li_idx in &scene.environment_lights {
        let light = &scene.lights[li_idx as usize];
        let le = light.environment(ray.dir);
        if le.is_black() {
            continue;
        }
        let w = emitter_weight(strategy, prev, || scene.light_pdf(prev.p, li_idx, 0, ray.dir, ray.origin, ray.dir));
        *l += throughput * le * w;
        observer.emission(li_idx, ray.dir, None, throughput, le, w);
    }
}

/// Adds to `l` what the area light `li_idx`, hit at `si`, emits back along `ray`, times
/// `throughput`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_emitted(
    scene: &World,
    si: &SurfaceInteraction,
    ray: &Ray,
    li_idx: u32,
    strategy: Strategy,
    prev: &PrevEvent,
    throughput: Rgb,
    l: &mut Rgb,
    observer: &mut impl PathObserver,
) {
    let le = scene.emitted(si, ray.dir);
    if !le.is_black() {
        let w = emitter_weight(strategy, prev, || scene.light_pdf(prev.p, li_idx, si.prim, ray.dir, si.p, si.ng));
        *l += throughput * le * w;
        observer.emission(li_idx, ray.dir, Some(si), throughput, le, w);
    }
}

/// Russian roulette: false when the path ends; otherwise the throughput is divided by the
/// survival probability. That is `fixed` where the settings give one, else the throughput's
/// largest channel times `eta_scale` (which undoes the 1/eta^2 radiance scaling of
/// refraction, as pbrt and Mitsuba do), capped at 0.95 so that a path trapped between
/// mirrors still ends. A probability that is not positive ends the path.
#[inline]
pub(crate) fn survives_roulette(throughput: &mut Rgb, eta_scale: f32, fixed: Option<f32>, rng: &mut Sampler) -> bool {
    let q = match fixed {
        Some(q) => q,
        None => (throughput.max_component() * eta_scale).min(0.95),
    };
    if !(q > 0.0) || rng.next_f32() >= q {
        return false;
    }
    *throughput = *throughput / q;
    true
}
