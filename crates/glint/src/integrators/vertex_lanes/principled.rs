//! The principled BSDF's vertex in lanes, as `PathState::scatter` computes it for
//! `Bsdf::Principled` (materials/principled/bsdf.rs): the BSDF's value and density towards
//! the light, the MIS weight and the shadow ray, then a lobe chosen by the lobe number
//! (diffuse, clearcoat, transmission, reflection), its direction, value, density and weight,
//! and the next ray. Every lobe is computed in every lane and the lane's branch selected, so
//! that lanes of different parameters (metallic or not, clearcoat or not, ...) share a chunk.
//!
//! The transcendental functions (the visible-normal sample's cosine and sine, the GTR1
//! sample's `sin_cos` and `powf`, GTR1's `ln`) are the scalar code's libm calls, made per
//! lane ([`per_lane`]): the same call gives the same bits.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::microfacet::{ggx_visible_normal_unit, per_lane};
use super::{put3, Column, Column3};
use crate::integrators::path::PathState;
use crate::lights::LightSample;
use crate::materials::Principled;
use crate::math::lanes::Lanes;
use crate::math::{INV_PI, PI};
use crate::sampling::Sampler;

/// Up to [`MAX_LANES`] principled vertices, one per lane.
#[derive(Clone, Copy, Default)]
pub(crate) struct PrincipledChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    // In: the BSDF's parameters.
    pub(super) base_color: Column3,
    pub(super) roughness: Column,
    pub(super) alpha_x: Column,
    pub(super) alpha_y: Column,
    pub(super) metallic: Column,
    pub(super) spec_trans: Column,
    pub(super) eta: Column,
    pub(super) spec_tint: Column,
    pub(super) sheen: Column,
    pub(super) sheen_tint: Column,
    pub(super) flatness: Column,
    pub(super) clearcoat: Column,
    pub(super) clearcoat_alpha: Column,
    /// The sampling rates: diffuse, specular, clearcoat.
    pub(super) rates: Column3,
}

impl PrincipledChunk {
    /// Adds a path's vertex as the next lane: its interaction and frame, the BSDF, the light
    /// sample, and the BSDF's random numbers drawn from `rng` as `PathState::scatter` draws
    /// them after the light sample (the lobe number, then the square).
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &crate::world::SurfaceInteraction,
        frame: &crate::math::Frame,
        b: &Principled,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.shared.push(path_index, path, si.p, light, Lobe::Read, rng);
        self.shared.v.put_frame(i, si.ng, frame);
        put3(&mut self.base_color, i, b.base_color.to_array());
        self.roughness[i] = b.roughness;
        self.alpha_x[i] = b.dist.alpha_x;
        self.alpha_y[i] = b.dist.alpha_y;
        self.metallic[i] = b.metallic;
        self.spec_trans[i] = b.spec_trans;
        self.eta[i] = b.eta;
        self.spec_tint[i] = b.spec_tint;
        self.sheen[i] = b.sheen;
        self.sheen_tint[i] = b.sheen_tint;
        self.flatness[i] = b.flatness;
        self.clearcoat[i] = b.clearcoat;
        self.clearcoat_alpha[i] = b.clearcoat_alpha;
        put3(&mut self.rates, i, [b.rates.diffuse, b.rates.specular, b.rates.clearcoat]);
    }
}

lane_kernel!(PrincipledChunk, principled_lanes);

