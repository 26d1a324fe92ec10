//! Volumetric path tracing (Mitsuba's `volpath`): the path tracer of `path`, with media.
//!
//! A ray travelling in a medium either scatters before the next surface or reaches it. The
//! free-flight distances of a path are drawn from one colour channel's exponential (the hero
//! channel, chosen per path), and the path is weighted by its contribution over the mean of
//! the three channels' path densities: spectral MIS with the balance heuristic over whole
//! paths (as Mitsuba's `volpathmis`), unbiased in every channel and at most 3 times the
//! channel's own estimate, where following one channel (Mitsuba's `volpath`) has no bound. At a scattering point the light is sampled (next-event estimation, with the
//! transmittance along the shadow ray) and the phase function continues the path, the two
//! combined by MIS as at surfaces. Surfaces with a `null` BSDF (and the straight-through
//! lobe of a thin dielectric) are passages, not scattering events: paths go on through them
//! without counting depth, and shadow rays pass through them, attenuated by every medium
//! they cross. A masked surface (`mask`) is a passage with probability 1 - opacity: paths
//! pass it at random, as in `path`, and shadow rays carry its 1 - opacity. A shape that
//! bounds media switches the ray's medium to the one on the side the ray leaves to.
//! Surfaces without media behave exactly as in `path`.
//!
//! Depth counts scattering events (in media and at surfaces, not passages), as Mitsuba's
//! `max_depth` does: 1 shows emitters seen directly (through any passages and media), 2
//! adds single scattering, and so on. Transmittance along shadow rays is exact in homogeneous
//! media (exp(-σt d) per channel and per medium crossed); heterogeneous media (grey
//! extinction from a density grid) sample distances by delta tracking and estimate shadow
//! rays' transmittance by ratio tracking, both against the grid's majorant.

use super::estimators::{add_emitted, add_environment, sample_light, survives_roulette, PrevEvent};
use super::observe::Unobserved;
use super::path::MAX_PATH_DEPTH;
use super::surface::opacity;
use super::{shading, shadow_ray, spawn_ray, Counters};
use crate::bsdf::BsdfSample;
use crate::describe::{Strategy, VolpathSettings};
use crate::materials::{Bsdf, ShadedBsdf};
use crate::math::{offset_origin, Frame, Ray, Rgb, Vec3};
use crate::media::{sample_distance, Medium};
use crate::sampling::{power_heuristic, Sampler};
use crate::world::{Hit, SurfaceInteraction, World};

/// The most passages (null boundaries, hidden emitters) one path or shadow ray makes; a
/// ray that meets more (a stack of coincident boundaries) ends there.
const MAX_PASSAGES: u32 = 256;

pub fn li(s: &VolpathSettings, scene: &World, camera_ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
    let max_depth = s.max_depth.unwrap_or(MAX_PATH_DEPTH).min(MAX_PATH_DEPTH);
    if max_depth == 0 {
        return Rgb::BLACK;
    }
    let mut path = VolPath::new(s, scene, max_depth, camera_ray, rng);
    loop {
        c.rays += 1;
        let hit = scene.intersect(&path.ray);
        if let Some(mi) = path.medium {
            match path.through_medium(mi, hit.map_or(f32::INFINITY, |h| h.t), rng, c) {
                Flight::Scattered => continue,
                Flight::Ended => break,
                Flight::ReachedSurface => {}
            }
        }
        let Some(hit) = hit else {
            path.escape();
            break;
        };
        if !path.at_surface(&hit, rng, c) {
            break;
        }
    }
    path.l
}

/// What a ray's flight through a medium came to.
enum Flight {
    /// It scattered in the medium (the path goes on from there).
    Scattered,
    /// It reached the surface it was traced to (or left the scene).
    ReachedSurface,
    /// The path ends.
    Ended,
}

