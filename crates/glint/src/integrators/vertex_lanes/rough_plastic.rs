//! The rough plastic's vertex in lanes, as `PathState::scatter` computes it for
//! `Bsdf::Plastic` with a rough coating (`dist` Some): the BSDF's value and density towards
//! the light (the diffuse base under the coating's tabulated transmittance plus the coating's
//! microfacet reflection), the MIS weight and the shadow ray, then the lobe chosen by the
//! lobe number (a visible normal of the coating and the direction it reflects `wo` to, or the
//! cosine-sampled base), the value and density of both lobes there (`BsdfSample::non_delta`'s
//! rules) and the next ray.
//!
//! A chunk of its own rather than lanes of the smooth plastic's: the two share the coating's
//! lobe probability and diffuse term ([`Coating`]) but not their samples (a delta reflection
//! with the base's density alone against a non-delta one with both lobes' value and density),
//! and a smooth plastic's vector never computes a microfacet term this way.
//!
//! The transmittance table is a gather from each lane's own table: each lane makes the scalar
//! call `materials::plastic::coating_transmittance` (the very function `PlasticParams` calls),
//! three times per vertex (at `wo`, towards the light and at the sampled direction), and only
//! for the lanes that read the result.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::microfacet::{per_lane, LaneMicrofacet, MicrofacetColumns};
use super::plastic::{Coating, PlasticColumns};
use super::smooth::fresnel_dielectric;
use super::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::bsdf::Microfacet;
use crate::integrators::path::PathState;
use crate::lights::LightSample;
use crate::materials::{coating_transmittance, PlasticParams, TRANSMITTANCE_RES};
use crate::math::lanes::{Lanes, MAX_LANES};
use crate::math::Frame;
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// Up to [`MAX_LANES`] vertices of rough plastics, one per lane.
#[derive(Clone, Copy, Default)]
pub(crate) struct RoughPlasticChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    // In: the BSDF: the plastic, its coating's distribution and transmittance table.
    pub(super) bsdf: PlasticColumns,
    pub(super) dist: MicrofacetColumns,
    pub(super) table: [Option<&'static [f32; TRANSMITTANCE_RES]>; MAX_LANES],
}

impl RoughPlasticChunk {
    /// Adds a path's vertex as the next lane: its plastic `bsdf` with the coating's
    /// distribution `dist` (`bsdf.dist`), its light sample (drawn before, as
    /// `PathState::scatter` draws it), then the lobe number and the square drawn from `rng` in
    /// `scatter`'s order.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        bsdf: &PlasticParams,
        dist: &Microfacet,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.shared.push(path_index, path, si.p, light, Lobe::Read, rng);
        self.shared.v.put_frame(i, si.ng, frame);
        self.bsdf.put(i, bsdf);
        self.dist.put(i, dist);
        self.table[i] = bsdf.transmittance;
    }
}

lane_kernel!(RoughPlasticChunk, rough_plastic_lanes);

/// `coating_transmittance(cos)` of the lanes set in `which` (lane i in bit i; 0 in the
/// others): the scalar function on each lane's table, index and cosine.
#[inline(always)]
fn transmittance<L: Lanes>(l: L, c: &RoughPlasticChunk, base: usize, which: u32, eta: L::F, cos: L::F) -> L::F {
    let [t] = per_lane(l, which, [eta, cos], |i, [eta, cos]| [coating_transmittance(c.table[base + i], eta, cos)]);
    t
}