/// Every lane's bit: the principled kernel's scalar calls (`sin`, `cos`, `powf`, `ln`) are
/// pure, so the stale lanes of a part-full vector make them too rather than thread `live`
/// through every lobe.
#[inline(always)]
fn all<L: Lanes>() -> u32 {
    u32::MAX >> (32 - L::N)
}

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for `Principled`.
#[inline(always)]
fn principled_lanes<L: Lanes>(l: L, c: &mut PrincipledChunk, base: usize, _live: u32, light_only: bool) {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let b = Params::load(l, c, base);
    let wo = c.shared.v.wo_local(l, base);

    // Next-event estimation.
    let light_wi = c.shared.v.local(l, base, load3(l, &c.shared.ne.light_wi, base));
    let f = b.eval(l, wo, light_wi);
    let bsdf_pdf = b.pdf(l, wo, light_wi);
    let throughput = load3(l, &c.shared.throughput, base);
    c.shared.ne.lanes(l, base, &c.shared.v, throughput, f, bsdf_pdf, light_only);

    // `Principled::sample`.
    let (u_lobe, u0, u1) =
        (l.load(&c.shared.u_lobe[base..]), l.load(&c.shared.u[0][base..]), l.load(&c.shared.u[1][base..]));
    let cos_o = wo.z;
    let front = l.gt(cos_o, zero);
    let (_, bsdf) = b.weights(l);
    let mut ok = l.and(l.ne(cos_o, zero), l.or(front, l.gt(bsdf, zero)));
    let v = select3(l, front, wo, neg3(l, wo));
    let m = b.sample_visible(l, v, u0, u1);
    let cos_om = dot(l, wo, m);
    let fr = super::smooth::fresnel_dielectric(l, cos_om, b.eta);
    let p = b.probabilities(l, front, fr.reflectance);
    ok = l.and(ok, p.ok);
    // The four lobes' directions; the lobe number picks one.
    let diffuse_wi = super::warp::cosine_hemisphere(l, u0, u1);
    let mc = gtr1_sample(l, b.clearcoat_alpha, u0, u1);
    let clearcoat_wi = sub3(l, scale(l, mc, l.mul(l.splat(2.0), dot(l, wo, mc))), wo);
    // `-wo / eta_ti` multiplies by the reciprocal (`Vec3`'s division); `cos_om / eta_ti` divides.
    let inv_eta = l.div(one, fr.eta_ti);
    let refract_dir = add3(l, scale(l, neg3(l, wo), inv_eta), scale(l, m, l.add(l.div(cos_om, fr.eta_ti), fr.cos_t)));
    let refract_wi = normalize(l, refract_dir);
    let reflect_wi = sub3(l, scale(l, m, l.mul(l.splat(2.0), cos_om)), wo);
    // The `if`/`else if` chain as masks that exclude each other.
    let dc = l.add(p.diffuse, p.clearcoat);
    let pick_diffuse = l.lt(u_lobe, p.diffuse);
    let below_dc = l.lt(u_lobe, dc);
    let below_dct = l.lt(u_lobe, l.add(dc, p.spec_trans));
    let pick_clearcoat = l.and_not(below_dc, pick_diffuse);
    let past_dc = l.not(l.or(pick_diffuse, below_dc));
    let pick_trans = l.and(past_dc, below_dct);
    let pick_reflect = l.and_not(past_dc, below_dct);
    let wi = select3(
        l,
        pick_diffuse,
        diffuse_wi,
        select3(l, pick_clearcoat, clearcoat_wi, select3(l, pick_trans, refract_wi, reflect_wi)),
    );
    let clearcoat_ok = compatible(l, mc, wo, clearcoat_wi, cos_o, true);
    let trans_ok = l.and(
        l.and(l.not(l.ge(fr.reflectance, one)), l.lt(l.mul(cos_o, refract_wi.z), zero)),
        compatible(l, m, wo, refract_wi, cos_o, false),
    );
    let reflect_ok = compatible(l, m, wo, reflect_wi, cos_o, true);
    let lobe_ok = l.or(
        l.or(pick_diffuse, l.and(pick_clearcoat, clearcoat_ok)),
        l.or(l.and(pick_trans, trans_ok), l.and(pick_reflect, reflect_ok)),
    );
    ok = l.and(ok, lobe_ok);
    // `!refracted && cos_o * wi.z <= 0` ends the sample.
    ok = l.and_not(ok, l.and_not(l.le(l.mul(cos_o, wi.z), zero), pick_trans));
    let pdf = b.pdf(l, wo, wi);
    ok = l.and(ok, l.gt(pdf, zero));
    let value = b.eval(l, wo, wi);
    let weight = scale(l, value, l.div(one, pdf));
    c.shared.store_next(l, base, ok, weight, pdf, wi);
    l.store(l.select(pick_trans, fr.eta_ti, one), &mut c.shared.next.eta[base..]);
}