/// One volumetric path between its events: what `li` advances.
struct VolPath<'a> {
    s: &'a VolpathSettings,
    scene: &'a World,
    max_depth: u32,
    /// Whether shadow rays must look for passages (only where there are any).
    passable: bool,
    /// The radiance gathered so far.
    l: Rgb,
    throughput: Rgb,
    /// Undoes the 1/eta^2 radiance scaling for Russian roulette, as in `path`.
    eta_scale: f32,
    ray: Ray,
    medium: Option<u32>,
    /// The last scattering event: its direction density, whether it was delta (or could not
    /// have been sampled by lights), and where it was.
    prev: PrevEvent,
    /// Scattering events so far.
    depth: u32,
    passages: u32,
    /// The hero channel, and each channel's path density over their mean (`throughput` is
    /// the path contribution over that mean).
    channel: usize,
    density_ratio: Rgb,
}

impl<'a> VolPath<'a> {
    fn new(s: &'a VolpathSettings, scene: &'a World, max_depth: u32, camera_ray: &Ray, rng: &mut Sampler) -> Self {
        let channel = if scene.media.is_empty() { 0 } else { ((rng.next_f32() * 3.0) as usize).min(2) };
        VolPath {
            s,
            scene,
            max_depth,
            passable: scene.has_masks || scene.has_passage_materials || !scene.media.is_empty(),
            l: Rgb::BLACK,
            throughput: Rgb::WHITE,
            eta_scale: 1.0,
            ray: *camera_ray,
            medium: scene.camera_medium,
            prev: PrevEvent { pdf: 1.0, delta: true, p: camera_ray.origin },
            depth: 0,
            passages: 0,
            channel,
            density_ratio: Rgb::WHITE,
        }
    }

    /// Counts a passage; false when the path has made too many.
    fn pass(&mut self) -> bool {
        self.passages += 1;
        self.passages <= MAX_PASSAGES
    }

    /// The flight through medium `mi` up to `t_max`: a free flight drawn on the hero
    /// channel, and where it scatters, light sampling and a phase-function sample.
    fn through_medium(&mut self, mi: u32, t_max: f32, rng: &mut Sampler, c: &mut Counters) -> Flight {
        let m = &self.scene.media[mi as usize];
        let flight = sample_distance(m, &self.ray, t_max, self.channel, rng);
        let mean = (self.density_ratio * flight.density).average();
        if !(mean > 0.0) {
            return Flight::Ended;
        }
        self.throughput = self.throughput * flight.value / mean;
        self.density_ratio = self.density_ratio * flight.density / mean;
        if self.throughput.is_black() {
            return Flight::Ended;
        }
        let Some(t) = flight.t else { return Flight::ReachedSurface };
        self.depth += 1;
        if self.depth >= self.max_depth {
            return Flight::Ended;
        }
        let p = self.ray.at(t);
        let wo = -self.ray.dir;
        if m.sample_emitters {
            let light = light_at_medium_point(self.scene, m, p, wo, self.medium, self.passable, rng, c);
            self.l += self.throughput * light;
        }
        let ps = m.phase.sample(wo, rng.next_2d());
        self.prev.pdf = ps.pdf;
        // Without light sampling here, lights the phase sample reaches count fully.
        self.prev.delta = !m.sample_emitters;
        self.prev.p = p;
        self.ray = Ray::new(p, ps.wi);
        if !roulette(self.s, self.depth, &mut self.throughput, self.eta_scale, rng) {
            return Flight::Ended;
        }
        Flight::Scattered
    }

    /// The ray left the scene: what the environment sends back along it.
    fn escape(&mut self) {
        if !(self.depth == 0 && self.s.hide_emitters) {
            add_environment(
                self.scene,
                &self.ray,
                Strategy::Mis,
                &self.prev,
                self.throughput,
                &mut self.l,
                &mut Unobserved,
            );
        }
    }

    /// The path at a surface: emission, passages (hidden emitters, masks, null and thin
    /// boundaries), light sampling and a BSDF sample; false when the path ends.
    fn at_surface(&mut self, hit: &Hit, rng: &mut Sampler, c: &mut Counters) -> bool {
        let scene = self.scene;
        let si = scene.interaction(&self.ray, hit);
        let boundary = scene.instances[si.instance as usize].media;

        if let Some(li_idx) = si.light {
            if self.depth == 0 && self.s.hide_emitters {
                // Looked through, as `path` looks through hidden emitters.
                if !self.pass() {
                    return false;
                }
                self.ray = spawn_ray(&si, self.ray.dir);
                return true;
            }
            add_emitted(
                scene,
                &si,
                &self.ray,
                li_idx,
                Strategy::Mis,
                &self.prev,
                self.throughput,
                &mut self.l,
                &mut Unobserved,
            );
        }

        // A masked surface lets the path through unscattered with probability 1 - opacity:
        // a passage, as in `path` (depth and the MIS state stay those of the last event).
        if scene.has_masks {
            let o = opacity(scene, &si, self.ray.dir);
            if o < 1.0 && rng.next_f32() >= o {
                if !self.pass() {
                    return false;
                }
                self.medium = boundary.medium_after(self.ray.dir.dot(si.ng), self.medium);
                self.ray = spawn_ray(&si, self.ray.dir);
                return true;
            }
        }
        self.scatter_at_surface(&si, rng, c)
    }

