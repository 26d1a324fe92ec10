//! `sampling::warp`'s cosine-weighted hemisphere in lanes, in its operations and constants:
//! the concentric disk's sine and cosine are the same polynomials as the scalar code's, so no
//! libm call is made on either side.

use super::lane_math::V3;
use crate::math::lanes::Lanes;
use crate::math::{INV_PI, PI};

/// `warp::cosine_hemisphere(u)` by `warp::concentric_disk`, in their operations (the
/// centre's branch as a select).
#[inline(always)]
pub(super) fn cosine_hemisphere<L: Lanes>(l: L, u0: L::F, u1: L::F) -> V3<L::F> {
    let (zero, one, two) = (l.splat(0.0), l.splat(1.0), l.splat(2.0));
    let qa = l.sub(l.mul(two, u0), one);
    let qb = l.sub(l.mul(two, u1), one);
    let around_y = l.le(l.abs(qa), l.abs(qb));
    let r = l.select(around_y, qb, qa);
    let q = l.select(around_y, qa, qb);
    let centre = l.eq(r, zero);
    let (sin_t, cos_t) = sin_cos_quarter(l, l.mul(l.splat(PI / 4.0), l.div(q, r)));
    let x = l.select(centre, zero, l.mul(r, l.select(around_y, sin_t, cos_t)));
    let y = l.select(centre, zero, l.mul(r, l.select(around_y, cos_t, sin_t)));
    // `(1 - x² - y²).max(0.0)`: never -0.0 nor NaN for a sample in the square, where
    // `Lanes::max` and `f32::max` agree.
    let z = l.sqrt(l.max(l.sub(l.sub(one, l.mul(x, x)), l.mul(y, y)), zero));
    V3 { x, y, z }
}

/// `warp::cosine_hemisphere_pdf(cos)`: `cos.max(0.0) / π`, where `Lanes::max` agrees with
/// `f32::max` for every `cos` but -0.0 (0 on NaN; callers pass no -0.0, or mask it out).
#[inline(always)]
pub(super) fn cosine_hemisphere_pdf<L: Lanes>(l: L, cos: L::F) -> L::F {
    l.mul(l.max(cos, l.splat(0.0)), l.splat(INV_PI))
}

/// `warp::sin_cos_quarter`, in its operations and constants.
#[inline(always)]
fn sin_cos_quarter<L: Lanes>(l: L, t: L::F) -> (L::F, L::F) {
    let c = |x: f32| l.splat(x);
    let t2 = l.mul(t, t);
    let sin_poly = l.add(c(1.0 / 120.0), l.mul(t2, l.add(c(-1.0 / 5040.0), l.mul(t2, c(1.0 / 362_880.0)))));
    let sin = l.mul(t, l.add(c(1.0), l.mul(t2, l.add(c(-1.0 / 6.0), l.mul(t2, sin_poly)))));
    let cos_inner = l.add(c(1.0 / 40_320.0), l.mul(t2, c(-1.0 / 3_628_800.0)));
    let cos_mid = l.add(c(1.0 / 24.0), l.mul(t2, l.add(c(-1.0 / 720.0), l.mul(t2, cos_inner))));
    let cos = l.add(c(1.0), l.mul(t2, l.add(c(-0.5), l.mul(t2, cos_mid))));
    (sin, cos)
}
