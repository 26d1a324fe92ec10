//! AVX-512 (F and VL): the node test compares straight into a mask register, and any-hit
//! traversal pushes a node's hit children with one compress. The triangle tests are the AVX2
//! path's, compiled with AVX-512 on: four blocks in one 16-lane test were measured 13 to 17%
//! slower on closest hits than two blocks in one 8-lane test (BENCHMARKS.md, Sapphire Rapids).
//!
//! The node test is `Avx2::node`'s slab arithmetic (`avx2::slabs8`) with the mask-register
//! form of the same comparison (`cmple`, LE_OQ), so the same bits.

use super::avx2::slabs8;
use super::sse::tri4_sse;
use super::{Avx2, Isa};
use crate::accel::tri4::{Tri4, Tri4Hits, TriHits, TriRay};
use crate::accel::wide::{NodeRay, WideNode};
use std::arch::x86_64::*;

#[derive(Clone, Copy, Debug)]
pub struct Avx512;

unsafe impl Isa for Avx512 {
    #[inline(always)]
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, dist: &mut [f32; W]) -> u32 {
        if W != 8 {
            return Avx2::node(node, r, t_max, dist);
        }
        // SAFETY: this path runs only where AVX2 is available too (`SimdPath::is_available`);
        // W = 8, and the rows are the caller's (`Isa::node`).
        let (t_near, t_far) = slabs8(node, r, t_max, 0);
        _mm256_storeu_ps(dist.as_mut_ptr(), t_near);
        _mm256_cmp_ps_mask::<_CMP_LE_OQ>(t_near, t_far) as u32
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_sse(block, r, t_min, t_max)
    }

    #[inline(always)]
    unsafe fn tri8(lo: &Tri4, hi: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> TriHits<8> {
        Avx2::tri8(lo, hi, r, t_min, t_max)
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