    /// Light sampling and a BSDF sample at a surface; false when the path ends.
    fn scatter_at_surface(&mut self, si: &SurfaceInteraction, rng: &mut Sampler, c: &mut Counters) -> bool {
        let scene = self.scene;
        let boundary = scene.instances[si.instance as usize].media;
        let wo_world = -self.ray.dir;
        let (bsdf, frame) = shading(scene, si, wo_world);
        let wo = frame.to_local(wo_world);

        // Next-event estimation, when one more segment is allowed.
        if !bsdf.is_delta() && self.depth + 1 < self.max_depth {
            let at = SurfacePoint { si, bsdf: &bsdf, frame: &frame, wo, medium: self.medium, passable: self.passable };
            add_light_at_surface(scene, &at, self.throughput, &mut self.l, rng, c);
        }

        let u_lobe = rng.next_f32();
        let u = rng.next_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            return false;
        };
        if bs.weight.is_black() {
            return false;
        }
        let passage = is_passage(&bsdf.bsdf, wo, &bs);
        if !passage && self.depth + 1 >= self.max_depth {
            return false;
        }
        self.throughput *= bs.weight;
        let wi_world = frame.to_world(bs.wi);
        self.medium = boundary.medium_after(wi_world.dot(si.ng), self.medium);
        self.ray = spawn_ray(si, wi_world);
        if passage {
            return self.pass();
        }
        self.depth += 1;
        self.eta_scale *= bs.eta * bs.eta;
        self.prev = PrevEvent { pdf: bs.pdf, delta: bs.delta, p: si.p };
        roulette(self.s, self.depth, &mut self.throughput, self.eta_scale, rng)
    }
}

/// A surface scattering point as next-event estimation sees it.
struct SurfacePoint<'a> {
    si: &'a SurfaceInteraction,
    bsdf: &'a ShadedBsdf,
    frame: &'a Frame,
    wo: Vec3,
    /// The medium the path arrived in.
    medium: Option<u32>,
    /// Whether shadow rays must look for passages.
    passable: bool,
}

/// Adds to `l` one light sample's contribution at a surface point times `throughput`,
/// MIS-weighted against BSDF sampling.
fn add_light_at_surface(
    scene: &World,
    at: &SurfacePoint,
    throughput: Rgb,
    l: &mut Rgb,
    rng: &mut Sampler,
    c: &mut Counters,
) {
    let (si, bsdf, wo) = (at.si, at.bsdf, at.wo);
    let Some((ls, pick_pmf, _)) = sample_light(scene, si.p, rng) else {
        return;
    };
    let wi = at.frame.to_local(ls.wi);
    let f = bsdf.eval(wo, wi);
    if f.is_black() {
        return;
    }
    let boundary = scene.instances[si.instance as usize].media;
    let start = boundary.medium_after(ls.wi.dot(si.ng), at.medium);
    let tr = transmittance(scene, shadow_ray(si, ls.wi, ls.dist), start, at.passable, rng, c);
    if tr.is_black() {
        return;
    }
    let light_pdf = pick_pmf * ls.pdf;
    let w = if ls.delta { 1.0 } else { power_heuristic(light_pdf, bsdf.pdf(wo, wi)) };
    *l += throughput * f * ls.radiance * tr * (w / light_pdf);
}

/// Russian roulette from `rr_depth` scattering events on; false when the path ends.
#[inline]
fn roulette(s: &VolpathSettings, depth: u32, throughput: &mut Rgb, eta_scale: f32, rng: &mut Sampler) -> bool {
    depth < s.rr_depth || survives_roulette(throughput, eta_scale, None, rng)
}

