//! AVX2: eight lanes per instruction, so an 8-wide node is one pass, and two blocks of four
//! triangles are one test. A lone block uses the SSE kernel, which compiles to VEX-encoded
//! 128-bit code here.

use super::sse::tri4_sse;
use super::Isa;
use crate::accel::tri4::{join_hits, Tri4, Tri4Hits, TriHits, TriRay};
use crate::accel::wide::{NodeRay, WideNode, FAR_SCALE};
use std::arch::x86_64::*;

#[derive(Clone, Copy, Debug)]
pub struct Avx2;

unsafe impl Isa for Avx2 {
    #[inline(always)]
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, dist: &mut [f32; W]) -> u32 {
        if W == 4 {
            return super::Sse::node(node, r, t_max, dist);
        }
        let mut mask = 0u32;
        for c in 0..W / 8 {
            // SAFETY: this path runs only with AVX2; `8 * c + 8 <= W` (so the store of eight
            // distances stays in `dist` too), and the rows are the caller's (`Isa::node`).
            let (t_near, t_far) = slabs8(node, r, t_max, c);
            _mm256_storeu_ps(dist.as_mut_ptr().add(8 * c), t_near);
            mask |= (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32) << (8 * c);
        }
        mask
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_sse(block, r, t_min, t_max)
    }

    #[inline(always)]
    unsafe fn tri8(lo: &Tri4, hi: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> TriHits<8> {
        tri8_avx2(lo, hi, r, t_min, t_max)
    }
}

/// Entry and scaled exit distances of children `8 * c..8 * c + 8` of a node (the slab test
/// of every path, eight lanes at once): a child is hit where entry <= exit. Shared by the
/// AVX2 and AVX-512 node tests, which differ only in how they read the comparison.
///
/// # Safety
/// AVX2 must be available, `8 * c + 8 <= W`, and the rows `r.near`, `r.far` below 6 (the
/// contract of `Isa::node`).
#[inline(always)]
pub(super) unsafe fn slabs8<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, c: usize) -> (__m256, __m256) {
    let o = [_mm256_set1_ps(r.o[0]), _mm256_set1_ps(r.o[1]), _mm256_set1_ps(r.o[2])];
    let inv = [_mm256_set1_ps(r.inv[0]), _mm256_set1_ps(r.inv[1]), _mm256_set1_ps(r.inv[2])];
    // SAFETY: the caller's contract; the node is 32-byte aligned and each row is `W * 4`
    // bytes, a multiple of 32, as the aligned load needs.
    let slab = |row: usize, a: usize| {
        _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds.get_unchecked(row).as_ptr().add(8 * c)), o[a]), inv[a])
    };
    // NaN slabs lose to the other operand (`maxps`/`minps`), as on every path.
    let t_near = _mm256_max_ps(
        slab(r.near[0], 0),
        _mm256_max_ps(slab(r.near[1], 1), _mm256_max_ps(slab(r.near[2], 2), _mm256_set1_ps(r.t_min))),
    );
    let t_far = _mm256_min_ps(
        slab(r.far[0], 0),
        _mm256_min_ps(slab(r.far[1], 1), _mm256_min_ps(slab(r.far[2], 2), _mm256_set1_ps(t_max))),
    );
    (t_near, _mm256_mul_ps(t_far, _mm256_set1_ps(FAR_SCALE)))
}

