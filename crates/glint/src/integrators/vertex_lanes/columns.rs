//! The columns every chunk shares: the vertex (ray direction, point, geometric normal, shading
//! frame) and, for BSDFs that are not delta, next-event estimation's light sample and what
//! the kernel makes of it (the shadow ray, its contribution and MIS weight).

use super::lane_math::*;
use super::{flag, get3, put3, Column, Column3};
use crate::describe::PathSettings;
use crate::integrators::estimators::PrevEvent;
use crate::integrators::path::{PathState, ShadowQuery};
use crate::integrators::Counters;
use crate::lights::LightSample;
use crate::math::lanes::{Lanes, MAX_LANES};
use crate::math::{Frame, Ray, Rgb, Vec3};
use crate::sampling::Sampler;

/// One vertex per lane: the ray that arrived, the point, the geometric normal and the
/// shading frame.
#[derive(Clone, Copy, Default)]
pub(crate) struct VertexColumns {
    pub dir: Column3,
    pub p: Column3,
    pub ng: Column3,
    pub n: Column3,
    pub s: Column3,
    pub t: Column3,
}

impl VertexColumns {
    /// Lane `i`'s ray direction and point.
    pub fn put_ray(&mut self, i: usize, dir: Vec3, p: Vec3) {
        put3(&mut self.dir, i, [dir.x, dir.y, dir.z]);
        put3(&mut self.p, i, [p.x, p.y, p.z]);
    }

    /// Lane `i`'s geometric normal and shading frame.
    pub fn put_frame(&mut self, i: usize, ng: Vec3, frame: &Frame) {
        put3(&mut self.ng, i, [ng.x, ng.y, ng.z]);
        put3(&mut self.n, i, [frame.n.x, frame.n.y, frame.n.z]);
        put3(&mut self.s, i, [frame.s.x, frame.s.y, frame.s.z]);
        put3(&mut self.t, i, [frame.t.x, frame.t.y, frame.t.z]);
    }

    /// `frame.to_local(-ray.dir)` in lanes.
    #[inline(always)]
    pub fn wo_local<L: Lanes>(&self, l: L, base: usize) -> V3<L::F> {
        self.local(l, base, neg3(l, load3(l, &self.dir, base)))
    }

    /// `frame.to_local(v)` in lanes.
    #[inline(always)]
    pub fn local<L: Lanes>(&self, l: L, base: usize, v: V3<L::F>) -> V3<L::F> {
        let (s, t, n) = (load3(l, &self.s, base), load3(l, &self.t, base), load3(l, &self.n, base));
        V3 { x: dot(l, v, s), y: dot(l, v, t), z: dot(l, v, n) }
    }

    /// `frame.to_world(v)` in lanes.
    #[inline(always)]
    pub fn world<L: Lanes>(&self, l: L, base: usize, v: V3<L::F>) -> V3<L::F> {
        let (s, t, n) = (load3(l, &self.s, base), load3(l, &self.t, base), load3(l, &self.n, base));
        add3(l, add3(l, scale(l, s, v.x), scale(l, t, v.y)), scale(l, n, v.z))
    }

    /// `spawn_ray(si, wi)`'s origin in lanes.
    #[inline(always)]
    pub fn spawn_origin<L: Lanes>(&self, l: L, base: usize, wi: V3<L::F>) -> V3<L::F> {
        offset_origin(l, load3(l, &self.p, base), load3(l, &self.ng, base), wi)
    }
}

/// Next-event estimation per lane: in, the light sample `PathState::scatter` drew
/// (`has_light` 0 where there is none); out, the shadow ray (`shadow` 0 where there is none).
#[derive(Clone, Copy, Default)]
pub(crate) struct NextEventColumns {
    pub has_light: Column,
    pub light_wi: Column3,
    pub light_dist: Column,
    pub light_radiance: Column3,
    pub light_pdf: Column,
    pub light_delta: Column,
    pub shadow: Column,
    pub shadow_origin: Column3,
    pub shadow_dir: Column3,
    pub shadow_t_max: Column,
    pub contribution: Column3,
    pub mis_weight: Column,
}