/// Next-event estimation at a scattering point `p` in medium `m` (index `medium`).
#[allow(clippy::too_many_arguments)]
fn light_at_medium_point(
    scene: &World,
    m: &Medium,
    p: Vec3,
    wo: Vec3,
    medium: Option<u32>,
    passable: bool,
    rng: &mut Sampler,
    c: &mut Counters,
) -> Rgb {
    let Some((ls, pick_pmf, _)) = sample_light(scene, p, rng) else {
        return Rgb::BLACK;
    };
    let phase = m.phase.eval(wo, ls.wi);
    if !(phase > 0.0) {
        return Rgb::BLACK;
    }
    let ray = if ls.dist.is_finite() { Ray::segment(p, ls.wi, ls.dist * (1.0 - 1e-4)) } else { Ray::new(p, ls.wi) };
    let tr = transmittance(scene, ray, medium, passable, rng, c);
    if tr.is_black() {
        return Rgb::BLACK;
    }
    let light_pdf = pick_pmf * ls.pdf;
    let w = if ls.delta { 1.0 } else { power_heuristic(light_pdf, phase) };
    ls.radiance * tr * (phase * w / light_pdf)
}

/// The fraction of light that travels along the shadow ray `ray`, which starts in `medium`:
/// zero when a surface that is not a passage blocks it, else the product of the media's
/// transmittances and the passages' transmission.
fn transmittance(
    scene: &World,
    mut ray: Ray,
    mut medium: Option<u32>,
    passable: bool,
    rng: &mut Sampler,
    c: &mut Counters,
) -> Rgb {
    c.shadow_rays += 1;
    if !passable {
        return if scene.occluded(&ray) { Rgb::BLACK } else { Rgb::WHITE };
    }
    let mut tr = Rgb::WHITE;
    for _ in 0..=MAX_PASSAGES {
        let hit = scene.intersect(&ray);
        if let Some(m) = medium {
            tr *= scene.media[m as usize].transmittance_along(&ray, hit.map_or(ray.t_max, |h| h.t), rng);
        }
        let Some(hit) = hit else {
            return tr;
        };
        if tr.is_black() {
            return tr;
        }
        let si = scene.interaction(&ray, &hit);
        let (bsdf, frame) = shading(scene, &si, -ray.dir);
        let through = bsdf.bsdf.passage_transmission(frame.to_local(-ray.dir));
        // A mask passes 1 - opacity unscattered; the surface beneath it passes its share
        // of the rest if it is itself a passage.
        let o = if scene.has_masks { opacity(scene, &si, ray.dir) } else { 1.0 };
        let pass = match through {
            Some(t) if o < 1.0 => t * o + Rgb::splat(1.0 - o),
            Some(t) => t,
            None if o < 1.0 => Rgb::splat(1.0 - o),
            None => return Rgb::BLACK,
        };
        tr *= pass;
        if tr.is_black() {
            return tr;
        }
        medium = scene.instances[si.instance as usize].media.medium_after(ray.dir.dot(si.ng), medium);
        ray = next_segment(&si, &ray, hit.t);
        c.shadow_rays += 1;
    }
    Rgb::BLACK
}

/// The rest of a shadow ray after it passed a surface at distance `t`.
fn next_segment(si: &SurfaceInteraction, ray: &Ray, t: f32) -> Ray {
    let o = offset_origin(si.p, si.ng, ray.dir);
    if !ray.t_max.is_finite() {
        return Ray::new(o, ray.dir);
    }
    let target = ray.at(ray.t_max);
    let to_target = target - o;
    let len = to_target.length();
    if !(len > 0.0) || to_target.dot(ray.dir) <= 0.0 || t >= ray.t_max {
        return Ray::segment(o, ray.dir, 0.0);
    }
    Ray::segment(o, to_target / len, len)
}

/// Whether a BSDF sample went straight through a passage (not a scattering event).
fn is_passage(bsdf: &Bsdf, wo: Vec3, bs: &BsdfSample) -> bool {
    bsdf.passage_transmission(wo).is_some() && bs.delta && bs.wi == -wo
}