/// `Gtr1::sample(u)`: the clearcoat's normal.
#[inline(always)]
fn gtr1_sample<L: Lanes>(l: L, alpha: L::F, u0: L::F, u1: L::F) -> V3<L::F> {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let phi = l.mul(l.splat(2.0 * PI), u0);
    let a2 = l.mul(alpha, alpha);
    let [sin_phi, cos_phi, pow] =
        per_lane(l, all::<L>(), [phi, a2, l.sub(one, u1)], |_, [phi, a2, e]| [phi.sin(), phi.cos(), a2.powf(e)]);
    let cos2 = l.div(l.sub(one, pow), l.sub(one, a2));
    // `.max(0.0)` of `1 - cos2` (never -0.0) and of `cos2` (-0.0 only for a2 > 1, which
    // `clearcoat_alpha` <= 0.1 rules out): `Lanes::max` agrees with `f32::max`.
    let sin_t = l.sqrt(l.max(l.sub(one, cos2), zero));
    V3 { x: l.mul(cos_phi, sin_t), y: l.mul(sin_phi, sin_t), z: l.sqrt(l.max(cos2, zero)) }
}

/// `Gtr1::d(m)`.
#[inline(always)]
fn gtr1_d<L: Lanes>(l: L, alpha: L::F, m: V3<L::F>) -> L::F {
    let one = l.splat(1.0);
    let a2 = l.mul(alpha, alpha);
    let a2m1 = l.sub(a2, one);
    let den = l.mul(
        l.mul(l.splat(PI), per_lane(l, all::<L>(), [a2], |_, [a2]| [a2.ln()])[0]),
        l.add(one, l.mul(l.mul(a2m1, m.z), m.z)),
    );
    let r = l.div(a2m1, den);
    l.select(l.gt(l.mul(r, m.z), l.splat(1e-20)), r, l.splat(0.0))
}

/// `smith_ggx1(v, m, 0.25)`: the clearcoat's masking.
#[inline(always)]
fn smith_ggx1_clearcoat<L: Lanes>(l: L, v: V3<L::F>, m: V3<L::F>) -> L::F {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let c2 = l.mul(v.z, v.z);
    let tan2 = l.div(l.sub(one, c2), c2);
    let g = l.div(l.splat(2.0), l.add(one, l.sqrt(l.add(one, l.mul(l.splat(0.25 * 0.25), tan2)))));
    let g = l.select(l.eq(v.z, one), one, g);
    l.select(l.le(l.mul(dot(l, v, m), v.z), zero), zero, g)
}

/// `schlick_weight(cos)`: `(1 - cos).clamp(0, 1)` to the fifth.
#[inline(always)]
fn schlick_weight<L: Lanes>(l: L, cos: L::F) -> L::F {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let x = l.sub(one, cos);
    // `clamp`: NaN stays NaN.
    let m = l.select(l.lt(x, zero), zero, l.select(l.gt(x, one), one, x));
    l.mul(l.mul(l.mul(l.mul(m, m), m), m), m)
}

/// `lerp(a, b, t)`.
#[inline(always)]
fn lerp<L: Lanes>(l: L, a: L::F, b: L::F, t: L::F) -> L::F {
    l.add(l.mul(a, l.sub(l.splat(1.0), t)), l.mul(b, t))
}

