//! Three-component vectors over lanes and the small geometric operations the kernels share,
//! each in the operations of its scalar twin (named in its doc) so that every lane gets the
//! scalar result's bits.

use super::Column3;
use crate::math::lanes::Lanes;

/// Three columns as vectors.
#[derive(Clone, Copy)]
pub(super) struct V3<F> {
    pub x: F,
    pub y: F,
    pub z: F,
}

#[inline(always)]
pub(super) fn load3<L: Lanes>(l: L, c: &Column3, base: usize) -> V3<L::F> {
    V3 { x: l.load(&c[0][base..]), y: l.load(&c[1][base..]), z: l.load(&c[2][base..]) }
}

#[inline(always)]
pub(super) fn store3<L: Lanes>(l: L, v: V3<L::F>, c: &mut Column3, base: usize) {
    l.store(v.x, &mut c[0][base..]);
    l.store(v.y, &mut c[1][base..]);
    l.store(v.z, &mut c[2][base..]);
}

/// `a.dot(b)`, in `Vec3::dot`'s order.
#[inline(always)]
pub(super) fn dot<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> L::F {
    l.add(l.add(l.mul(a.x, b.x), l.mul(a.y, b.y)), l.mul(a.z, b.z))
}

#[inline(always)]
pub(super) fn scale<L: Lanes>(l: L, a: V3<L::F>, k: L::F) -> V3<L::F> {
    V3 { x: l.mul(a.x, k), y: l.mul(a.y, k), z: l.mul(a.z, k) }
}

#[inline(always)]
pub(super) fn add3<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.add(a.x, b.x), y: l.add(a.y, b.y), z: l.add(a.z, b.z) }
}

#[inline(always)]
pub(super) fn sub3<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.sub(a.x, b.x), y: l.sub(a.y, b.y), z: l.sub(a.z, b.z) }
}

#[inline(always)]
pub(super) fn mul3<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.mul(a.x, b.x), y: l.mul(a.y, b.y), z: l.mul(a.z, b.z) }
}

#[inline(always)]
pub(super) fn select3<L: Lanes>(l: L, m: L::M, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.select(m, a.x, b.x), y: l.select(m, a.y, b.y), z: l.select(m, a.z, b.z) }
}

/// `a.max(b)` as Rust's `f32::max` answers it (the other operand where one is NaN), for
/// operands that are not both zeros of different signs (where `f32::max` leaves the sign
/// unspecified); `Lanes::max` alone gives `b` where `b` is NaN.
#[inline(always)]
pub(super) fn max_num<L: Lanes>(l: L, a: L::F, b: L::F) -> L::F {
    l.select(l.ne(b, b), a, l.max(a, b))
}

/// `math::offset_origin(p, ng, dir)`: `p` moved off the surface to the side `dir` leaves by.
#[inline(always)]
pub(super) fn offset_origin<L: Lanes>(l: L, p: V3<L::F>, ng: V3<L::F>, dir: V3<L::F>) -> V3<L::F> {
    // `p.abs().max_component()`: the operands are absolute values, never -0.0.
    let m = max_num(l, max_num(l, l.abs(p.x), l.abs(p.y)), l.abs(p.z));
    let k = l.mul(l.splat(1e-4), l.add(l.splat(1.0), m));
    let back = l.lt(dot(l, ng, dir), l.splat(0.0));
    let n = select3(l, back, V3 { x: l.neg(ng.x), y: l.neg(ng.y), z: l.neg(ng.z) }, ng);
    add3(l, p, scale(l, n, k))
}

/// `Frame::from_normal(n)` (Duff et al.'s basis), in its operations.
#[inline(always)]
pub(super) fn frame_from_normal<L: Lanes>(l: L, n: V3<L::F>) -> (V3<L::F>, V3<L::F>) {
    let one = l.splat(1.0);
    // `1.0f32.copysign(n.z)`.
    let sign = l.select(l.sign(n.z), l.splat(-1.0), one);
    let a = l.div(l.splat(-1.0), l.add(sign, n.z));
    let b = l.mul(l.mul(n.x, n.y), a);
    let s = V3 { x: l.add(one, l.mul(l.mul(l.mul(sign, n.x), n.x), a)), y: l.mul(sign, b), z: l.mul(l.neg(sign), n.x) };
    let t = V3 { x: b, y: l.add(sign, l.mul(l.mul(n.y, n.y), a)), z: l.neg(n.y) };
    (s, t)
}

/// Whether every component is finite (`Vec3::is_finite`).
#[inline(always)]
pub(super) fn finite3<L: Lanes>(l: L, v: V3<L::F>) -> L::M {
    let inf = l.splat(f32::INFINITY);
    l.and(l.and(l.lt(l.abs(v.x), inf), l.lt(l.abs(v.y), inf)), l.lt(l.abs(v.z), inf))
}

#[inline(always)]
pub(super) fn cross<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 {
        x: l.sub(l.mul(a.y, b.z), l.mul(a.z, b.y)),
        y: l.sub(l.mul(a.z, b.x), l.mul(a.x, b.z)),
        z: l.sub(l.mul(a.x, b.y), l.mul(a.y, b.x)),
    }
}

#[inline(always)]
pub(super) fn neg3<L: Lanes>(l: L, a: V3<L::F>) -> V3<L::F> {
    V3 { x: l.neg(a.x), y: l.neg(a.y), z: l.neg(a.z) }
}

/// `v.normalize()`: `v * (1 / |v|)`.
#[inline(always)]
pub(super) fn normalize<L: Lanes>(l: L, v: V3<L::F>) -> V3<L::F> {
    scale(l, v, l.div(l.splat(1.0), l.sqrt(dot(l, v, v))))
}

/// `Rgb::is_black` of a colour in lanes: every channel zero.
#[inline(always)]
pub(super) fn black3<L: Lanes>(l: L, v: V3<L::F>) -> L::M {
    let zero = l.splat(0.0);
    l.and(l.and(l.eq(v.x, zero), l.eq(v.y, zero)), l.eq(v.z, zero))
}
