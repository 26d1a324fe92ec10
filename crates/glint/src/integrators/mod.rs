//! Integrators: estimate the radiance arriving along a camera ray.
//!
//! Each integrator has serialisable settings and a per-ray `li`; scheduling of pixels and
//! threads lives in the render module, so integrators never see threads.

mod direct;
mod estimators;
mod first_hit;
mod observe;
mod path;
mod path_batch;
mod surface;
mod vertex_lanes;
mod volpath;
mod whitted;

/// An integrator is its description: the settings a scene states, with the estimators
/// implemented here (`li`, `li_batch`).
pub use crate::describe::IntegratorDesc as Integrator;
pub use crate::describe::{DirectSettings, PathSettings, Strategy, VolpathSettings, WhittedSettings};
pub use first_hit::{closest_hit_cost, first_hit, FirstHit};
pub(crate) use observe::{NextEvent, PathObserver, Scattering};
pub(crate) use path::{li as path_li, PathState};
pub use path_batch::{CameraSample, PathShading};
pub(crate) use surface::transmittance;

use crate::materials::ShadedBsdf;
use crate::math::{offset_origin, Frame, Ray, Rgb, Vec3};
use crate::sampling::Sampler;
use crate::world::{BatchTraversal, Hit, SurfaceInteraction, World};

/// Per-thread counters, summed at the end of a render.
#[derive(Clone, Copy, Debug, Default)]
pub struct Counters {
    pub rays: u64,
    pub shadow_rays: u64,
}

impl Integrator {
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Whitted(_) => "whitted",
            Integrator::Path(_) => "path",
            Integrator::Direct(_) => "direct",
            Integrator::Volpath(_) => "volpath",
        }
    }

    #[inline]
    pub fn li(&self, scene: &World, ray: &Ray, rng: &mut Sampler, counters: &mut Counters) -> Rgb {
        match self {
            Integrator::Whitted(s) => whitted::li(s, scene, ray, rng, counters),
            Integrator::Path(s) => path::li(s, scene, ray, rng, counters),
            Integrator::Direct(s) => direct::li(s, scene, ray, rng, counters),
            Integrator::Volpath(s) => volpath::li(s, scene, ray, rng, counters),
        }
    }

    /// The radiance of many camera samples: `out[i]` is [`Integrator::li`] of `samples[i]`,
    /// bit for bit. The path tracer advances the paths together (see `path_batch`); the
    /// other integrators trace them one after another.
    ///
    /// Panics if the slices differ in length.
    pub fn li_batch(
        &self,
        scene: &World,
        traversal: BatchTraversal,
        shading: PathShading,
        samples: &mut [CameraSample],
        out: &mut [Rgb],
        counters: &mut Counters,
    ) {
        assert_eq!(samples.len(), out.len(), "li_batch: one radiance per sample");
        match self {
            Integrator::Path(s) => path_batch::li_batch(s, scene, traversal, shading, samples, out, counters),
            Integrator::Whitted(_) | Integrator::Direct(_) | Integrator::Volpath(_) => {
                for (cs, o) in samples.iter_mut().zip(out.iter_mut()) {
                    *o = self.li(scene, &cs.ray, &mut cs.sampler, counters);
                }
            }
        }
    }
}

/// The BSDF at a hit and the frame to evaluate it in. Two-sided opaque materials turn
/// their frame to face the viewer; one-sided ones (Mitsuba's default) keep it, so their back
/// face is black; dielectrics keep it, since which side is inside matters to them. Normal
/// and bump maps tilt the BSDF within that frame (see `surface`).
pub(crate) fn shading(scene: &World, si: &SurfaceInteraction, wo_world: Vec3) -> (ShadedBsdf, Frame) {
    surface::shade(scene, si, wo_world)
}

/// The most emitters a camera ray looks through when they are hidden; one that meets more
/// (a stack of coincident lights) ends there as if it had left the scene.
const MAX_HIDDEN_EMITTERS: u32 = 64;

/// The first hit of a camera ray, and the ray that made it. With `hide_emitters` the ray
/// passes through every emitter it meets, as Mitsuba's `hide_emitters` does, so that what lies
/// behind an area light shows instead of it.
pub(crate) fn camera_hit(scene: &World, ray: &Ray, hide_emitters: bool, c: &mut Counters) -> Option<(Ray, Hit)> {
    let mut ray = *ray;
    for _ in 0..=MAX_HIDDEN_EMITTERS {
        c.rays += 1;
        let hit = scene.intersect(&ray)?;
        let si = scene.interaction(&ray, &hit);
        if !hide_emitters || si.light.is_none() {
            return Some((ray, hit));
        }
        ray = spawn_ray(&si, ray.dir);
    }
    None
}

/// A ray leaving the surface at `si` in direction `dir`, offset off the surface.
#[inline]
pub(crate) fn spawn_ray(si: &SurfaceInteraction, dir: Vec3) -> Ray {
    Ray::new(offset_origin(si.p, si.ng, dir), dir)
}

/// A shadow ray from `si` towards the point `dist` away along `dir` (stops just short of it).
/// The ray aims at that point from the offset origin: keeping `dir` from there would miss
/// the point, and where the light surface is oblique to the ray it would hit the light
/// itself well before `dist` and count it as an occluder.
#[inline]
pub(crate) fn shadow_ray(si: &SurfaceInteraction, dir: Vec3, dist: f32) -> Ray {
    let o = offset_origin(si.p, si.ng, dir);
    if !dist.is_finite() {
        return Ray::segment(o, dir, f32::INFINITY);
    }
    let to_target = si.p + dir * dist - o;
    let len = to_target.length();
    Ray::segment(o, to_target / len, len * (1.0 - 1e-4))
}
