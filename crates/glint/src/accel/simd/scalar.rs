//! The portable path: one lane at a time, with the same operations (and the same NaN
//! behaviour of min/max) as the SIMD paths, so it returns the same answers on any CPU.

use super::Isa;
use crate::accel::tri4::{tri4_scalar, Tri4, Tri4Hits, TriRay};
use crate::accel::wide::{NodeRay, WideNode, FAR_SCALE};

#[derive(Clone, Copy, Debug)]
pub struct Scalar;

/// `maxps` semantics: the second operand when either is NaN.
#[inline(always)]
fn max_ps(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline(always)]
fn min_ps(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

unsafe impl Isa for Scalar {
    #[inline(always)]
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, dist: &mut [f32; W]) -> u32 {
        let mut mask = 0;
        #[allow(clippy::needless_range_loop)] // lane `i` of several arrays
        for i in 0..W {
            let slab = |row: usize, a: usize| (node.bounds[row][i] - r.o[a]) * r.inv[a];
            let t_near = max_ps(slab(r.near[0], 0), max_ps(slab(r.near[1], 1), max_ps(slab(r.near[2], 2), r.t_min)));
            let t_far = min_ps(slab(r.far[0], 0), min_ps(slab(r.far[1], 1), min_ps(slab(r.far[2], 2), t_max)));
            dist[i] = t_near;
            mask |= ((t_near <= t_far * FAR_SCALE) as u32) << i;
        }
        mask
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_scalar(block, r, t_min, t_max)
    }
}
