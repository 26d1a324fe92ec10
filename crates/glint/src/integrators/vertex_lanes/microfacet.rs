//! `bsdf::Microfacet` over lanes: one distribution per lane (its kind and its roughness along
//! local x and y), each function in its scalar twin's operations and branches (as selects), so
//! that every lane gets the bits of `Microfacet::d`, `g1`, `g`, `pdf_wm` and `sample_wm`.
//!
//! GGX runs in the vector operations but for the sine and cosine of the sampled azimuth, which
//! are the scalar `f32::cos` and `f32::sin` of each lane. Beckmann shares GGX's operations
//! where they are the same and takes the rest lane by lane from the scalar code: `d`'s
//! exponential (`f32::exp` per lane), the visible fraction (the f64 error function, by
//! `Microfacet::visible_fraction` per lane) and the whole visible-normal sample
//! (`Microfacet::sample_wm` per lane: a Newton iteration in f64). Those per-lane calls are
//! made only for the lanes that need them, so GGX-only vectors never leave the vector code.
//! The rough BSDFs' kernels share it: each keeps a [`MicrofacetColumns`] and loads a
//! [`LaneMicrofacet`] from it.

use super::lane_math::*;
use super::Column;
use crate::bsdf::{Microfacet, MicrofacetKind};
use crate::math::lanes::{Lanes, MAX_LANES};
use crate::math::{vec3, PI};

/// One distribution per lane, as the chunk gathered them.
#[derive(Clone, Copy, Default)]
pub(crate) struct MicrofacetColumns {
    /// 1 for Beckmann, 0 for GGX.
    pub beckmann: Column,
    pub alpha_u: Column,
    pub alpha_v: Column,
}

impl MicrofacetColumns {
    /// Lane `i`'s distribution.
    pub fn put(&mut self, i: usize, m: &Microfacet) {
        self.beckmann[i] = super::flag(m.kind == MicrofacetKind::Beckmann);
        self.alpha_u[i] = m.alpha_u;
        self.alpha_v[i] = m.alpha_v;
    }

    /// The distributions of the lanes from `base`.
    #[inline(always)]
    pub fn lanes<L: Lanes>(&self, l: L, base: usize) -> LaneMicrofacet<L> {
        let beckmann = l.gt(l.load(&self.beckmann[base..]), l.splat(0.0));
        LaneMicrofacet {
            beckmann,
            beckmann_bits: l.bits(beckmann),
            alpha_u: l.load(&self.alpha_u[base..]),
            alpha_v: l.load(&self.alpha_v[base..]),
        }
    }
}

/// `L::N` distributions, one per lane.
#[derive(Clone, Copy)]
pub(super) struct LaneMicrofacet<L: Lanes> {
    /// The Beckmann lanes (the others are GGX), also as bits (lane i in bit i).
    pub beckmann: L::M,
    pub beckmann_bits: u32,
    pub alpha_u: L::F,
    pub alpha_v: L::F,
}

/// `f` of each lane whose bit is set in `which` (lane i in bit i), on the lane's values of
/// `args`; 0 in the other lanes. This is how the vector code makes a scalar call per lane.
#[inline(always)]
pub(super) fn per_lane<L: Lanes, const K: usize, const R: usize>(
    l: L,
    which: u32,
    args: [L::F; K],
    mut f: impl FnMut(usize, [f32; K]) -> [f32; R],
) -> [L::F; R] {
    let mut ins = [[0.0f32; MAX_LANES]; K];
    for (k, a) in args.into_iter().enumerate() {
        l.store(a, &mut ins[k]);
    }
    let mut outs = [[0.0f32; MAX_LANES]; R];
    for i in 0..L::N {
        if which >> i & 1 != 0 {
            let r = f(i, std::array::from_fn(|k| ins[k][i]));
            for (k, v) in r.into_iter().enumerate() {
                outs[k][i] = v;
            }
        }
    }
    outs.map(|o| l.load(&o))
}

impl<L: Lanes> LaneMicrofacet<L> {
    /// Lane `i`'s distribution as the scalar code has it, given the lanes' roughness stored
    /// in `au` and `av`.
    #[inline(always)]
    fn scalar(&self, i: usize, au: f32, av: f32) -> Microfacet {
        let kind = if self.beckmann_bits >> i & 1 != 0 { MicrofacetKind::Beckmann } else { MicrofacetKind::Ggx };
        // Not `Microfacet::anisotropic`: the columns hold the clamped values already.
        Microfacet { kind, alpha_u: au, alpha_v: av }
    }

