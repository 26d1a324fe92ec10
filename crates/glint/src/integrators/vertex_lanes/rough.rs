//! The rough conductor's vertex in lanes, as `PathState::scatter` computes it for
//! `Bsdf::RoughConductor`: the BSDF's value and density towards the light, the MIS weight and
//! the shadow ray, then a visible normal (`microfacet`), the reflected direction, its value
//! and density (`BsdfSample::non_delta`'s rules) and the next ray.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::microfacet::{LaneMicrofacet, MicrofacetColumns};
use super::smooth::fresnel_conductor;
use super::{put3, Column3};
use crate::integrators::path::PathState;
use crate::lights::LightSample;
use crate::materials::RoughConductor;
use crate::math::lanes::Lanes;
use crate::math::Frame;
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// Up to [`MAX_LANES`] rough conductor vertices, one per lane.
#[derive(Clone, Copy, Default)]
pub(crate) struct RoughChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    // In: the BSDF.
    pub(super) dist: MicrofacetColumns,
    pub(super) eta: Column3,
    pub(super) k: Column3,
    pub(super) specular: Column3,
}

impl RoughChunk {
    /// Adds a path's vertex as the next lane with its light sample (drawn by the caller, first),
    /// then draws the BSDF's random numbers from `rng` as `PathState::scatter` does: a lobe
    /// number (unused by a conductor, drawn all the same) and a square.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        m: &RoughConductor,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.shared.push(path_index, path, si.p, light, Lobe::Unread, rng);
        self.shared.v.put_frame(i, si.ng, frame);
        self.dist.put(i, &m.dist);
        put3(&mut self.eta, i, m.eta.to_array());
        put3(&mut self.k, i, m.k.to_array());
        put3(&mut self.specular, i, m.specular.to_array());
    }
}

lane_kernel!(RoughChunk, rough_lanes);

/// `RoughConductor::eval` and `pdf` at (`wo`, `wi`), sharing their half vector and D.
#[inline(always)]
fn eval_pdf<L: Lanes>(
    l: L,
    dist: &LaneMicrofacet<L>,
    eta: V3<L::F>,
    k: V3<L::F>,
    spec: V3<L::F>,
    wo: V3<L::F>,
    wi: V3<L::F>,
) -> (V3<L::F>, L::F) {
    let zero = l.splat(0.0);
    let below = l.or(l.le(wo.z, zero), l.le(wi.z, zero));
    // `(wo + wi).normalize()`.
    let h = normalize(l, add3(l, wo, wi));
    let d = dist.d(l, h);
    let black = l.or(below, l.eq(d, zero));
    let cos_ih = dot(l, wi, h);
    let g = dist.g(l, wo, wi, h);
    // `specular * f * (d * g / (4.0 * wo.z))`.
    let s = l.div(l.mul(d, g), l.mul(l.splat(4.0), wo.z));
    let f = V3 {
        x: l.mul(l.mul(spec.x, fresnel_conductor(l, cos_ih, eta.x, k.x)), s),
        y: l.mul(l.mul(spec.y, fresnel_conductor(l, cos_ih, eta.y, k.y)), s),
        z: l.mul(l.mul(spec.z, fresnel_conductor(l, cos_ih, eta.z, k.z)), s),
    };
    let f = select3(l, black, V3 { x: zero, y: zero, z: zero }, f);
    // `self.dist.pdf_wm(wo, h) / (4.0 * wo.dot(h))`.
    let pdf = l.div(dist.pdf_wm_given_d(l, wo, h, d), l.mul(l.splat(4.0), dot(l, wo, h)));
    (f, l.select(below, zero, pdf))
}

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for a rough conductor.
#[inline(always)]
fn rough_lanes<L: Lanes>(l: L, c: &mut RoughChunk, base: usize, live: u32, light_only: bool) {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let dist = c.dist.lanes(l, base);
    let (eta, k, spec) = (load3(l, &c.eta, base), load3(l, &c.k, base), load3(l, &c.specular, base));
    let wo = c.shared.v.wo_local(l, base);

    // Next-event estimation: the BSDF towards the light, then what `NextEventColumns::lanes`
    // makes of it.
    let thr = load3(l, &c.shared.throughput, base);
    let light_wi = c.shared.v.local(l, base, load3(l, &c.shared.ne.light_wi, base));
    let (f, bsdf_pdf) = eval_pdf(l, &dist, eta, k, spec, wo, light_wi);
    c.shared.ne.lanes(l, base, &c.shared.v, thr, f, bsdf_pdf, light_only);

    // `RoughConductor::sample`: nothing where `wo` is below the surface, else a visible
    // normal and the direction it reflects `wo` to.
    let above = l.not(l.le(wo.z, zero));
    let u = [l.load(&c.shared.u[0][base..]), l.load(&c.shared.u[1][base..])];
    let h = dist.sample_wm(l, wo, u, live & l.bits(above));
    // `(h * (2.0 * wo.dot(h)) - wo).normalize()`.
    let wi = normalize(l, sub3(l, scale(l, h, l.mul(l.splat(2.0), dot(l, wo, h))), wo));
    let (value, pdf) = eval_pdf(l, &dist, eta, k, spec, wo, wi);
    // `BsdfSample::non_delta`: none below the surface or without density; the weight is
    // `value / pdf`, a product by the reciprocal. Then `scatter` ends the path on a black one.
    let kept = l.and(l.and_not(above, l.le(wi.z, zero)), l.gt(pdf, zero));
    let weight = scale(l, value, l.div(one, pdf));
    c.shared.store_next(l, base, kept, weight, pdf, wi);
}