/// `PlasticParams::eval` and `pdf` of a rough coating at (`wo`, `wi`), sharing their half
/// vector and D; the lanes in `live` look their transmittance up.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn eval_pdf<L: Lanes>(
    l: L,
    c: &RoughPlasticChunk,
    base: usize,
    live: u32,
    dist: &LaneMicrofacet<L>,
    coat: &Coating<L::F>,
    wo: V3<L::F>,
    wi: V3<L::F>,
) -> (V3<L::F>, L::F) {
    let (zero, one, four) = (l.splat(0.0), l.splat(1.0), l.splat(4.0));
    let below = l.or(l.le(wo.z, zero), l.le(wi.z, zero));
    // `diffuse_eval(wo, wi)`.
    let ti = transmittance(l, c, base, live & !l.bits(below), coat.eta, wi.z);
    let diffuse = coat.diffuse_eval_through(l, wi.z, ti);
    // The coating: `specular * (f * d.d(h) * d.g(wo, wi, h) / (4.0 * wo.z))`, `f` the Fresnel
    // reflectance at `wo.dot(h)`, `h` the normalized `wo + wi`; added to the base's.
    let h = normalize(l, add3(l, wo, wi));
    let d = dist.d(l, h);
    let cos_oh = dot(l, wo, h);
    let fr = fresnel_dielectric(l, cos_oh, coat.eta).reflectance;
    let k = l.div(l.mul(l.mul(fr, d), dist.g(l, wo, wi, h)), l.mul(four, wo.z));
    let f = add3(l, diffuse, scale(l, load3(l, &c.bsdf.specular, base), k));
    let f = select3(l, below, V3 { x: zero, y: zero, z: zero }, f);
    // `(1 - ps) * cosine_hemisphere_pdf(wi.z)` (`wi.z` is above 0 or NaN where it counts),
    // plus `ps * d.pdf_wm(wo, h) / (4.0 * wo.dot(h))`.
    let p_base = l.mul(l.sub(one, coat.ps), cosine_hemisphere_pdf(l, wi.z));
    let p_coat = l.div(l.mul(coat.ps, dist.pdf_wm_given_d(l, wo, h, d)), l.mul(four, cos_oh));
    (f, l.select(below, zero, l.add(p_base, p_coat)))
}

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for a rough plastic.
#[inline(always)]
fn rough_plastic_lanes<L: Lanes>(l: L, c: &mut RoughPlasticChunk, base: usize, live: u32, light_only: bool) {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let wo = c.shared.v.wo_local(l, base);
    let dist = c.dist.lanes(l, base);
    // `eval`, `pdf` and `sample` give nothing below the surface (NaN goes on).
    let above = l.not(l.le(wo.z, zero));
    let mut coat = Coating::new(l, &c.bsdf, base, wo.z);
    coat.to = transmittance(l, c, base, live & l.bits(above), coat.eta, wo.z);

    // Next-event estimation: the BSDF towards the light, then what `NextEventColumns::lanes`
    // makes of it.
    let thr = load3(l, &c.shared.throughput, base);
    let light_wi = c.shared.v.local(l, base, load3(l, &c.shared.ne.light_wi, base));
    let (f, bsdf_pdf) = eval_pdf(l, c, base, live, &dist, &coat, wo, light_wi);
    c.shared.ne.lanes(l, base, &c.shared.v, thr, f, bsdf_pdf, light_only);

    // `sample`: where `u_lobe < ps`, a visible normal of the coating and `h * (2.0 *
    // wo.dot(h)) - wo` (not normalized); else the cosine-sampled base. Then `finish`: both
    // lobes' value and density there.
    let coat_lobe = l.lt(l.load(&c.shared.u_lobe[base..]), coat.ps);
    let u = [l.load(&c.shared.u[0][base..]), l.load(&c.shared.u[1][base..])];
    let h = dist.sample_wm(l, wo, u, live & l.bits(l.and(above, coat_lobe)));
    let reflected = sub3(l, scale(l, h, l.mul(l.splat(2.0), dot(l, wo, h))), wo);
    let wi = select3(l, coat_lobe, reflected, cosine_hemisphere(l, u[0], u[1]));
    let (value, pdf) = eval_pdf(l, c, base, live & l.bits(above), &dist, &coat, wo, wi);
    // `BsdfSample::non_delta`: none where `wi.z <= 0` or without density; the weight is
    // `value / pdf`, a product by the reciprocal. Then `scatter` ends the path on a black one.
    let kept = l.and(l.and_not(above, l.le(wi.z, zero)), l.gt(pdf, zero));
    let weight = scale(l, value, l.div(one, pdf));
    c.shared.store_next(l, base, kept, weight, pdf, wi);
}
