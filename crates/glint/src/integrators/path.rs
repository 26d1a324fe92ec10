//! Unidirectional path tracing with next-event estimation and multiple importance
//! sampling (power heuristic), Russian roulette on the path throughput, and unbounded depth
//! by default. Depth counts path segments, as Mitsuba's `max_depth` does: 1 shows emitters
//! seen directly, 2 adds direct lighting, and so on.
//!
//! A path is a [`PathState`] advanced one vertex at a time: [`PathState::step`] takes the hit
//! of the path's ray and leaves the next ray to trace and, at most, one shadow ray whose
//! answer [`PathState::resolve_shadow`] adds in. [`li`] traces those rays one at a time (the
//! reference); `path_batch` traces many paths' rays together. Both run the same steps in the
//! same order, so a path's radiance is the same bits either way.

use super::estimators::{add_emitted, add_environment, sample_light, survives_roulette, PrevEvent};
use super::observe::{NextEvent, PathObserver, Scattering, Unobserved};
use super::surface::{passes_mask, transmittance};
use super::{camera_hit, shading, shadow_ray, spawn_ray, Counters};
use crate::describe::{PathSettings, Strategy};
use crate::materials::ShadedBsdf;
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::{power_heuristic, Sampler};
use crate::world::{Hit, SurfaceInteraction, World};

/// The longest path, in segments, even when `max_depth` is unbounded: a hard ceiling so that
/// a path trapped between mirrors with a Russian roulette probability of 1 still ends. Light
/// carried by longer paths is lost (a bias below throughput^4096).
pub const MAX_PATH_DEPTH: u32 = 4096;

/// The radiance along `camera_ray`, its path traced to its end one ray at a time.
pub fn li(s: &PathSettings, scene: &World, camera_ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
    let mut path = PathState::new(s, camera_ray);
    while path.tracing {
        let hit = path.trace(s, scene, c);
        path.step(s, scene, hit, rng, c);
        if let Some(shadow) = path.shadow.take() {
            let visible = transmittance(scene, &shadow.ray, c);
            path.resolve_shadow(&shadow, visible);
        }
    }
    path.l
}

/// A shadow ray of next-event estimation and what it adds if light gets along it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShadowQuery {
    pub ray: Ray,
    /// Throughput x BSDF x emitted radiance, before the MIS weight and the light's density.
    pub contribution: Rgb,
    pub mis_weight: f32,
    pub light_pdf: f32,
}

/// One path between vertices: what it has gathered and what it traces next.
#[derive(Clone, Debug)]
pub(crate) struct PathState {
    /// Radiance gathered so far.
    pub l: Rgb,
    throughput: Rgb,
    /// The product of eta^2 over the refractions so far: it undoes the 1/eta^2 radiance
    /// scaling in `throughput` for Russian roulette, as pbrt and Mitsuba do, so that paths
    /// inside glass are not killed for a scale factor that leaving the glass undoes.
    eta_scale: f32,
    /// The ray to trace next (when `tracing`).
    pub ray: Ray,
    /// The BSDF sample that produced `ray`: its density (solid angle), whether it was delta,
    /// and where; the camera ray behaves like a delta sample (nothing else could have
    /// produced it).
    prev: PrevEvent,
    /// Segments traced so far.
    pub depth: u32,
    mask_passes: u32,
    max_depth: u32,
    /// Whether `ray` is still to be traced; false once the path has ended.
    pub tracing: bool,
    /// The shadow ray the last step left, if any.
    pub shadow: Option<ShadowQuery>,
}

impl PathState {
    pub fn new(s: &PathSettings, camera_ray: &Ray) -> PathState {
        let max_depth = s.max_depth.unwrap_or(MAX_PATH_DEPTH).min(MAX_PATH_DEPTH);
        PathState {
            l: Rgb::BLACK,
            throughput: Rgb::WHITE,
            eta_scale: 1.0,
            ray: *camera_ray,
            prev: PrevEvent { pdf: 1.0, delta: true, p: camera_ray.origin },
            depth: 0,
            mask_passes: 0,
            max_depth,
            tracing: max_depth > 0,
            shadow: None,
        }
    }

