//! The rough dielectric's vertex in lanes, as `PathState::scatter` computes it for
//! `Bsdf::RoughDielectric` (`eval_rough_dielectric`, `pdf_rough_dielectric` and
//! `sample_rough_dielectric` in bsdf/microfacet.rs): the BSDF's value and density towards the
//! light, the MIS weight and the shadow ray, then a visible normal (`microfacet`), reflection
//! or refraction about it by the lobe number, the sample's value, density, weight and eta, and
//! the next ray. Both sides of the interface: `wo` below the surface is a path inside the glass.
//!
//! The lobe weights of the tints (`lobe_weight`, a maximum over channels, clamped) are the
//! scalar function's, called once per vertex at `push`; the microfacet's libm calls are
//! `microfacet`'s per-lane ones. Everything else runs in the vector operations.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::microfacet::{LaneMicrofacet, MicrofacetColumns};
use super::smooth::fresnel_dielectric;
use super::{put3, Column, Column3};
use crate::bsdf::lobe_weight;
use crate::integrators::path::PathState;
use crate::lights::LightSample;
use crate::materials::RoughDielectric;
use crate::math::lanes::Lanes;
use crate::math::Frame;
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// Up to [`MAX_LANES`] rough dielectric vertices, one per lane.
#[derive(Clone, Copy, Default)]
pub(crate) struct RoughDielectricChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    // In: the BSDF, with its tints' lobe weights.
    pub(super) dist: MicrofacetColumns,
    pub(super) eta: Column,
    pub(super) reflect: Column3,
    pub(super) transmit: Column3,
    pub(super) reflect_weight: Column,
    pub(super) transmit_weight: Column,
}

impl RoughDielectricChunk {
    /// Adds a path's vertex as the next lane with its light sample (drawn by the caller, first),
    /// then draws the BSDF's random numbers from `rng` as `PathState::scatter` does: the lobe
    /// number, then the square.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        b: &RoughDielectric,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.shared.push(path_index, path, si.p, light, Lobe::Read, rng);
        self.shared.v.put_frame(i, si.ng, frame);
        self.dist.put(i, &b.dist);
        self.eta[i] = b.eta;
        put3(&mut self.reflect, i, b.reflect.to_array());
        put3(&mut self.transmit, i, b.transmit.to_array());
        self.reflect_weight[i] = lobe_weight(b.reflect);
        self.transmit_weight[i] = lobe_weight(b.transmit);
    }
}

lane_kernel!(RoughDielectricChunk, rough_dielectric_lanes);

/// One vector's rough dielectrics.
struct Glass<L: Lanes> {
    dist: LaneMicrofacet<L>,
    eta: L::F,
    reflect: V3<L::F>,
    transmit: V3<L::F>,
    reflect_weight: L::F,
    transmit_weight: L::F,
}

impl<L: Lanes> Glass<L> {
    #[inline(always)]
    fn load(l: L, c: &RoughDielectricChunk, base: usize) -> Glass<L> {
        Glass {
            dist: c.dist.lanes(l, base),
            eta: l.load(&c.eta[base..]),
            reflect: load3(l, &c.reflect, base),
            transmit: load3(l, &c.transmit, base),
            reflect_weight: l.load(&c.reflect_weight[base..]),
            transmit_weight: l.load(&c.transmit_weight[base..]),
        }
    }

    /// `lobe_probabilities(f, reflect, transmit)`, from the tints' lobe weights.
    #[inline(always)]
    fn lobe_probabilities(&self, l: L, f: L::F) -> (L::F, L::F) {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let pr = l.mul(f, self.reflect_weight);
        let pt = l.mul(l.sub(one, f), self.transmit_weight);
        let s = l.add(pr, pt);
        let none = l.le(s, zero);
        (l.select(none, zero, l.div(pr, s)), l.select(none, zero, l.div(pt, s)))
    }

