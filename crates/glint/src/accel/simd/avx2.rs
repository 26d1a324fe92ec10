//! AVX2: eight lanes per instruction, so an 8-wide node is one pass. Triangle blocks use the
//! SSE kernel, which compiles to VEX-encoded 128-bit code here.

use super::sse::tri4_sse;
use super::Isa;
use crate::accel::tri4::{Tri4, Tri4Hits, TriRay};
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
        let o = [_mm256_set1_ps(r.o[0]), _mm256_set1_ps(r.o[1]), _mm256_set1_ps(r.o[2])];
        let inv = [_mm256_set1_ps(r.inv[0]), _mm256_set1_ps(r.inv[1]), _mm256_set1_ps(r.inv[2])];
        let (t_min, t_max, scale) = (_mm256_set1_ps(r.t_min), _mm256_set1_ps(t_max), _mm256_set1_ps(FAR_SCALE));
        for c in 0..W / 8 {
            // SAFETY: `row < 6` (the contract of `Isa::node`) and `8 * c + 8 <= W`; the node
            // is 32-byte aligned and each row is `W * 4` bytes, a multiple of 32, as the
            // aligned load needs.
            let slab = |row: usize, a: usize| {
                _mm256_mul_ps(
                    _mm256_sub_ps(_mm256_load_ps(node.bounds.get_unchecked(row).as_ptr().add(8 * c)), o[a]),
                    inv[a],
                )
            };
            let t_near = _mm256_max_ps(
                slab(r.near[0], 0),
                _mm256_max_ps(slab(r.near[1], 1), _mm256_max_ps(slab(r.near[2], 2), t_min)),
            );
            let t_far = _mm256_min_ps(
                slab(r.far[0], 0),
                _mm256_min_ps(slab(r.far[1], 1), _mm256_min_ps(slab(r.far[2], 2), t_max)),
            );
            _mm256_storeu_ps(dist.as_mut_ptr().add(8 * c), t_near);
            mask |= (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, _mm256_mul_ps(t_far, scale))) as u32)
                << (8 * c);
        }
        mask
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_sse(block, r, t_min, t_max)
    }
}
