//! SSE2 (baseline x86-64): four lanes per instruction. An 8-wide node takes two passes.

use super::Isa;
use crate::accel::tri4::{tri4_scalar, Tri4, Tri4Hits, TriRay};
use crate::accel::wide::{NodeRay, WideNode, FAR_SCALE};
use std::arch::x86_64::*;

#[derive(Clone, Copy, Debug)]
pub struct Sse;

unsafe impl Isa for Sse {
    #[inline(always)]
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, dist: &mut [f32; W]) -> u32 {
        let mut mask = 0u32;
        let o = [_mm_set1_ps(r.o[0]), _mm_set1_ps(r.o[1]), _mm_set1_ps(r.o[2])];
        let inv = [_mm_set1_ps(r.inv[0]), _mm_set1_ps(r.inv[1]), _mm_set1_ps(r.inv[2])];
        let (t_min, t_max, scale) = (_mm_set1_ps(r.t_min), _mm_set1_ps(t_max), _mm_set1_ps(FAR_SCALE));
        for c in 0..W / 4 {
            // SAFETY: `node.bounds[row]` is checked; `4 * c + 4 <= W`; the node is 32-byte
            // aligned and each row is `W * 4` bytes, a multiple of 16, as the aligned load needs.
            let slab = |row: usize, a: usize| {
                _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[row].as_ptr().add(4 * c)), o[a]), inv[a])
            };
            // NaN slabs (ray in a slab's plane) lose to the other operand: conservative.
            let t_near =
                _mm_max_ps(slab(r.near[0], 0), _mm_max_ps(slab(r.near[1], 1), _mm_max_ps(slab(r.near[2], 2), t_min)));
            let t_far =
                _mm_min_ps(slab(r.far[0], 0), _mm_min_ps(slab(r.far[1], 1), _mm_min_ps(slab(r.far[2], 2), t_max)));
            _mm_storeu_ps(dist.as_mut_ptr().add(4 * c), t_near);
            mask |= (_mm_movemask_ps(_mm_cmple_ps(t_near, _mm_mul_ps(t_far, scale))) as u32) << (4 * c);
        }
        mask
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_sse(block, r, t_min, t_max)
    }
}

/// The watertight test on four triangles, operation for operation as `tri_lane`.
#[inline(always)]
pub(super) unsafe fn tri4_sse(b: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
    let [kx, ky, kz] = r.k;
    // SAFETY: `TriRay` axes are < 3.
    let rel = |k: usize, axis: usize| {
        _mm_sub_ps(_mm_load_ps(b.v[k].get_unchecked(axis).as_ptr()), _mm_set1_ps(*r.o.get_unchecked(axis)))
    };
    let (a_x, a_y, a_z) = (rel(0, kx), rel(0, ky), rel(0, kz));
    let (b_x, b_y, b_z) = (rel(1, kx), rel(1, ky), rel(1, kz));
    let (c_x, c_y, c_z) = (rel(2, kx), rel(2, ky), rel(2, kz));
    let (sx, sy, sz) = (_mm_set1_ps(r.s[0]), _mm_set1_ps(r.s[1]), _mm_set1_ps(r.s[2]));
    let ax = _mm_sub_ps(a_x, _mm_mul_ps(sx, a_z));
    let ay = _mm_sub_ps(a_y, _mm_mul_ps(sy, a_z));
    let bx = _mm_sub_ps(b_x, _mm_mul_ps(sx, b_z));
    let by = _mm_sub_ps(b_y, _mm_mul_ps(sy, b_z));
    let cx = _mm_sub_ps(c_x, _mm_mul_ps(sx, c_z));
    let cy = _mm_sub_ps(c_y, _mm_mul_ps(sy, c_z));
    let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
    let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
    let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
    let zero = _mm_setzero_ps();
    let any_zero = _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)), _mm_cmpeq_ps(w, zero));
    let neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
    let pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
    let inside = _mm_andnot_ps(_mm_and_ps(neg, pos), _mm_castsi128_ps(_mm_set1_epi32(-1)));
    let zero_bits = _mm_movemask_ps(any_zero);
    if zero_bits | _mm_movemask_ps(inside) == 0 {
        // Most blocks: the ray passes outside every triangle.
        return Tri4Hits::NONE;
    }
    if zero_bits != 0 {
        // An edge function is exactly zero (ray through an edge or vertex): the reference
        // redoes it in double precision; so do we, lane by lane.
        return tri4_scalar(b, r, t_min, t_max);
    }
    let det = _mm_add_ps(_mm_add_ps(u, v), w);
    let mut ok = _mm_and_ps(inside, _mm_cmpneq_ps(det, zero));
    let t_scaled = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(u, _mm_mul_ps(sz, a_z)), _mm_mul_ps(v, _mm_mul_ps(sz, b_z))),
        _mm_mul_ps(w, _mm_mul_ps(sz, c_z)),
    );
    let inv = _mm_div_ps(_mm_set1_ps(1.0), det);
    let t = _mm_mul_ps(t_scaled, inv);
    ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(t_min)), _mm_cmplt_ps(t, _mm_set1_ps(t_max))));
    let mut h = Tri4Hits { mask: _mm_movemask_ps(ok) as u32, ..Tri4Hits::NONE };
    if h.mask != 0 {
        _mm_storeu_ps(h.t.as_mut_ptr(), t);
        _mm_storeu_ps(h.b1.as_mut_ptr(), _mm_mul_ps(v, inv));
        _mm_storeu_ps(h.b2.as_mut_ptr(), _mm_mul_ps(w, inv));
    }
    h
}