/// `schlick(r0, cos_i, eta)`'s weight, the same for every channel.
#[inline(always)]
fn schlick_w<L: Lanes>(l: L, cos_i: L::F, eta: L::F) -> L::F {
    let one = l.splat(1.0);
    let outside = l.ge(cos_i, l.splat(0.0));
    let inv = l.div(one, eta);
    let eta_it = l.select(outside, eta, inv);
    let eta_ti = l.select(outside, inv, eta);
    let cos_t2 = l.sub(one, l.mul(l.mul(l.sub(one, l.mul(cos_i, cos_i)), eta_ti), eta_ti));
    // `cos_t2.max(0.0)`: `1 - x` is never -0.0, and `Lanes::max` gives 0 on NaN.
    let inside = schlick_weight(l, l.sqrt(l.max(cos_t2, l.splat(0.0))));
    l.select(l.gt(eta_it, one), schlick_weight(l, l.abs(cos_i)), inside)
}

/// `schlick(r0, cos_i, eta)`: `r0.map(|r| lerp(w, 1, r))`.
#[inline(always)]
fn schlick<L: Lanes>(l: L, r0: V3<L::F>, w: L::F) -> V3<L::F> {
    let one = l.splat(1.0);
    V3 { x: lerp(l, w, one, r0.x), y: lerp(l, w, one, r0.y), z: lerp(l, w, one, r0.z) }
}

/// `compatible(m, wo, wi, cos_o, reflection)`.
#[inline(always)]
fn compatible<L: Lanes>(l: L, m: V3<L::F>, wo: V3<L::F>, wi: V3<L::F>, cos_o: L::F, reflection: bool) -> L::M {
    let zero = l.splat(0.0);
    let ms = select3(l, l.lt(cos_o, zero), neg3(l, m), m);
    let o = l.gt(dot(l, wo, ms), zero);
    if reflection {
        l.and(o, l.gt(dot(l, wi, ms), zero))
    } else {
        l.and(o, l.lt(dot(l, wi, ms), zero))
    }
}

/// `Principled::probabilities`: `ok` false where it returns `None`.
struct Probabilities<F, M> {
    diffuse: F,
    clearcoat: F,
    spec_trans: F,
    spec_reflect: F,
    ok: M,
}

/// One vector's BSDF parameters.
struct Params<F> {
    base_color: V3<F>,
    roughness: F,
    alpha_x: F,
    alpha_y: F,
    metallic: F,
    spec_trans: F,
    eta: F,
    spec_tint: F,
    sheen: F,
    sheen_tint: F,
    flatness: F,
    clearcoat: F,
    clearcoat_alpha: F,
    rates: V3<F>,
}

impl<F: Copy> Params<F> {
    #[inline(always)]
    fn load<L: Lanes<F = F>>(l: L, c: &PrincipledChunk, base: usize) -> Params<F> {
        let col = |x: &Column| l.load(&x[base..]);
        Params {
            base_color: load3(l, &c.base_color, base),
            roughness: col(&c.roughness),
            alpha_x: col(&c.alpha_x),
            alpha_y: col(&c.alpha_y),
            metallic: col(&c.metallic),
            spec_trans: col(&c.spec_trans),
            eta: col(&c.eta),
            spec_tint: col(&c.spec_tint),
            sheen: col(&c.sheen),
            sheen_tint: col(&c.sheen_tint),
            flatness: col(&c.flatness),
            clearcoat: col(&c.clearcoat),
            clearcoat_alpha: col(&c.clearcoat_alpha),
            rates: load3(l, &c.rates, base),
        }
    }

    /// `Principled::weights`: the diffuse (BRDF) and transmissive (BSDF) weights.
    #[inline(always)]
    fn weights<L: Lanes<F = F>>(&self, l: L) -> (F, F) {
        let dielectric = l.sub(l.splat(1.0), self.metallic);
        (l.mul(dielectric, l.sub(l.splat(1.0), self.spec_trans)), l.mul(dielectric, self.spec_trans))
    }

