//! AVX-512 (F and VL): the node test compares straight into a mask register, four blocks
//! of four triangles are one 16-lane test, and any-hit traversal pushes a node's hit
//! children with one compress. Everything else is the AVX2 path's, compiled with AVX-512 on.
//!
//! Same operations as `tri4_sse` and `Avx2::node`, lane for lane, so the same bits: the
//! 512-bit and mask-register forms of the same IEEE instructions with SSE's comparison
//! predicates (`cmpeq` EQ_OQ, `cmplt` LT_OS, `cmpgt` GT_OS, `cmpneq` NEQ_UQ, `cmple` LE_OQ).

use super::sse::tri4_sse;
use super::{Avx2, Isa};
use crate::accel::tri4::{concat_hits, Tri4, Tri4Hits, TriHits, TriRay};
use crate::accel::wide::{NodeRay, WideNode, FAR_SCALE};
use std::arch::x86_64::*;

#[derive(Clone, Copy, Debug)]
pub struct Avx512;

unsafe impl Isa for Avx512 {
    #[inline(always)]
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, dist: &mut [f32; W]) -> u32 {
        if W != 8 {
            return Avx2::node(node, r, t_max, dist);
        }
        let o = [_mm256_set1_ps(r.o[0]), _mm256_set1_ps(r.o[1]), _mm256_set1_ps(r.o[2])];
        let inv = [_mm256_set1_ps(r.inv[0]), _mm256_set1_ps(r.inv[1]), _mm256_set1_ps(r.inv[2])];
        // SAFETY: `row < 6` (the contract of `Isa::node`) and W = 8; the node is 32-byte
        // aligned and each row is 32 bytes, as the aligned load needs.
        let slab = |row: usize, a: usize| {
            _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds.get_unchecked(row).as_ptr()), o[a]), inv[a])
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
        _mm256_storeu_ps(dist.as_mut_ptr(), t_near);
        _mm256_cmp_ps_mask::<_CMP_LE_OQ>(t_near, _mm256_mul_ps(t_far, _mm256_set1_ps(FAR_SCALE))) as u32
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_sse(block, r, t_min, t_max)
    }

    #[inline(always)]
    unsafe fn tri8(lo: &Tri4, hi: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> TriHits<8> {
        Avx2::tri8(lo, hi, r, t_min, t_max)
    }

    const BLOCKS_PER_TEST: usize = 4;

    #[inline(always)]
    unsafe fn tri16(blocks: [&Tri4; 4], r: &TriRay, t_min: f32, t_max: f32) -> TriHits<16> {
        tri16_avx512(blocks, r, t_min, t_max)
    }

    #[inline(always)]
    unsafe fn compress_refs<const W: usize>(children: &[u32; W], mask: u32, out: *mut u32) -> usize {
        if W != 8 {
            return Avx2::compress_refs(children, mask, out);
        }
        // SAFETY: W = 8: `children` is one 256-bit vector, and `out` is valid for writes of
        // eight `u32`s (the caller's contract); both accesses are unaligned ones.
        let refs = _mm256_loadu_si256(children.as_ptr().cast());
        _mm256_storeu_si256(out.cast(), _mm256_maskz_compress_epi32(mask as u8, refs));
        (mask & 0xff).count_ones() as usize
    }
}

