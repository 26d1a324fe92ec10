//! The smooth plastic's vertex in lanes, as `PathState::scatter` computes it for
//! `Bsdf::Plastic` with a smooth coating (`dist` None): the diffuse lobe towards the light
//! (the delta lobe has no value there), the MIS weight and the shadow ray, then the lobe
//! chosen by the lobe number: the coating's mirror reflection (a delta sample) or the
//! cosine-sampled diffuse base, and the next ray.
//!
//! What both coatings share (the BSDF's columns, [`PlasticColumns`]; the lobe probability,
//! the transmittance through the coating, the base's albedo and its diffuse term,
//! [`Coating`]) is here; the rough coating's kernel (`rough_plastic`) adds its microfacet lobe
//! and replaces the transmittance `1 - F` by its table.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::smooth::fresnel_dielectric;
use super::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use super::{flag, put3, Column, Column3};
use crate::integrators::path::PathState;
use crate::lights::LightSample;
use crate::materials::PlasticParams;
use crate::math::lanes::Lanes;
use crate::math::{Frame, INV_PI};
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// Up to [`MAX_LANES`] vertices of smooth plastics, one per lane: what the scalar code
/// gathered, and what the kernel leaves. Flags are 1.0 (true) or 0.0.
#[derive(Clone, Copy, Default)]
pub(crate) struct PlasticChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    /// In: the BSDF.
    pub(super) bsdf: PlasticColumns,
}

impl PlasticChunk {
    /// Adds a path's vertex as the next lane: its smooth plastic (`dist` None), its light
    /// sample (drawn before, as `PathState::scatter` draws it), then the lobe number and the
    /// square drawn from `rng` in `scatter`'s order.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        bsdf: &PlasticParams,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        debug_assert!(bsdf.dist.is_none(), "rough plastics wait in `RoughPlasticChunk`");
        let i = self.shared.push(path_index, path, si.p, light, Lobe::Read, rng);
        self.shared.v.put_frame(i, si.ng, frame);
        self.bsdf.put(i, bsdf);
    }
}

lane_kernel!(PlasticChunk, plastic_lanes);

/// `PlasticParams`' fields that both coatings' kernels read, one plastic per lane. Flags are
/// 1.0 (true) or 0.0.
#[derive(Clone, Copy, Default)]
pub(crate) struct PlasticColumns {
    pub diffuse: Column3,
    pub specular: Column3,
    pub eta: Column,
    pub fdr_internal: Column,
    pub nonlinear: Column,
}

impl PlasticColumns {
    /// Lane `i`'s plastic (its coating's roughness and table aside).
    pub fn put(&mut self, i: usize, p: &PlasticParams) {
        put3(&mut self.diffuse, i, p.diffuse.to_array());
        put3(&mut self.specular, i, p.specular.to_array());
        self.eta[i] = p.eta;
        self.fdr_internal[i] = p.fdr_internal;
        self.nonlinear[i] = flag(p.nonlinear);
    }
}

/// The coating over one vector of lanes, for the viewing direction's cosine `wo.z`: what
/// `PlasticParams`' `prob_specular` and `diffuse_eval` compute from `wo` alone.
pub(super) struct Coating<F> {
    pub eta: F,
    /// `eta * eta`.
    pub eta2: F,
    /// `fresnel_dielectric(wo.z, eta).reflectance`.
    pub fresnel_o: F,
    /// `coating_transmittance(wo.z)`: `1 - fresnel_o` for a smooth coating (`new`'s), the
    /// table's value for a rough one (which its kernel puts here).
    pub to: F,
    /// `prob_specular(wo.z)`.
    pub ps: F,
    /// The base's albedo under the internal-scattering correction (linear or nonlinear).
    pub albedo: V3<F>,
}

impl<F: Copy> Coating<F> {
    #[inline(always)]
    pub fn new<L: Lanes<F = F>>(l: L, c: &PlasticColumns, base: usize, wo_z: F) -> Coating<F> {
        let (zero, one, three) = (l.splat(0.0), l.splat(1.0), l.splat(3.0));
        let eta = l.load(&c.eta[base..]);
        let diffuse = load3(l, &c.diffuse, base);
        let specular = load3(l, &c.specular, base);
        let fresnel_o = fresnel_dielectric(l, wo_z, eta).reflectance;
        // `specular_weight`: `Rgb::average` is `(r + g + b) / 3`.
        let d = l.div(l.add(l.add(diffuse.x, diffuse.y), diffuse.z), three);
        let s = l.div(l.add(l.add(specular.x, specular.y), specular.z), three);
        let ds = l.add(d, s);
        let sw = l.select(l.le(ds, zero), l.splat(0.5), l.div(s, ds));
        // `prob_specular`.
        let ps = l.mul(fresnel_o, sw);
        let pd = l.mul(l.sub(one, fresnel_o), l.sub(one, sw));
        let sum = l.add(ps, pd);
        let ps = l.select(l.le(sum, zero), zero, l.div(ps, sum));
        // `diffuse_eval`'s albedo: `d / (1 - d F_dr)` per channel, or `diffuse / (1 - F_dr)`,
        // which `Rgb`'s division by a number computes as a product with `1 / (1 - F_dr)`.
        let fdr = l.load(&c.fdr_internal[base..]);
        let nonlinear = l.gt(l.load(&c.nonlinear[base..]), zero);
        let nl = |d: F| l.div(d, l.sub(one, l.mul(d, fdr)));
        let albedo_nl = V3 { x: nl(diffuse.x), y: nl(diffuse.y), z: nl(diffuse.z) };
        let albedo_lin = scale(l, diffuse, l.div(one, l.sub(one, fdr)));
        Coating {
            eta,
            eta2: l.mul(eta, eta),
            fresnel_o,
            to: l.sub(one, fresnel_o),
            ps,
            albedo: select3(l, nonlinear, albedo_nl, albedo_lin),
        }
    }