    #[inline(always)]
    fn probabilities<L: Lanes<F = F>>(&self, l: L, front: L::M, f: F) -> Probabilities<F, L::M> {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let (brdf, bsdf) = self.weights(l);
        let r = &self.rates;
        let has_trans = l.gt(self.spec_trans, zero);
        let one_minus_f = l.sub(one, f);
        let diffuse = l.select(front, l.mul(brdf, r.x), zero);
        let clearcoat = l.select(front, l.mul(l.mul(l.splat(0.25), self.clearcoat), r.z), zero);
        let trans_front = l.mul(l.mul(r.y, bsdf), one_minus_f);
        let spec_trans = l.select(has_trans, l.select(front, trans_front, one_minus_f), zero);
        let reflect_front = l.mul(r.y, l.sub(one, l.mul(bsdf, one_minus_f)));
        let spec_reflect = l.select(front, reflect_front, f);
        let total = l.add(l.add(l.add(diffuse, clearcoat), spec_trans), spec_reflect);
        // `total > 0 && total.is_finite()`.
        let ok = l.and(l.gt(total, zero), l.lt(total, l.splat(f32::INFINITY)));
        Probabilities {
            diffuse: l.div(diffuse, total),
            clearcoat: l.div(clearcoat, total),
            spec_trans: l.div(spec_trans, total),
            spec_reflect: l.div(spec_reflect, total),
            ok,
        }
    }

    /// `AnisoGgx::d(m)`.
    #[inline(always)]
    fn d<L: Lanes<F = F>>(&self, l: L, m: V3<F>) -> F {
        let zero = l.splat(0.0);
        let (x, y) = (l.div(m.x, self.alpha_x), l.div(m.y, self.alpha_y));
        let s = l.add(l.add(l.mul(x, x), l.mul(y, y)), l.mul(m.z, m.z));
        let den = l.mul(l.mul(l.mul(l.mul(l.splat(PI), self.alpha_x), self.alpha_y), s), s);
        let r = l.div(l.splat(1.0), den);
        let keep = l.and(l.gt(l.mul(r, m.z), l.splat(1e-20)), l.lt(l.abs(r), l.splat(f32::INFINITY)));
        l.select(l.and(l.gt(m.z, zero), keep), r, zero)
    }

    /// `AnisoGgx::g1(v, m)`.
    #[inline(always)]
    fn g1<L: Lanes<F = F>>(&self, l: L, v: V3<F>, m: V3<F>) -> F {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let (ax, ay) = (l.mul(self.alpha_x, v.x), l.mul(self.alpha_y, v.y));
        let xy = l.add(l.mul(ax, ax), l.mul(ay, ay));
        let tan2 = l.div(xy, l.mul(v.z, v.z));
        let g = l.div(l.splat(2.0), l.add(one, l.sqrt(l.add(one, tan2))));
        let g = l.select(l.eq(xy, zero), one, g);
        l.select(l.le(l.mul(dot(l, v, m), v.z), zero), zero, g)
    }

    /// `AnisoGgx::pdf_visible(v, m)`.
    #[inline(always)]
    fn pdf_visible<L: Lanes<F = F>>(&self, l: L, v: V3<F>, m: V3<F>) -> F {
        let zero = l.splat(0.0);
        let p = l.div(l.mul(l.mul(self.d(l, m), self.g1(l, v, m)), l.abs(dot(l, v, m))), v.z);
        l.select(l.and(l.gt(v.z, zero), l.gt(p, l.splat(1e-20))), p, zero)
    }

    /// `AnisoGgx::sample_visible(v, u)`.
    #[inline(always)]
    fn sample_visible<L: Lanes<F = F>>(&self, l: L, v: V3<F>, u0: F, u1: F) -> V3<F> {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let vh = normalize(l, V3 { x: l.mul(ax, v.x), y: l.mul(ay, v.y), z: v.z });
        let nh = ggx_visible_normal_unit(l, vh, [u0, u1], all::<L>());
        // `nh.z.max(1e-6)`: `max_num`, since `nh.z` may be NaN.
        normalize(l, V3 { x: l.mul(ax, nh.x), y: l.mul(ay, nh.y), z: max_num(l, nh.z, l.splat(1e-6)) })
    }

