//! The vertex of the smooth (delta) BSDFs in lanes, as `PathState::scatter` computes it for
//! `Bsdf::Conductor` (the mirror direction, the conductor Fresnel term per channel) and
//! `Bsdf::Dielectric` (the dielectric Fresnel term, reflection or refraction chosen by the
//! lobe number): no light sample, no shadow ray, the next ray.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::{put3, Column, Column3};
use crate::integrators::path::PathState;
use crate::materials::{Conductor, Dielectric};
use crate::math::lanes::Lanes;
use crate::math::Frame;
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// A smooth BSDF the chunk takes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Smooth {
    Conductor(Conductor),
    Dielectric(Dielectric),
}

/// Up to [`MAX_LANES`] vertices of smooth BSDFs, one per lane.
#[derive(Clone, Copy, Default)]
pub(crate) struct SmoothChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    // In: the BSDF.
    /// 1 for a dielectric, 0 for a conductor.
    pub(super) glass: Column,
    /// The conductor's eta, k and specular reflectance; the dielectric's eta (in the first
    /// channel of `eta`), reflectance (`specular`) and transmittance.
    pub(super) eta: Column3,
    pub(super) k: Column3,
    pub(super) specular: Column3,
    pub(super) transmit: Column3,
}

impl SmoothChunk {
    /// Adds a path's vertex as the next lane, drawing the BSDF's random numbers from `rng` as
    /// `PathState::scatter` does (a lobe number, which the dielectric reads, and a square).
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        bsdf: Smooth,
        rng: &mut Sampler,
    ) {
        // A delta BSDF: no light sample.
        let i = self.shared.push(path_index, path, si.p, None, Lobe::Read, rng);
        self.shared.v.put_frame(i, si.ng, frame);
        match bsdf {
            Smooth::Conductor(m) => {
                self.glass[i] = 0.0;
                put3(&mut self.eta, i, m.eta.to_array());
                put3(&mut self.k, i, m.k.to_array());
                put3(&mut self.specular, i, m.specular.to_array());
                put3(&mut self.transmit, i, [0.0; 3]);
            }
            Smooth::Dielectric(d) => {
                self.glass[i] = 1.0;
                put3(&mut self.eta, i, [d.eta, 1.0, 1.0]);
                put3(&mut self.k, i, [0.0; 3]);
                put3(&mut self.specular, i, d.reflect.to_array());
                put3(&mut self.transmit, i, d.transmit.to_array());
            }
        }
    }
}

lane_kernel!(SmoothChunk, smooth_lanes);

/// One vector of the chunk's lanes, from `base`: `Conductor::sample` or `Dielectric::sample`
/// (each computed only where a lane has it), then `frame.to_world` and `spawn_ray`.
#[inline(always)]
fn smooth_lanes<L: Lanes>(l: L, c: &mut SmoothChunk, base: usize, _live: u32, _light_only: bool) {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let wo = c.shared.v.wo_local(l, base);
    let (eta, spec) = (load3(l, &c.eta, base), load3(l, &c.specular, base));
    let glass = l.gt(l.load(&c.glass[base..]), zero);
    let mirror = l.not(glass);
    let reflected = V3 { x: l.neg(wo.x), y: l.neg(wo.y), z: wo.z };
    // The conductor: the mirror direction, where `wo` is above the surface.
    let (mut wi, mut weight, mut sampled, mut eta_out) = (reflected, spec, l.not(l.le(wo.z, zero)), one);
    if l.bits(mirror) != 0 {
        let k = load3(l, &c.k, base);
        weight = V3 {
            x: l.mul(spec.x, fresnel_conductor(l, wo.z, eta.x, k.x)),
            y: l.mul(spec.y, fresnel_conductor(l, wo.z, eta.y, k.y)),
            z: l.mul(spec.z, fresnel_conductor(l, wo.z, eta.z, k.z)),
        };
    }
    if l.bits(glass) != 0 {
        let fr = fresnel_dielectric(l, wo.z, eta.x);
        let reflect = l.lt(l.load(&c.shared.u_lobe[base..]), fr.reflectance);
        // `refract_local(wo, fr)`, and the radiance scale 1 / eta_ti².
        let k = l.div(l.splat(-1.0), fr.eta_ti);
        let refracted = V3 { x: l.mul(wo.x, k), y: l.mul(wo.y, k), z: fr.cos_t };
        let transmit = load3(l, &c.transmit, base);
        let scaled = scale(l, transmit, l.div(one, l.mul(fr.eta_ti, fr.eta_ti)));
        wi = select3(l, glass, select3(l, reflect, reflected, refracted), wi);
        weight = select3(l, glass, select3(l, reflect, spec, scaled), weight);
        eta_out = l.select(glass, l.select(reflect, one, fr.eta_ti), eta_out);
        // `Dielectric::sample` always samples.
        sampled = l.or(glass, l.and(mirror, sampled));
    }
    // A delta sample of density 1.
    c.shared.store_next(l, base, sampled, weight, one, wi);
    l.store(one, &mut c.shared.next.delta[base..]);
    l.store(eta_out, &mut c.shared.next.eta[base..]);
}

/// `bsdf::DielectricFresnel` over lanes.
pub(super) struct Fresnel<F> {
    pub reflectance: F,
    pub cos_t: F,
    pub eta_ti: F,
}

/// `bsdf::fresnel_dielectric`, in its operations and branches (as selects).
#[inline(always)]
pub(super) fn fresnel_dielectric<L: Lanes>(l: L, cos_i: L::F, eta: L::F) -> Fresnel<L::F> {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let front = l.ge(cos_i, zero);
    let eta_ti = l.select(front, eta, l.div(one, eta));
    let ci = l.abs(cos_i);
    let sin2_t = l.div(l.sub(one, l.mul(ci, ci)), l.mul(eta_ti, eta_ti));
    let total = l.ge(sin2_t, one);
    // `(1 - sin2_t).max(0.0)`: never -0.0, and `Lanes::max` gives 0 on NaN as `f32::max` does.
    let ct = l.sqrt(l.max(l.sub(one, sin2_t), zero));
    let rs = l.div(l.sub(ci, l.mul(eta_ti, ct)), l.add(ci, l.mul(eta_ti, ct)));
    let rp = l.div(l.sub(l.mul(eta_ti, ci), ct), l.add(l.mul(eta_ti, ci), ct));
    let f = l.mul(l.splat(0.5), l.add(l.mul(rs, rs), l.mul(rp, rp)));
    let cos_t = l.select(front, l.neg(ct), ct);
    // eta == 1 first, then total internal reflection.
    let index_matched = l.eq(eta, one);
    Fresnel {
        reflectance: l.select(index_matched, zero, l.select(total, one, f)),
        cos_t: l.select(index_matched, l.neg(cos_i), l.select(total, zero, cos_t)),
        eta_ti: l.select(index_matched, one, eta_ti),
    }
}

/// `bsdf::fresnel_conductor` for one channel, in its operations (the rough conductor's too).
#[inline(always)]
pub(super) fn fresnel_conductor<L: Lanes>(l: L, cos_i: L::F, eta: L::F, k: L::F) -> L::F {
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