/// The watertight test on two blocks at once, operation for operation as `tri4_sse` (and so
/// `tri_lane`) on each: the 256-bit forms of the same instructions, with the comparison
/// predicates of SSE's `cmpeq` (EQ_OQ), `cmplt` (LT_OS), `cmpgt` (GT_OS), `cmpneq` (NEQ_UQ).
#[inline(always)]
unsafe fn tri8_avx2(lo: &Tri4, hi: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> TriHits<8> {
    let [kx, ky, kz] = r.k;
    // SAFETY: `TriRay` axes are < 3, and `Tri4` is 16-byte aligned with rows of four floats
    // at multiples of 16 bytes, as the aligned loads need.
    let rel = |k: usize, axis: usize| {
        let l = _mm_load_ps(lo.v[k].get_unchecked(axis).as_ptr());
        let h = _mm_load_ps(hi.v[k].get_unchecked(axis).as_ptr());
        _mm256_sub_ps(_mm256_set_m128(h, l), _mm256_set1_ps(*r.o.get_unchecked(axis)))
    };
    let (a_x, a_y, a_z) = (rel(0, kx), rel(0, ky), rel(0, kz));
    let (b_x, b_y, b_z) = (rel(1, kx), rel(1, ky), rel(1, kz));
    let (c_x, c_y, c_z) = (rel(2, kx), rel(2, ky), rel(2, kz));
    let (sx, sy, sz) = (_mm256_set1_ps(r.s[0]), _mm256_set1_ps(r.s[1]), _mm256_set1_ps(r.s[2]));
    let ax = _mm256_sub_ps(a_x, _mm256_mul_ps(sx, a_z));
    let ay = _mm256_sub_ps(a_y, _mm256_mul_ps(sy, a_z));
    let bx = _mm256_sub_ps(b_x, _mm256_mul_ps(sx, b_z));
    let by = _mm256_sub_ps(b_y, _mm256_mul_ps(sy, b_z));
    let cx = _mm256_sub_ps(c_x, _mm256_mul_ps(sx, c_z));
    let cy = _mm256_sub_ps(c_y, _mm256_mul_ps(sy, c_z));
    let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
    let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
    let w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
    let zero = _mm256_setzero_ps();
    let eq = |x| _mm256_cmp_ps::<_CMP_EQ_OQ>(x, zero);
    let lt = |x| _mm256_cmp_ps::<_CMP_LT_OS>(x, zero);
    let gt = |x| _mm256_cmp_ps::<_CMP_GT_OS>(x, zero);
    let any_zero = _mm256_or_ps(_mm256_or_ps(eq(u), eq(v)), eq(w));
    let neg = _mm256_or_ps(_mm256_or_ps(lt(u), lt(v)), lt(w));
    let pos = _mm256_or_ps(_mm256_or_ps(gt(u), gt(v)), gt(w));
    // Inside unless some edge function is negative and some positive.
    let outside = _mm256_movemask_ps(_mm256_and_ps(neg, pos));
    let zero_bits = _mm256_movemask_ps(any_zero);
    if zero_bits == 0 && outside == 0xff {
        // Most pairs: the ray passes outside all eight triangles.
        return TriHits::NONE;
    }
    if zero_bits != 0 {
        // An edge function is exactly zero: each block as the four-lane kernel does it
        // (which redoes such a block in double precision).
        return join_hits(&tri4_sse(lo, r, t_min, t_max), &tri4_sse(hi, r, t_min, t_max));
    }
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let ok = _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, zero);
    let t_scaled = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(u, _mm256_mul_ps(sz, a_z)), _mm256_mul_ps(v, _mm256_mul_ps(sz, b_z))),
        _mm256_mul_ps(w, _mm256_mul_ps(sz, c_z)),
    );
    let inv = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let t = _mm256_mul_ps(t_scaled, inv);
    let in_range = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_GT_OS>(t, _mm256_set1_ps(t_min)),
        _mm256_cmp_ps::<_CMP_LT_OS>(t, _mm256_set1_ps(t_max)),
    );
    let mask = (_mm256_movemask_ps(_mm256_and_ps(ok, in_range)) as u32) & !(outside as u32);
    let mut h = TriHits::<8> { mask, ..TriHits::NONE };
    if mask != 0 {
        _mm256_storeu_ps(h.t.as_mut_ptr(), t);
        _mm256_storeu_ps(h.b1.as_mut_ptr(), _mm256_mul_ps(v, inv));
        _mm256_storeu_ps(h.b2.as_mut_ptr(), _mm256_mul_ps(w, inv));
    }
    h
}
