//! The smooth conductor's vertex in lanes: the mirror direction, the conductor Fresnel term
//! per channel and the next ray, as `PathState::scatter` computes them for
//! `Bsdf::Conductor` (a delta BSDF: no light sample, no shadow ray).

use super::lane_math::*;
use super::{get3, put3, Column, Column3, LaneIsa};
use crate::describe::PathSettings;
use crate::integrators::estimators::PrevEvent;
use crate::integrators::path::PathState;
use crate::materials::Conductor;
#[cfg(target_arch = "x86_64")]
use crate::math::lanes::{Avx2x8, Avx512x16};
use crate::math::lanes::{Lanes, One, MAX_LANES};
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// Up to [`MAX_LANES`] smooth-conductor vertices, one per lane.
#[derive(Clone, Copy, Default)]
pub(crate) struct MirrorChunk {
    pub len: usize,
    pub path: [u32; MAX_LANES],
    // In: the vertex and the conductor.
    pub(super) dir: Column3,
    pub(super) p: Column3,
    pub(super) ng: Column3,
    pub(super) n: Column3,
    pub(super) s: Column3,
    pub(super) t: Column3,
    pub(super) eta: Column3,
    pub(super) k: Column3,
    pub(super) specular: Column3,
    // Out: the next ray and the sample's weight (`sampled` 0 where the path ends).
    pub(super) sampled: Column,
    pub(super) weight: Column3,
    pub(super) next_origin: Column3,
    pub(super) next_dir: Column3,
}

impl MirrorChunk {
    pub fn is_full(&self, lanes: usize) -> bool {
        self.len >= lanes
    }