impl NextEventColumns {
    /// Lane `i`'s light sample and the light's probability of being picked.
    pub fn put(&mut self, i: usize, light: Option<(LightSample, f32)>) {
        match light {
            Some((ls, pick_pmf)) => {
                self.has_light[i] = 1.0;
                put3(&mut self.light_wi, i, [ls.wi.x, ls.wi.y, ls.wi.z]);
                self.light_dist[i] = ls.dist;
                put3(&mut self.light_radiance, i, ls.radiance.to_array());
                self.light_pdf[i] = pick_pmf * ls.pdf;
                self.light_delta[i] = flag(ls.delta);
            }
            None => {
                // Finite values in the unused lanes: nothing is computed from them.
                self.has_light[i] = 0.0;
                put3(&mut self.light_wi, i, [0.0, 0.0, 1.0]);
                self.light_dist[i] = 1.0;
                put3(&mut self.light_radiance, i, [0.0; 3]);
                self.light_pdf[i] = 1.0;
                self.light_delta[i] = 0.0;
            }
        }
    }

    /// Leaves lane `i`'s shadow ray, if it has one, in its path.
    pub fn finish(&self, i: usize, path: &mut PathState, c: &mut Counters) {
        if self.shadow[i] == 0.0 {
            return;
        }
        path.leave_shadow_ray(
            ShadowQuery {
                ray: Ray::segment(get3(&self.shadow_origin, i), get3(&self.shadow_dir, i), self.shadow_t_max[i]),
                contribution: Rgb::from_array(get3(&self.contribution, i).to_array()),
                mis_weight: self.mis_weight[i],
                light_pdf: self.light_pdf[i],
            },
            c,
        );
    }

    /// What `PathState::scatter` does with the light sample once it has the BSDF's value `f`
    /// and density `bsdf_pdf` towards it: the MIS weight (`power_heuristic`, 1 for a delta
    /// light or `light_only`), the contribution `throughput * f * radiance`, and the shadow ray
    /// (`shadow_ray(si, ls.wi, ls.dist)`) where there is a light and `f` is not black.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn lanes<L: Lanes>(
        &mut self,
        l: L,
        base: usize,
        v: &VertexColumns,
        throughput: V3<L::F>,
        f: V3<L::F>,
        bsdf_pdf: L::F,
        light_only: bool,
    ) {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let f_black = black3(l, f);
        let light_pdf = l.load(&self.light_pdf[base..]);
        // `power_heuristic(light_pdf, bsdf_pdf)`.
        let a = l.mul(light_pdf, light_pdf);
        let b = l.mul(bsdf_pdf, bsdf_pdf);
        let sum = l.add(a, b);
        let heuristic = l.select(l.eq(a, l.splat(f32::INFINITY)), one, l.select(l.eq(sum, zero), zero, l.div(a, sum)));
        let delta = l.gt(l.load(&self.light_delta[base..]), zero);
        let mis = if light_only { one } else { l.select(delta, one, heuristic) };
        let has_light = l.gt(l.load(&self.has_light[base..]), zero);
        let shadow = l.and_not(has_light, f_black);
        let radiance = load3(l, &self.light_radiance, base);
        store3(l, mul3(l, mul3(l, throughput, f), radiance), &mut self.contribution, base);
        l.store(mis, &mut self.mis_weight[base..]);
        l.store(l.select(shadow, one, zero), &mut self.shadow[base..]);
        // `shadow_ray(si, ls.wi, ls.dist)`.
        let light_wi = load3(l, &self.light_wi, base);
        let p = load3(l, &v.p, base);
        let dist = l.load(&self.light_dist[base..]);
        let o = offset_origin(l, p, load3(l, &v.ng, base), light_wi);
        let to_target = sub3(l, add3(l, p, scale(l, light_wi, dist)), o);
        let len = l.sqrt(dot(l, to_target, to_target));
        let toward = scale(l, to_target, l.div(one, len));
        let finite = l.lt(l.abs(dist), l.splat(f32::INFINITY));
        store3(l, o, &mut self.shadow_origin, base);
        store3(l, select3(l, finite, toward, light_wi), &mut self.shadow_dir, base);
        let t_max = l.mul(len, l.splat(1.0 - 1e-4));
        l.store(l.select(finite, t_max, l.splat(f32::INFINITY)), &mut self.shadow_t_max[base..]);
    }
}

/// The sampled continuation per lane, what `PathState::scatter` hands to `go_on`: `sampled`
/// 0 where the path ends; the sample's weight, density, kind (`delta` 1 or 0) and eta; the
/// next ray. A new chunk's lanes have eta 1 and are not delta, so the kernels of BSDFs that
/// never refract or sample a delta lobe leave those two alone.
#[derive(Clone, Copy)]
pub(crate) struct NextRayColumns {
    pub sampled: Column,
    pub weight: Column3,
    pub pdf: Column,
    pub delta: Column,
    pub eta: Column,
    pub origin: Column3,
    pub dir: Column3,
}