    /// `Principled::half_vector(wo, wi)`: the half vector, `eta_path`, `reflect`, and `ok`
    /// false where it returns `None`.
    #[inline(always)]
    fn half_vector<L: Lanes<F = F>>(&self, l: L, wo: V3<F>, wi: V3<F>) -> (V3<F>, F, L::M, L::M) {
        let zero = l.splat(0.0);
        let reflect = l.gt(l.mul(wo.z, wi.z), zero);
        let eta_path = l.select(l.gt(wo.z, zero), self.eta, l.div(l.splat(1.0), self.eta));
        let h = add3(l, wo, select3(l, reflect, wi, scale(l, wi, eta_path)));
        let ok = l.gt(dot(l, h, h), zero);
        let h = normalize(l, h);
        (select3(l, l.lt(h.z, zero), neg3(l, h), h), eta_path, reflect, ok)
    }

    /// `Principled::main_fresnel(f_d, cos, front)`.
    #[inline(always)]
    fn main_fresnel<L: Lanes<F = F>>(&self, l: L, f_d: F, cos: F, front: L::M) -> V3<F> {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let (_, bsdf) = self.weights(l);
        let back = l.mul(bsdf, f_d);
        let eta_it = l.select(l.ge(cos, zero), self.eta, l.div(one, self.eta));
        let w = schlick_w(l, cos, self.eta);
        let mut f = V3 { x: zero, y: zero, z: zero };
        let metal = scale(l, schlick(l, self.base_color, w), self.metallic);
        f = select3(l, l.gt(self.metallic, zero), add3(l, f, metal), f);
        let e = l.div(l.sub(eta_it, one), l.add(eta_it, one));
        let r0 = scale(l, tint_of(l, self.base_color), l.mul(e, e));
        let tinted = scale(l, schlick(l, r0, w), l.mul(l.sub(one, self.metallic), self.spec_tint));
        f = select3(l, l.gt(self.spec_tint, zero), add3(l, f, tinted), f);
        let plain = l.mul(l.mul(l.sub(one, self.metallic), l.sub(one, self.spec_tint)), f_d);
        let f = add3(l, f, V3 { x: plain, y: plain, z: plain });
        select3(l, front, f, V3 { x: back, y: back, z: back })
    }

    /// `Principled::diffuse_and_sheen(wo, wi, wh, brdf)`.
    #[inline(always)]
    fn diffuse_and_sheen<L: Lanes<F = F>>(&self, l: L, wo: V3<F>, wi: V3<F>, wh: V3<F>, brdf: F) -> V3<F> {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let (ci, co) = (l.abs(wi.z), l.abs(wo.z));
        let cos_d = dot(l, wh, wi);
        let lobe = disney_diffuse(l, self.roughness, self.flatness, ci, co, cos_d);
        let value = scale(l, self.base_color, l.mul(l.mul(l.mul(brdf, ci), l.splat(INV_PI)), lobe));
        let fd = schlick_weight(l, l.abs(cos_d));
        let tint = tint_of(l, self.base_color);
        let white = l.sub(one, self.sheen_tint);
        let c_sheen = add3(l, V3 { x: white, y: white, z: white }, scale(l, tint, self.sheen_tint));
        let dielectric = l.sub(one, self.metallic);
        let k = l.mul(l.mul(l.mul(self.sheen, dielectric), fd), ci);
        let sheen = l.and(l.gt(self.sheen, zero), l.gt(dielectric, zero));
        select3(l, sheen, add3(l, value, scale(l, c_sheen, k)), value)
    }