    /// `diffuse_eval(wo, wi)` of a smooth coating for the incident cosine `wi_z`.
    #[inline(always)]
    fn diffuse_eval<L: Lanes<F = F>>(&self, l: L, wi_z: F) -> V3<F> {
        let ti = l.sub(l.splat(1.0), fresnel_dielectric(l, wi_z, self.eta).reflectance);
        self.diffuse_eval_through(l, wi_z, ti)
    }

    /// `diffuse_eval(wo, wi)` for the incident cosine `wi_z`, where the coating transmits `ti`
    /// (`coating_transmittance(wi.z)`): `albedo * (INV_PI * wi.z * to * ti / (eta * eta))`, in
    /// that order.
    #[inline(always)]
    pub fn diffuse_eval_through<L: Lanes<F = F>>(&self, l: L, wi_z: F, ti: F) -> V3<F> {
        let k = l.div(l.mul(l.mul(l.mul(l.splat(INV_PI), wi_z), self.to), ti), self.eta2);
        scale(l, self.albedo, k)
    }
}

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for a smooth plastic.
#[inline(always)]
fn plastic_lanes<L: Lanes>(l: L, c: &mut PlasticChunk, base: usize, _live: u32, light_only: bool) {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let wo = c.shared.v.wo_local(l, base);
    let n = load3(l, &c.shared.v.n, base);
    let thr = load3(l, &c.shared.throughput, base);
    let coat = Coating::new(l, &c.bsdf, base, wo.z);
    // `eval`, `pdf` and `sample` give nothing below the surface (NaN goes on).
    let wo_below = l.le(wo.z, zero);

    // Next-event estimation: `eval` and `pdf` towards the light (the diffuse lobe's only),
    // then what `NextEventColumns::lanes` makes of them. `frame.to_local(ls.wi).z`.
    let wi_z = dot(l, load3(l, &c.shared.ne.light_wi, base), n);
    let black = l.or(wo_below, l.le(wi_z, zero));
    let f = select3(l, black, V3 { x: zero, y: zero, z: zero }, coat.diffuse_eval(l, wi_z));
    // `(1 - ps) * cosine_hemisphere_pdf(wi.z)`, where `wi.z` is above 0 or NaN.
    let bsdf_pdf = l.select(black, zero, l.mul(l.sub(one, coat.ps), cosine_hemisphere_pdf(l, wi_z)));
    c.shared.ne.lanes(l, base, &c.shared.v, thr, f, bsdf_pdf, light_only);

    // `sample`: the coating's reflection where `u_lobe < ps`, weighted `specular * (F / ps)`
    // with density `ps`; else the cosine-sampled base, weighted `diffuse_eval / pdf` with
    // density `(1 - ps) * cosine_hemisphere_pdf(wi.z)`, none where `wi.z <= 0`.
    let mirror = l.lt(l.load(&c.shared.u_lobe[base..]), coat.ps);
    let reflected = V3 { x: l.neg(wo.x), y: l.neg(wo.y), z: wo.z };
    let w_mirror = scale(l, load3(l, &c.bsdf.specular, base), l.div(coat.fresnel_o, coat.ps));
    let d = cosine_hemisphere(l, l.load(&c.shared.u[0][base..]), l.load(&c.shared.u[1][base..]));
    // `d.z` is never -0.0 (a square root of a `max` with +0).
    let pdf_d = l.mul(l.sub(one, coat.ps), cosine_hemisphere_pdf(l, d.z));
    let w_diffuse = scale(l, coat.diffuse_eval(l, d.z), l.div(one, pdf_d));
    let below_base = l.and_not(l.le(d.z, zero), mirror);
    let kept = l.and_not(l.not(wo_below), below_base);
    let weight = select3(l, mirror, w_mirror, w_diffuse);
    let pdf = l.select(mirror, coat.ps, pdf_d);
    c.shared.store_next(l, base, kept, weight, pdf, select3(l, mirror, reflected, d));
    l.store(l.select(mirror, one, zero), &mut c.shared.next.delta[base..]);
}