    /// `eval_rough_dielectric` and `pdf_rough_dielectric` at (`wo`, `wi`), sharing their half
    /// vector, Fresnel term and D.
    #[inline(always)]
    fn eval_pdf(&self, l: L, wo: V3<L::F>, wi: V3<L::F>) -> (V3<L::F>, L::F) {
        let (zero, one, four) = (l.splat(0.0), l.splat(1.0), l.splat(4.0));
        // `half_vector(eta, wo, wi)`: `none` where it returns `None`.
        let (co, ci) = (wo.z, wi.z);
        let is_reflect = l.gt(l.mul(co, ci), zero);
        let etap = l.select(is_reflect, one, l.select(l.gt(co, zero), self.eta, l.div(one, self.eta)));
        // `wi * etap + wo`: `wi * 1.0` is `wi` for reflection.
        let sum = add3(l, scale(l, wi, etap), wo);
        let wm = normalize(l, sum);
        let wm = select3(l, l.lt(wm.z, zero), neg3(l, wm), wm);
        let (cos_im, cos_om) = (dot(l, wi, wm), dot(l, wo, wm));
        let none = l.or(l.or(l.eq(co, zero), l.eq(ci, zero)), l.eq(dot(l, sum, sum), zero));
        let none = l.or(none, l.or(l.lt(l.mul(cos_im, ci), zero), l.lt(l.mul(cos_om, co), zero)));

        let f = fresnel_dielectric(l, cos_om, self.eta).reflectance;
        let d = self.dist.d(l, wm);
        let dg = l.mul(d, self.dist.g(l, wo, wi, wm));
        let abs_co = l.abs(co);
        // Reflection: `reflect * (dg * f / (4.0 * wo.z.abs()))`.
        let s = l.div(l.mul(dg, f), l.mul(four, abs_co));
        // Refraction: `(wi.dot(wm) + wo.dot(wm) / etap).powi(2)` is a square: `powi(2)` is
        // `x * x` both where LLVM folds it and in compiler-builtins' `__powisf2` (1 * (x * x)).
        let t = l.add(cos_im, l.div(cos_om, etap));
        let t2 = l.mul(t, t);
        let denom = l.mul(t2, abs_co);
        let ratio = l.abs(l.div(l.mul(cos_im, cos_om), denom));
        let ft = l.div(l.mul(l.mul(dg, l.sub(one, f)), ratio), l.mul(etap, etap));
        let value = select3(l, is_reflect, scale(l, self.reflect, s), scale(l, self.transmit, ft));
        let value = select3(l, none, V3 { x: zero, y: zero, z: zero }, value);

        let (pr, pt) = self.lobe_probabilities(l, f);
        let pdf_wm = self.dist.pdf_wm_given_d(l, wo, wm, d);
        // `pdf_wm / (4.0 * wo.dot(wm).abs()) * pr`.
        let pdf_reflect = l.mul(l.div(pdf_wm, l.mul(four, l.abs(cos_om))), pr);
        // `pdf_wm * wi.dot(wm).abs() / denom * pt`, `denom` the square above.
        let pdf_refract = l.mul(l.div(l.mul(pdf_wm, l.abs(cos_im)), t2), pt);
        let pdf = l.select(none, zero, l.select(is_reflect, pdf_reflect, pdf_refract));
        (value, pdf)
    }
}

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for a rough dielectric.
#[inline(always)]
fn rough_dielectric_lanes<L: Lanes>(l: L, c: &mut RoughDielectricChunk, base: usize, live: u32, light_only: bool) {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let g = Glass::load(l, c, base);
    let wo = c.shared.v.wo_local(l, base);

    // Next-event estimation: the BSDF towards the light, then what `NextEventColumns::lanes`
    // makes of it.
    let thr = load3(l, &c.shared.throughput, base);
    let light_wi = c.shared.v.local(l, base, load3(l, &c.shared.ne.light_wi, base));
    let (f, bsdf_pdf) = g.eval_pdf(l, wo, light_wi);
    c.shared.ne.lanes(l, base, &c.shared.v, thr, f, bsdf_pdf, light_only);

    // `sample_rough_dielectric`: nothing where `wo.z == 0`, else a visible normal (seen from
    // either side), the Fresnel term there and the lobe number's choice.
    let facing = l.ne(wo.z, zero);
    let u_lobe = l.load(&c.shared.u_lobe[base..]);
    let u = [l.load(&c.shared.u[0][base..]), l.load(&c.shared.u[1][base..])];
    let wm = g.dist.sample_wm(l, wo, u, live & l.bits(facing));
    let cos_om = dot(l, wo, wm);
    let fr = fresnel_dielectric(l, cos_om, g.eta);
    let (pr, _) = g.lobe_probabilities(l, fr.reflectance);
    let reflect = l.lt(u_lobe, pr);
    // Reflection: `wm * (2.0 * cos_om) - wo`, kept on `wo`'s side.
    let reflected = sub3(l, scale(l, wm, l.mul(l.splat(2.0), cos_om)), wo);
    let reflect_ok = l.not(l.le(l.mul(reflected.z, wo.z), zero));
    // Refraction: `-wo / eta_ti + wm * (cos_om / eta_ti + cos_t)` (the first a product by the
    // reciprocal, `Vec3`'s division; the second a quotient), kept across the surface and
    // normalized; none under total internal reflection.
    let across =
        add3(l, scale(l, neg3(l, wo), l.div(one, fr.eta_ti)), scale(l, wm, l.add(l.div(cos_om, fr.eta_ti), fr.cos_t)));
    let refract_ok = l.not(l.or(l.ge(fr.reflectance, one), l.ge(l.mul(across.z, wo.z), zero)));
    let wi = select3(l, reflect, reflected, normalize(l, across));
    let lobe_ok = l.or(l.and(reflect, reflect_ok), l.and_not(refract_ok, reflect));
    let (value, pdf) = g.eval_pdf(l, wo, wi);
    // `pdf <= 0.0 || !pdf.is_finite()` ends the sample; the weight is `value / pdf`, a product
    // by the reciprocal. Then `scatter` ends the path on a black one.
    let density = l.and(l.gt(pdf, zero), l.lt(l.abs(pdf), l.splat(f32::INFINITY)));
    let kept = l.and(l.and(facing, lobe_ok), density);
    let weight = scale(l, value, l.div(one, pdf));
    c.shared.store_next(l, base, kept, weight, pdf, wi);
    l.store(l.select(reflect, one, fr.eta_ti), &mut c.shared.next.eta[base..]);
}