    /// `Principled::eval(wo, wi)`.
    #[inline(always)]
    fn eval<L: Lanes<F = F>>(&self, l: L, wo: V3<F>, wi: V3<F>) -> V3<F> {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let (cos_o, cos_i) = (wo.z, wi.z);
        let (wh, eta_path, reflect, half_ok) = self.half_vector(l, wo, wi);
        let refract = l.lt(l.mul(cos_o, cos_i), zero);
        let front = l.gt(cos_o, zero);
        let (brdf, bsdf) = self.weights(l);
        let oh = dot(l, wo, wh);
        let f_d = super::smooth::fresnel_dielectric(l, oh, self.eta).reflectance;
        let reflect_ok = compatible(l, wh, wo, wi, cos_o, true);
        let refract_ok = compatible(l, wh, wo, wi, cos_o, false);
        let d = self.d(l, wh);
        let g = l.mul(self.g1(l, wo, wh), self.g1(l, wi, wh));
        let mut value = V3 { x: zero, y: zero, z: zero };
        let specular =
            scale(l, self.main_fresnel(l, f_d, oh, front), l.div(l.mul(d, g), l.mul(l.splat(4.0), l.abs(cos_o))));
        let with_specular = l.and(l.and(reflect, reflect_ok), l.gt(f_d, zero));
        value = select3(l, with_specular, add3(l, value, specular), value);
        let scale_t = l.div(one, l.mul(eta_path, eta_path));
        let ih = dot(l, wi, wh);
        let sq = l.add(oh, l.mul(eta_path, ih));
        let mut t = l.mul(l.mul(scale_t, l.sub(one, f_d)), d);
        t = l.mul(l.mul(l.mul(l.mul(l.mul(t, g), eta_path), eta_path), oh), ih);
        t = l.div(t, l.mul(cos_o, l.mul(sq, sq)));
        let root = V3 { x: l.sqrt(self.base_color.x), y: l.sqrt(self.base_color.y), z: l.sqrt(self.base_color.z) };
        let transmitted = scale(l, root, l.mul(bsdf, l.abs(t)));
        let with_trans = l.and(l.and(l.gt(bsdf, zero), l.and(refract, refract_ok)), l.lt(f_d, one));
        value = select3(l, with_trans, add3(l, value, transmitted), value);
        let fcc = lerp(l, schlick_w(l, oh, self.eta), one, l.splat(0.04));
        let dcc = gtr1_d(l, self.clearcoat_alpha, wh);
        let gcc = l.mul(smith_ggx1_clearcoat(l, wo, wh), smith_ggx1_clearcoat(l, wi, wh));
        let cc = l.mul(l.mul(l.mul(l.mul(l.mul(self.clearcoat, l.splat(0.25)), fcc), dcc), gcc), l.abs(cos_i));
        let with_cc = l.and(l.and(l.gt(self.clearcoat, zero), l.and(reflect, reflect_ok)), front);
        value = select3(l, with_cc, add3(l, value, V3 { x: cc, y: cc, z: cc }), value);
        let with_diffuse = l.and(l.gt(brdf, zero), l.and(reflect, front));
        let diffuse = self.diffuse_and_sheen(l, wo, wi, wh, brdf);
        value = select3(l, with_diffuse, add3(l, value, diffuse), value);
        let ok = l.and(l.ne(cos_o, zero), half_ok);
        select3(l, ok, value, V3 { x: zero, y: zero, z: zero })
    }