    /// Whether the next ray is a camera ray that must look through hidden emitters (which
    /// [`PathState::trace`] does one ray at a time).
    pub fn traces_hidden_emitters(&self, s: &PathSettings) -> bool {
        self.depth == 0 && s.hide_emitters
    }

    /// The closest hit of the path's next ray, traced alone. Hidden emitters are looked
    /// through by the camera ray (which then replaces `ray`, and does not count as depth).
    pub fn trace(&mut self, s: &PathSettings, scene: &World, c: &mut Counters) -> Option<Hit> {
        if self.depth == 0 {
            camera_hit(scene, &self.ray, s.hide_emitters, c).map(|(r, h)| {
                self.ray = r;
                h
            })
        } else {
            c.rays += 1;
            scene.intersect(&self.ray)
        }
    }

    /// Adds a shadow ray's contribution, `visible` being the fraction of light that got along it.
    #[inline]
    pub fn resolve_shadow(&mut self, q: &ShadowQuery, visible: f32) {
        if visible > 0.0 {
            self.l += q.contribution * (q.mis_weight * visible / q.light_pdf);
        }
    }

    /// One vertex: emission at `hit`, then (unless the path ends there) a shadow ray for
    /// next-event estimation and the next ray by sampling the BSDF. Clears `tracing` when the
    /// path ends. The caller resolves `shadow` before the next step.
    #[inline]
    pub fn step(&mut self, s: &PathSettings, scene: &World, hit: Option<Hit>, rng: &mut Sampler, c: &mut Counters) {
        self.step_observed(s, scene, hit, rng, c, &mut Unobserved);
    }

    /// [`PathState::step`], showing `observer` what the vertex does (see `observe`).
    pub(crate) fn step_observed<O: PathObserver>(
        &mut self,
        s: &PathSettings,
        scene: &World,
        hit: Option<Hit>,
        rng: &mut Sampler,
        c: &mut Counters,
        observer: &mut O,
    ) {
        let Some(si) = self.arrive(s, scene, hit, rng, observer) else { return };
        let (bsdf, frame) = shading(scene, &si, -self.ray.dir);
        self.scatter(s, scene, &si, &bsdf, &frame, rng, c, observer);
    }

    /// The first part of a step: the vertex is reached (depth counted, `tracing` cleared),
    /// emission seen there or the environment seen on a miss is added, and a masked surface
    /// may be passed. Returns the interaction where the path goes on to scatter there
    /// ([`PathState::scatter`], after `shading`); `None` where the step is over.
    #[inline]
    pub(crate) fn arrive<O: PathObserver>(
        &mut self,
        s: &PathSettings,
        scene: &World,
        hit: Option<Hit>,
        rng: &mut Sampler,
        observer: &mut O,
    ) -> Option<SurfaceInteraction> {
        self.tracing = false;
        self.depth += 1;
        let ray = self.ray;
        let Some(hit) = hit else {
            if !(self.depth == 1 && s.hide_emitters) {
                add_environment(scene, &ray, s.strategy, &self.prev, self.throughput, &mut self.l, observer);
            }
            return None;
        };
        let si = scene.interaction(&ray, &hit);

        if let Some(li_idx) = si.light {
            if !(self.depth == 1 && s.hide_emitters) {
                add_emitted(scene, &si, &ray, li_idx, s.strategy, &self.prev, self.throughput, &mut self.l, observer);
            }
        }
        // A masked surface lets the path through unscattered with probability 1 - opacity.
        // Passing is not a bounce: depth, the MIS state and the previous vertex stay as
        // they were (shadow rays from that vertex crossed the surface the same way).
        if passes_mask(scene, &si, ray.dir, self.mask_passes, rng) {
            self.mask_passes += 1;
            self.depth -= 1;
            self.ray = spawn_ray(&si, ray.dir);
            self.tracing = true;
            return None;
        }
        if self.depth >= self.max_depth {
            return None;
        }
        Some(si)
    }