    /// `Microfacet::projected_alpha2_tan2(v)`.
    #[inline(always)]
    fn projected_alpha2_tan2(&self, l: L, v: V3<L::F>) -> L::F {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos2 = l.mul(v.z, v.z);
        let num = l.add(l.mul(l.mul(l.mul(au, au), v.x), v.x), l.mul(l.mul(l.mul(av, av), v.y), v.y));
        // `.max(0.0)`: each term is a product (α·α·v)·v, never -0.0, nor is their sum or the
        // quotient by a square; `Lanes::max` gives 0 on NaN as `f32::max` does.
        l.max(l.div(num, cos2), l.splat(0.0))
    }

    /// `Microfacet::d(h)`.
    #[inline(always)]
    pub fn d(&self, l: L, h: V3<L::F>) -> L::F {
        let zero = l.splat(0.0);
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos2 = l.mul(h.z, h.z);
        let below = l.or(l.le(cos2, zero), l.le(h.z, zero));
        let (x, y) = (l.div(h.x, au), l.div(h.y, av));
        let x2y2 = l.add(l.mul(x, x), l.mul(y, y));
        let pi_au_av = l.mul(l.mul(l.splat(PI), au), av);
        // GGX: 1 / (π αu αv t²), t = x² + y² + cos².
        let t = l.add(x2y2, cos2);
        let mut r = l.div(l.splat(1.0), l.mul(l.mul(pi_au_av, t), t));
        if self.beckmann_bits != 0 {
            // Beckmann: exp(-(x² + y²) / cos²) / (π αu αv cos⁴), the exponential per lane.
            let [e] = per_lane(l, self.beckmann_bits, [l.div(l.neg(x2y2), cos2)], |_, [a]| [a.exp()]);
            let beck = l.div(e, l.mul(l.mul(pi_au_av, cos2), cos2));
            r = l.select(self.beckmann, beck, r);
        }
        let finite = l.lt(l.abs(r), l.splat(f32::INFINITY));
        l.select(below, zero, l.select(finite, r, zero))
    }

    /// `Microfacet::g1(v, h)`.
    #[inline(always)]
    pub fn g1(&self, l: L, v: V3<L::F>, h: V3<L::F>) -> L::F {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let hidden = l.le(l.mul(dot(l, v, h), v.z), zero);
        let a2t2 = self.projected_alpha2_tan2(l, v);
        // GGX: 2 / (1 + sqrt(1 + α² tan²)).
        let mut r = l.div(l.splat(2.0), l.add(one, l.sqrt(l.add(one, a2t2))));
        if self.beckmann_bits != 0 {
            // Beckmann: the rational fit in a = 1 / sqrt(α² tan²), 1 from a = 1.6 on.
            let a = l.div(one, l.sqrt(a2t2));
            let num = l.add(l.mul(l.splat(3.535), a), l.mul(l.mul(l.splat(2.181), a), a));
            let den = l.add(l.add(one, l.mul(l.splat(2.276), a)), l.mul(l.mul(l.splat(2.577), a), a));
            let beck = l.select(l.ge(a, l.splat(1.6)), one, l.div(num, den));
            r = l.select(self.beckmann, beck, r);
        }
        l.select(hidden, zero, l.select(l.eq(a2t2, zero), one, r))
    }

    /// `Microfacet::g(wo, wi, h)`.
    #[inline(always)]
    pub fn g(&self, l: L, wo: V3<L::F>, wi: V3<L::F>, h: V3<L::F>) -> L::F {
        l.mul(self.g1(l, wo, h), self.g1(l, wi, h))
    }

    /// `wo` turned to the upper hemisphere (`if wo.z < 0.0 { -wo } else { wo }`).
    #[inline(always)]
    fn upper(l: L, wo: V3<L::F>) -> V3<L::F> {
        select3(l, l.lt(wo.z, l.splat(0.0)), neg3(l, wo), wo)
    }

    /// `Microfacet::pdf_wm(wo, h)`.
    // The rough conductor's kernel needs D as well, and calls `pdf_wm_given_d`.
    #[cfg_attr(not(test), allow(dead_code))]
    #[inline(always)]
    pub fn pdf_wm(&self, l: L, wo: V3<L::F>, h: V3<L::F>) -> L::F {
        self.pdf_wm_given_d(l, wo, h, self.d(l, h))
    }