    /// `Principled::pdf(wo, wi)`.
    #[inline(always)]
    fn pdf<L: Lanes<F = F>>(&self, l: L, wo: V3<F>, wi: V3<F>) -> F {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let (cos_o, cos_i) = (wo.z, wi.z);
        let (wh, eta_path, reflect, half_ok) = self.half_vector(l, wo, wi);
        let refract = l.lt(l.mul(cos_o, cos_i), zero);
        let front = l.gt(cos_o, zero);
        let oh = dot(l, wo, wh);
        let f_d = super::smooth::fresnel_dielectric(l, oh, self.eta).reflectance;
        let p = self.probabilities(l, front, f_d);
        let ih = dot(l, wi, wh);
        let sq = l.add(oh, l.mul(eta_path, ih));
        let dwh_reflect = l.abs(l.div(one, l.mul(l.splat(4.0), ih)));
        let dwh_refract = l.abs(l.div(l.mul(l.mul(eta_path, eta_path), ih), l.mul(sq, sq)));
        let dwh_dwi = l.select(reflect, dwh_reflect, dwh_refract);
        let v = select3(l, l.lt(cos_o, zero), neg3(l, wo), wo);
        let visible = self.pdf_visible(l, v, wh);
        let mut pdf = zero;
        let reflect_ok = l.and(reflect, compatible(l, wh, wo, wi, cos_o, true));
        pdf = l.select(reflect_ok, l.add(pdf, l.mul(l.mul(p.spec_reflect, visible), dwh_dwi)), pdf);
        let gtr1_pdf = l.select(l.lt(wh.z, zero), zero, l.mul(wh.z, gtr1_d(l, self.clearcoat_alpha, wh)));
        let cc = l.mul(l.mul(p.clearcoat, gtr1_pdf), dwh_dwi);
        pdf = l.select(l.and(reflect_ok, l.gt(p.clearcoat, zero)), l.add(pdf, cc), pdf);
        let diffuse = l.mul(p.diffuse, super::warp::cosine_hemisphere_pdf(l, l.abs(cos_i)));
        pdf = l.select(l.and(reflect, l.gt(p.diffuse, zero)), l.add(pdf, diffuse), pdf);
        let trans_ok = l.and(l.and(refract, l.gt(p.spec_trans, zero)), compatible(l, wh, wo, wi, cos_o, false));
        pdf = l.select(trans_ok, l.add(pdf, l.mul(l.mul(p.spec_trans, visible), dwh_dwi)), pdf);
        let ok = l.and(l.and(l.ne(cos_o, zero), half_ok), p.ok);
        let finite = l.lt(l.abs(pdf), l.splat(f32::INFINITY));
        l.select(l.and(ok, finite), pdf, zero)
    }
}

/// `tint_of(base)`: the colour over its luminance, white where it has none.
#[inline(always)]
fn tint_of<L: Lanes>(l: L, base: V3<L::F>) -> V3<L::F> {
    let one = l.splat(1.0);
    let lum =
        l.add(l.add(l.mul(l.splat(0.2126), base.x), l.mul(l.splat(0.7152), base.y)), l.mul(l.splat(0.0722), base.z));
    let tinted = scale(l, base, l.div(one, lum));
    select3(l, l.gt(lum, l.splat(0.0)), tinted, V3 { x: one, y: one, z: one })
}

/// `disney_diffuse(roughness, flatness, ci, co, cos_d)`.
#[inline(always)]
fn disney_diffuse<L: Lanes>(l: L, roughness: L::F, flatness: L::F, ci: L::F, co: L::F, cos_d: L::F) -> L::F {
    let (one, half) = (l.splat(1.0), l.splat(0.5));
    let (f_light, f_view) = (schlick_weight(l, ci), schlick_weight(l, co));
    let f_diff = l.mul(l.sub(one, l.mul(half, f_view)), l.sub(one, l.mul(half, f_light)));
    let rr = l.mul(l.mul(l.mul(l.splat(2.0), roughness), cos_d), cos_d);
    let f_retro = l.mul(rr, l.add(l.add(f_light, f_view), l.mul(l.mul(f_light, f_view), l.sub(rr, one))));
    let lobe = l.add(f_diff, f_retro);
    let fss90 = l.div(rr, l.splat(2.0));
    let fss = l.mul(lerp(l, one, fss90, f_light), lerp(l, one, fss90, f_view));
    let f_ss = l.mul(l.splat(1.25), l.add(l.mul(fss, l.sub(l.div(one, l.add(ci, co)), half)), half));
    l.select(l.gt(flatness, l.splat(0.0)), lerp(l, lobe, f_ss, flatness), lobe)
}