/// The watertight test on four blocks at once, operation for operation as `tri4_sse` (and
/// so `tri_lane`) on each block.
#[inline(always)]
unsafe fn tri16_avx512(blocks: [&Tri4; 4], r: &TriRay, t_min: f32, t_max: f32) -> TriHits<16> {
    let [kx, ky, kz] = r.k;
    // SAFETY: `TriRay` axes are < 3, and `Tri4` is 16-byte aligned with rows of four floats
    // at multiples of 16 bytes, as the aligned loads need.
    let rel = |k: usize, axis: usize| {
        let row = |i: usize| _mm_load_ps(blocks[i].v[k].get_unchecked(axis).as_ptr());
        let v = _mm512_castps128_ps512(row(0));
        let v = _mm512_insertf32x4::<1>(v, row(1));
        let v = _mm512_insertf32x4::<2>(v, row(2));
        let v = _mm512_insertf32x4::<3>(v, row(3));
        _mm512_sub_ps(v, _mm512_set1_ps(*r.o.get_unchecked(axis)))
    };
    let (a_x, a_y, a_z) = (rel(0, kx), rel(0, ky), rel(0, kz));
    let (b_x, b_y, b_z) = (rel(1, kx), rel(1, ky), rel(1, kz));
    let (c_x, c_y, c_z) = (rel(2, kx), rel(2, ky), rel(2, kz));
    let (sx, sy, sz) = (_mm512_set1_ps(r.s[0]), _mm512_set1_ps(r.s[1]), _mm512_set1_ps(r.s[2]));
    let ax = _mm512_sub_ps(a_x, _mm512_mul_ps(sx, a_z));
    let ay = _mm512_sub_ps(a_y, _mm512_mul_ps(sy, a_z));
    let bx = _mm512_sub_ps(b_x, _mm512_mul_ps(sx, b_z));
    let by = _mm512_sub_ps(b_y, _mm512_mul_ps(sy, b_z));
    let cx = _mm512_sub_ps(c_x, _mm512_mul_ps(sx, c_z));
    let cy = _mm512_sub_ps(c_y, _mm512_mul_ps(sy, c_z));
    let u = _mm512_sub_ps(_mm512_mul_ps(cx, by), _mm512_mul_ps(cy, bx));
    let v = _mm512_sub_ps(_mm512_mul_ps(ax, cy), _mm512_mul_ps(ay, cx));
    let w = _mm512_sub_ps(_mm512_mul_ps(bx, ay), _mm512_mul_ps(by, ax));
    let zero = _mm512_setzero_ps();
    let eq = |x| _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(x, zero);
    let lt = |x| _mm512_cmp_ps_mask::<_CMP_LT_OS>(x, zero);
    let gt = |x| _mm512_cmp_ps_mask::<_CMP_GT_OS>(x, zero);
    let zero_bits = eq(u) | eq(v) | eq(w);
    // Inside unless some edge function is negative and some positive.
    let outside = (lt(u) | lt(v) | lt(w)) & (gt(u) | gt(v) | gt(w));
    if zero_bits == 0 && outside == 0xffff {
        // Most groups: the ray passes outside all sixteen triangles.
        return TriHits::NONE;
    }
    if zero_bits != 0 {
        // An edge function is exactly zero: each block as the four-lane kernel does it
        // (which redoes such a block in double precision).
        let [a, b, c, d] = blocks;
        let each = |blk| tri4_sse(blk, r, t_min, t_max);
        return concat_hits(&[each(a), each(b), each(c), each(d)]);
    }
    let det = _mm512_add_ps(_mm512_add_ps(u, v), w);
    let ok = _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(det, zero);
    let t_scaled = _mm512_add_ps(
        _mm512_add_ps(_mm512_mul_ps(u, _mm512_mul_ps(sz, a_z)), _mm512_mul_ps(v, _mm512_mul_ps(sz, b_z))),
        _mm512_mul_ps(w, _mm512_mul_ps(sz, c_z)),
    );
    let inv = _mm512_div_ps(_mm512_set1_ps(1.0), det);
    let t = _mm512_mul_ps(t_scaled, inv);
    let in_range = _mm512_cmp_ps_mask::<_CMP_GT_OS>(t, _mm512_set1_ps(t_min))
        & _mm512_cmp_ps_mask::<_CMP_LT_OS>(t, _mm512_set1_ps(t_max));
    let mask = (ok & in_range & !outside) as u32;
    let mut h = TriHits::<16> { mask, ..TriHits::NONE };
    if mask != 0 {
        _mm512_storeu_ps(h.t.as_mut_ptr(), t);
        _mm512_storeu_ps(h.b1.as_mut_ptr(), _mm512_mul_ps(v, inv));
        _mm512_storeu_ps(h.b2.as_mut_ptr(), _mm512_mul_ps(w, inv));
    }
    h
}