    /// Adds a path's vertex as the next lane, drawing the BSDF's random numbers from `rng` as
    /// `PathState::scatter` does (a lobe number and a square, unused by a mirror).
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        mirror: &Conductor,
        rng: &mut Sampler,
    ) {
        let i = self.len;
        self.len += 1;
        self.path[i] = path_index;
        let d = path.ray.dir;
        put3(&mut self.dir, i, [d.x, d.y, d.z]);
        put3(&mut self.p, i, [si.p.x, si.p.y, si.p.z]);
        put3(&mut self.ng, i, [si.ng.x, si.ng.y, si.ng.z]);
        put3(&mut self.n, i, [frame.n.x, frame.n.y, frame.n.z]);
        put3(&mut self.s, i, [frame.s.x, frame.s.y, frame.s.z]);
        put3(&mut self.t, i, [frame.t.x, frame.t.y, frame.t.z]);
        put3(&mut self.eta, i, mirror.eta.to_array());
        put3(&mut self.k, i, mirror.k.to_array());
        put3(&mut self.specular, i, mirror.specular.to_array());
        let _u_lobe = rng.next_f32();
        let _u = rng.next_2d();
    }

    /// Runs the kernel over the chunk's lanes on `isa`.
    pub fn run(&mut self, isa: LaneIsa) {
        match isa {
            LaneIsa::One => mirror_chunk(One, self),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `LaneIsa::detect` chose AVX2 only where `Avx2x8::new` found it.
            LaneIsa::Avx2 => unsafe { mirror_chunk_avx2(self) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `LaneIsa::detect` chose AVX-512 only where `Avx512x16::new` found it.
            LaneIsa::Avx512 => unsafe { mirror_chunk_avx512(self) },
        }
    }

    /// Writes lane `i`'s results into its path, as the end of `PathState::scatter` does.
    pub fn finish(&self, i: usize, path: &mut PathState, s: &PathSettings, rng: &mut Sampler) {
        if self.sampled[i] == 0.0 {
            return;
        }
        let weight = Rgb::from_array(get3(&self.weight, i).to_array());
        let prev = PrevEvent { pdf: 1.0, delta: true, p: get3(&self.p, i) };
        let ray = Ray::new(get3(&self.next_origin, i), get3(&self.next_dir, i));
        path.go_on(s, weight, 1.0, prev, ray, rng);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn mirror_chunk_avx2(chunk: &mut MirrorChunk) {
    // SAFETY: this function's contract is that the CPU has AVX2.
    mirror_chunk(unsafe { Avx2x8::new_unchecked() }, chunk)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
unsafe fn mirror_chunk_avx512(chunk: &mut MirrorChunk) {
    // SAFETY: this function's contract is that the CPU has AVX-512F.
    mirror_chunk(unsafe { Avx512x16::new_unchecked() }, chunk)
}

#[inline(always)]
fn mirror_chunk<L: Lanes>(l: L, c: &mut MirrorChunk) {
    let mut base = 0;
    while base < c.len {
        mirror_lanes(l, c, base);
        base += L::N;
    }
}

/// One vector of the chunk's lanes, from `base`: `Conductor::sample`, then `frame.to_world`
/// and `spawn_ray`.
#[inline(always)]
fn mirror_lanes<L: Lanes>(l: L, c: &mut MirrorChunk, base: usize) {
    let zero = l.splat(0.0);
    let wo_world = neg3(l, load3(l, &c.dir, base));
    let (s, t, n) = (load3(l, &c.s, base), load3(l, &c.t, base), load3(l, &c.n, base));
    // `frame.to_local(wo)`.
    let wo = V3 { x: dot(l, wo_world, s), y: dot(l, wo_world, t), z: dot(l, wo_world, n) };
    let (eta, k, spec) = (load3(l, &c.eta, base), load3(l, &c.k, base), load3(l, &c.specular, base));
    let weight = V3 {
        x: l.mul(spec.x, fresnel_conductor(l, wo.z, eta.x, k.x)),
        y: l.mul(spec.y, fresnel_conductor(l, wo.z, eta.y, k.y)),
        z: l.mul(spec.z, fresnel_conductor(l, wo.z, eta.z, k.z)),
    };
    let black = l.and(l.and(l.eq(weight.x, zero), l.eq(weight.y, zero)), l.eq(weight.z, zero));
    let sampled = l.and_not(l.not(l.le(wo.z, zero)), black);
    l.store(l.select(sampled, l.splat(1.0), zero), &mut c.sampled[base..]);
    store3(l, weight, &mut c.weight, base);
    // `reflect_local(wo)`, then `frame.to_world`.
    let wi = V3 { x: l.neg(wo.x), y: l.neg(wo.y), z: wo.z };
    let wi_world = add3(l, add3(l, scale(l, s, wi.x), scale(l, t, wi.y)), scale(l, n, wi.z));
    store3(l, wi_world, &mut c.next_dir, base);
    let (p, ng) = (load3(l, &c.p, base), load3(l, &c.ng, base));
    store3(l, offset_origin(l, p, ng, wi_world), &mut c.next_origin, base);
}

/// `bsdf::fresnel_conductor` for one channel, in its operations.
#[inline(always)]
fn fresnel_conductor<L: Lanes>(l: L, cos_i: L::F, eta: L::F, k: L::F) -> L::F {
    let (zero, one, half) = (l.splat(0.0), l.splat(1.0), l.splat(0.5));
    // `cos_i.clamp(0.0, 1.0)`: NaN stays NaN (`Lanes::max`/`min` would make it a bound).
    let c = l.select(l.lt(cos_i, zero), zero, l.select(l.gt(cos_i, one), one, cos_i));
    let c2 = l.mul(c, c);
    let s2 = l.sub(one, c2);
    let eta2 = l.mul(eta, eta);
    let k2 = l.mul(k, k);
    let t0 = l.sub(l.sub(eta2, k2), s2);
    // `.max(0.0)` of sums that are never -0.0: `Lanes::max` agrees with `f32::max` (0 on NaN).
    let a2b2 = l.sqrt(l.max(l.add(l.mul(t0, t0), l.mul(l.mul(l.splat(4.0), eta2), k2)), zero));
    let t1 = l.add(a2b2, c2);
    let a = l.sqrt(l.max(l.mul(half, l.add(a2b2, t0)), zero));
    let t2 = l.mul(l.mul(l.splat(2.0), c), a);
    let rs = l.div(l.sub(t1, t2), l.add(t1, t2));
    let t3 = l.add(l.mul(c2, a2b2), l.mul(s2, s2));
    let t4 = l.mul(t2, s2);
    let rp = l.div(l.mul(rs, l.sub(t3, t4)), l.add(t3, t4));
    let r = l.mul(half, l.add(rp, rs));
    l.select(l.lt(l.abs(r), l.splat(f32::INFINITY)), r, one)
}
