//! The portable path: one lane at a time, with the same operations (and the same NaN
//! behaviour of min/max) as the SIMD paths, so it returns the same answers on any CPU.

use super::Isa;
use crate::accel::tri4::{tri4_scalar, Tri4, Tri4Hits, TriRay};
use crate::accel::wide::{NodeRay, WideNode};

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
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max_far: f32, dist: &mut [f32; W]) -> u32 {
        let mut mask = 0;
        for i in 0..W {
            let near = |a: usize| (node.bounds[r.near[a]][i] - r.o[a]) * r.inv[a];
            let far = |a: usize| (node.bounds[r.far[a]][i] - r.o[a]) * r.inv_far[a];
            let t_near = max_ps(max_ps(near(0), near(1)), max_ps(near(2), r.t_min));
            let t_far = min_ps(min_ps(far(0), far(1)), min_ps(far(2), t_max_far));
            dist[i] = t_near;
            mask |= ((t_near <= t_far) as u32) << i;
        }
        mask
    }

    #[inline(always)]
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
        tri4_scalar(block, r, t_min, t_max)
    }
}