    /// `Microfacet::pdf_wm(wo, h)` where `d` is `self.d(l, h)` already (Beckmann's costs an
    /// exponential per lane: a kernel that needs both computes it once).
    #[inline(always)]
    pub fn pdf_wm_given_d(&self, l: L, wo: V3<L::F>, h: V3<L::F>, d: L::F) -> L::F {
        let (zero, one) = (l.splat(0.0), l.splat(1.0));
        let w = Self::upper(l, wo);
        let cos_wh = dot(l, w, h);
        let none = l.or(l.eq(wo.z, zero), l.le(cos_wh, zero));
        // `visible_fraction(w)`: GGX's is `g1`'s expression.
        let a2t2 = self.projected_alpha2_tan2(l, w);
        let mut visible = l.div(l.splat(2.0), l.add(one, l.sqrt(l.add(one, a2t2))));
        if self.beckmann_bits != 0 {
            // Beckmann's, in f64 with the error function: the scalar code's, lane by lane.
            let (mut au, mut av) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
            l.store(self.alpha_u, &mut au);
            l.store(self.alpha_v, &mut av);
            let [beck] = per_lane(l, self.beckmann_bits, [w.x, w.y, w.z], |i, [x, y, z]| {
                [self.scalar(i, au[i], av[i]).visible_fraction(vec3(x, y, z))]
            });
            visible = l.select(self.beckmann, beck, visible);
        }
        let visible = l.select(l.eq(a2t2, zero), one, visible);
        let r = l.div(l.mul(l.mul(visible, cos_wh), d), w.z);
        l.select(none, zero, r)
    }

    /// `Microfacet::sample_wm(wo, u)` for the lanes set in `active` (lane i in bit i; the
    /// others' results are unspecified): GGX's visible normal in lanes, Beckmann's lane by lane.
    #[inline(always)]
    pub fn sample_wm(&self, l: L, wo: V3<L::F>, u: [L::F; 2], active: u32) -> V3<L::F> {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let w = Self::upper(l, wo);
        let vh = normalize(l, V3 { x: l.mul(au, w.x), y: l.mul(av, w.y), z: w.z });
        let m = ggx_visible_normal_unit(l, vh, u, active & !self.beckmann_bits);
        // `m.z.max(1e-6)`: `Lanes::max` gives the bound on NaN as `f32::max` does.
        let h = normalize(l, V3 { x: l.mul(au, m.x), y: l.mul(av, m.y), z: l.max(m.z, l.splat(1e-6)) });
        let beckmann = active & self.beckmann_bits;
        if beckmann == 0 {
            return h;
        }
        let (mut aus, mut avs) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
        l.store(au, &mut aus);
        l.store(av, &mut avs);
        let [x, y, z] = per_lane(l, beckmann, [wo.x, wo.y, wo.z, u[0], u[1]], |i, [x, y, z, u0, u1]| {
            let m = self.scalar(i, aus[i], avs[i]).sample_wm(vec3(x, y, z), [u0, u1]);
            [m.x, m.y, m.z]
        });
        select3(l, self.beckmann, V3 { x, y, z }, h)
    }
}

/// `microfacet::ggx_visible_normal_unit(v, u)`, the azimuth's cosine and sine by the scalar
/// calls of the lanes set in `active` (the others get 0 for both).
#[inline(always)]
pub(super) fn ggx_visible_normal_unit<L: Lanes>(l: L, v: V3<L::F>, u: [L::F; 2], active: u32) -> V3<L::F> {
    let (zero, one) = (l.splat(0.0), l.splat(1.0));
    let lensq = l.add(l.mul(v.x, v.x), l.mul(v.y, v.y));
    // `Vec3 { x: -v.y, y: v.x, z: 0.0 } / lensq.sqrt()`: a product by the reciprocal.
    let k = l.div(one, l.sqrt(lensq));
    let tilted = V3 { x: l.mul(l.neg(v.y), k), y: l.mul(v.x, k), z: l.mul(zero, k) };
    let t1 = select3(l, l.gt(lensq, zero), tilted, V3 { x: one, y: zero, z: zero });
    let t2 = cross(l, v, t1);
    let r = l.sqrt(u[0]);
    let phi = l.mul(l.splat(2.0 * PI), u[1]);
    let [cos_phi, sin_phi] = per_lane(l, active, [phi], |_, [p]| [p.cos(), p.sin()]);
    let p1 = l.mul(r, cos_phi);
    let s = l.mul(l.splat(0.5), l.add(one, v.z));
    // The `.max(0.0)`s: 1 - a and (1 - a) - b are never -0.0 here, and `Lanes::max` gives 0
    // on NaN as `f32::max` does.
    let one_minus_p1p1 = l.sub(one, l.mul(p1, p1));
    let p2 = l.add(l.mul(l.sub(one, s), l.sqrt(l.max(one_minus_p1p1, zero))), l.mul(l.mul(s, r), sin_phi));
    let up = l.sqrt(l.max(l.sub(one_minus_p1p1, l.mul(p2, p2)), zero));
    add3(l, add3(l, scale(l, t1, p1), scale(l, t2, p2)), scale(l, v, up))
}