    /// What [`PathState::arrive`] does at a hit that the caller knows neither emits light
    /// nor may be passed (no mask, no culled back face): the vertex is reached. Returns
    /// whether the path goes on to scatter there (it has not reached its depth limit).
    #[inline]
    pub(crate) fn arrive_opaque(&mut self) -> bool {
        self.tracing = false;
        self.depth += 1;
        self.depth < self.max_depth
    }

    /// The rest of a step at `si`, whose BSDF and frame `shading` gave: a shadow ray for
    /// next-event estimation, and the next ray by sampling the BSDF.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn scatter<O: PathObserver>(
        &mut self,
        s: &PathSettings,
        scene: &World,
        si: &SurfaceInteraction,
        bsdf: &ShadedBsdf,
        frame: &Frame,
        rng: &mut Sampler,
        c: &mut Counters,
        observer: &mut O,
    ) {
        let wo = frame.to_local(-self.ray.dir);

        // Next-event estimation: one light, chosen by the scene's light distribution.
        if s.strategy != Strategy::Bsdf && !bsdf.is_delta() {
            if let Some((ls, pick_pmf, light)) = sample_light(scene, si.p, rng) {
                let wi = frame.to_local(ls.wi);
                let f = bsdf.eval(wo, wi);
                // A black BSDF value adds nothing, but its derivative may not be zero (a
                // reflectance of 0 that an optimiser is to raise): observers that ask see it.
                if !f.is_black() || O::SEES_BLACK_BSDF {
                    let light_pdf = pick_pmf * ls.pdf;
                    let mis_weight = if ls.delta || s.strategy == Strategy::Light {
                        1.0
                    } else {
                        power_heuristic(light_pdf, bsdf.pdf(wo, wi))
                    };
                    let throughput = self.throughput;
                    let ls = &ls;
                    observer.next_event(&NextEvent {
                        si,
                        bsdf,
                        wo,
                        wi,
                        ls,
                        light,
                        throughput,
                        f,
                        mis_weight,
                        light_pdf,
                    });
                    if !f.is_black() {
                        c.shadow_rays += 1;
                        self.shadow = Some(ShadowQuery {
                            ray: shadow_ray(si, ls.wi, ls.dist),
                            contribution: self.throughput * f * ls.radiance,
                            mis_weight,
                            light_pdf,
                        });
                    }
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let u_lobe = rng.next_f32();
        let u = rng.next_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            return;
        };
        if bs.weight.is_black() {
            return;
        }
        observer.scattering(&Scattering { si, bsdf, wo, wi: bs.wi, delta: bs.delta });
        let wi_world = frame.to_world(bs.wi);
        let prev = PrevEvent { pdf: bs.pdf, delta: bs.delta, p: si.p };
        self.go_on(s, bs.weight, bs.eta, prev, spawn_ray(si, wi_world), rng);
    }

    /// The end of a step whose BSDF sampled the next ray: the throughput takes the sample's
    /// weight, and the path goes on unless Russian roulette ends it.
    #[inline]
    pub(crate) fn go_on(
        &mut self,
        s: &PathSettings,
        weight: Rgb,
        eta: f32,
        prev: PrevEvent,
        ray: Ray,
        rng: &mut Sampler,
    ) {
        self.throughput *= weight;
        self.eta_scale *= eta * eta;
        self.prev = prev;
        self.ray = ray;
        if self.depth >= s.rr_depth && !survives_roulette(&mut self.throughput, self.eta_scale, s.rr_probability, rng) {
            return;
        }
        self.tracing = true;
    }

    /// Leaves the shadow ray of next-event estimation (counted in `c`).
    #[inline]
    pub(crate) fn leave_shadow_ray(&mut self, q: ShadowQuery, c: &mut Counters) {
        c.shadow_rays += 1;
        self.shadow = Some(q);
    }

    /// The path's throughput so far.
    #[inline]
    pub(crate) fn throughput(&self) -> Rgb {
        self.throughput
    }
}