impl Default for NextRayColumns {
    fn default() -> NextRayColumns {
        let zero = [0.0; MAX_LANES];
        NextRayColumns {
            sampled: zero,
            weight: [zero; 3],
            pdf: zero,
            delta: zero,
            eta: [1.0; MAX_LANES],
            origin: [zero; 3],
            dir: [zero; 3],
        }
    }
}

impl NextRayColumns {
    /// Lane `i`'s continuation into its path from the point `p`, as the end of
    /// `PathState::scatter` does (nothing where the path ends).
    pub fn finish(&self, i: usize, path: &mut PathState, s: &PathSettings, rng: &mut Sampler, p: Vec3) {
        if self.sampled[i] == 0.0 {
            return;
        }
        let weight = Rgb::from_array(get3(&self.weight, i).to_array());
        let prev = PrevEvent { pdf: self.pdf[i], delta: self.delta[i] != 0.0, p };
        let ray = Ray::new(get3(&self.origin, i), get3(&self.dir, i));
        path.go_on(s, weight, self.eta[i], prev, ray, rng);
    }
}

/// Whether a BSDF reads the lobe number `PathState::scatter` draws for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Lobe {
    Read,
    Unread,
}

/// What every chunk holds besides its BSDF's parameters: which path each lane is, its vertex,
/// throughput, light sample and the BSDF's random numbers in, the continuation out.
#[derive(Clone, Copy, Default)]
pub(crate) struct SharedColumns {
    pub len: usize,
    /// Which path each lane is (the caller's index).
    pub path: [u32; MAX_LANES],
    pub v: VertexColumns,
    pub throughput: Column3,
    pub ne: NextEventColumns,
    pub u_lobe: Column,
    pub u: [Column; 2],
    pub next: NextRayColumns,
}

impl SharedColumns {
    /// Adds path `index`'s vertex at `p` as the next lane (its frame is the caller's to put)
    /// with the light sample the caller drew, then draws the BSDF's random numbers from `rng`
    /// as `PathState::scatter` draws them after the light sample: the lobe number (kept only
    /// where the BSDF reads it: `Lobe::Unread` leaves its value unused, so the compiler drops
    /// its hashing while the sampler still moves past it), then the square. Returns the lane.
    #[inline(always)]
    pub fn push(
        &mut self,
        index: u32,
        path: &PathState,
        p: Vec3,
        light: Option<(LightSample, f32)>,
        lobe: Lobe,
        rng: &mut Sampler,
    ) -> usize {
        let i = self.len;
        self.len += 1;
        self.path[i] = index;
        self.v.put_ray(i, path.ray.dir, p);
        put3(&mut self.throughput, i, path.throughput().to_array());
        self.ne.put(i, light);
        let u_lobe = rng.next_f32();
        if lobe == Lobe::Read {
            self.u_lobe[i] = u_lobe;
        }
        let u = rng.next_2d();
        self.u[0][i] = u[0];
        self.u[1][i] = u[1];
        i
    }

    /// Stores the continuation of the lanes from `base` as the end of `PathState::scatter`
    /// makes it: the lanes in `kept` whose `weight` is not black (`scatter` ends a path on a
    /// black weight) go on along `wi` (in the shading frame) from the vertex, the sample's
    /// density `pdf`. Eta and the delta flag are the kernel's to store where they vary.
    #[inline(always)]
    pub fn store_next<L: Lanes>(&mut self, l: L, base: usize, kept: L::M, weight: V3<L::F>, pdf: L::F, wi: V3<L::F>) {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let sampled = l.and_not(kept, black3(l, weight));
        l.store(l.select(sampled, one, zero), &mut self.next.sampled[base..]);
        store3(l, weight, &mut self.next.weight, base);
        l.store(pdf, &mut self.next.pdf[base..]);
        // `frame.to_world(wi)`, then `spawn_ray`.
        let wi_world = self.v.world(l, base, wi);
        store3(l, wi_world, &mut self.next.dir, base);
        store3(l, self.v.spawn_origin(l, base, wi_world), &mut self.next.origin, base);
    }

    /// Lane `i`'s shadow ray and continuation into its path, as the end of
    /// `PathState::scatter` does.
    pub fn finish(&self, i: usize, path: &mut PathState, s: &PathSettings, rng: &mut Sampler, c: &mut Counters) {
        self.ne.finish(i, path, c);
        self.next.finish(i, path, s, rng, get3(&self.v.p, i));
    }
}
