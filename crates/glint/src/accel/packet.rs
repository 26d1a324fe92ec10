//! Occlusion of packets of rays: up to [`Lanes::N`] rays traverse the wide BVH together, one
//! ray per lane, so that a node is loaded once for all of them and the loop's bookkeeping
//! (stack, masks, branches) is shared.
//!
//! A node's W children are tested one at a time against all the packet's rays: lane i
//! computes, for ray i and that child, exactly the slab test of the single-ray kernels (the
//! same near and far rows, chosen per lane by the direction's sign, the same operations and
//! the same `maxps` rule), so a ray's bit says what the single-ray test would say. Leaves
//! are tested ray by ray through the single-ray triangle kernels. Where fewer than
//! [`SINGLE_BELOW`] rays are still active at a node, each goes on alone from there through
//! the single-ray traversal (as Embree's hybrid traversal does), which wastes no lanes.
//!
//! Any-hit queries do not shorten rays, so which boxes a ray passes does not depend on the
//! order nodes are visited in: a ray is reported blocked exactly when some leaf it reaches
//! through boxes it passes holds a triangle it hits, the single-ray answer (the tests compare
//! them ray by ray, special rays included).
//!
//! Closest-hit packets ([`WideBvh::intersect_packet`]) visit nodes in another order than a
//! single ray does (children by the entry distance of the packet's first active ray), and
//! each ray's `t_max` shrinks as its leaf tests find hits, culling the boxes it enters
//! beyond. The tie rule (smallest `(t, primitive)`, see [`ClosestLeaf`]) makes a ray's answer
//! independent of that order, so it is the single-ray answer bit for bit.

use super::simd::Isa;
use super::wide::{
    leaf_mask, leaf_range, AnyLeaf, ClosestLeaf, NodeRay, WideBvh, WideNode, EMPTY_CHILD, FAR_SCALE, LEAF_BIT, STACK,
};
use crate::math::lanes::{Lanes, MAX_LANES};
use crate::math::Ray;
use std::mem::MaybeUninit;

/// Active rays at a node below which they leave the packet and go on one by one. Measured
/// (BENCHMARKS.md, "SIMD lanes and packets of shadow rays": 2 was best or tied on all six ray sets).
pub const SINGLE_BELOW: u32 = 2;

/// What a packet traversal tests at a leaf: lane `lane`'s ray, through the single-ray leaf
/// test (which is also what the single-ray fall-back uses).
pub trait PacketLeaf {
    type Single: AnyLeaf;
    fn single(&self, lane: usize) -> Self::Single;
}

/// The packet's rays in lanes: what [`NodeRay`] holds per ray, one vector per component,
/// and whether each direction component is negative (which slab row is the near one).
struct PacketRays<L: Lanes> {
    o: [L::F; 3],
    inv: [L::F; 3],
    neg: [L::M; 3],
    t_min: L::F,
    t_max: L::F,
}

impl<L: Lanes> PacketRays<L> {
    /// Lanes past `nrs.len()` repeat ray 0 (their bits are never used).
    #[inline(always)]
    fn new(l: L, nrs: &[NodeRay], rays: &[Ray]) -> PacketRays<L> {
        let mut soa = [[0.0f32; MAX_LANES]; 8];
        #[allow(clippy::needless_range_loop)] // lane `i` of eight arrays
        for i in 0..L::N {
            let k = if i < nrs.len() { i } else { 0 };
            let nr = &nrs[k];
            for a in 0..3 {
                soa[a][i] = nr.o[a];
                soa[3 + a][i] = nr.inv[a];
            }
            soa[6][i] = nr.t_min;
            soa[7][i] = rays[k].t_max;
        }
        let inv = [l.load(&soa[3]), l.load(&soa[4]), l.load(&soa[5])];
        PacketRays {
            o: [l.load(&soa[0]), l.load(&soa[1]), l.load(&soa[2])],
            inv,
            // `NodeRay::new` takes the near row from the sign of the reciprocal.
            neg: [l.sign(inv[0]), l.sign(inv[1]), l.sign(inv[2])],
            t_min: l.load(&soa[6]),
            t_max: l.load(&soa[7]),
        }
    }

    /// The rays that pass child `c`'s box: per lane, the single-ray kernels' slab test.
    #[inline(always)]
    fn hits<const W: usize>(&self, l: L, node: &WideNode<W>, c: usize) -> u32 {
        self.hits_near(l, node, c).0
    }

    /// [`PacketRays::hits`] and each lane's entry distance (what the single-ray kernels
    /// keep in `dist` to cull the box later).
    #[inline(always)]
    fn hits_near<const W: usize>(&self, l: L, node: &WideNode<W>, c: usize) -> (u32, L::F) {
        // No closures here: a closure is compiled apart from the `#[target_feature]` caller,
        // and its intrinsics become calls.
        let mut near = [l.splat(0.0); 3];
        let mut far = [l.splat(0.0); 3];
        for a in 0..3 {
            let lo = l.mul(l.sub(l.splat(node.bounds[a][c]), self.o[a]), self.inv[a]);
            let hi = l.mul(l.sub(l.splat(node.bounds[3 + a][c]), self.o[a]), self.inv[a]);
            near[a] = l.select(self.neg[a], hi, lo);
            far[a] = l.select(self.neg[a], lo, hi);
        }
        let t_near = l.max(near[0], l.max(near[1], l.max(near[2], self.t_min)));
        let t_far = l.min(far[0], l.min(far[1], l.min(far[2], self.t_max)));
        (l.bits(l.le(t_near, l.mul(t_far, l.splat(FAR_SCALE)))), t_near)
    }

    /// The lanes whose entry distance `t_near` is not beyond their (shortened) `t_max`: the
    /// single-ray kernels' `dist <= t_max * FAR_SCALE` per lane (false for NaN).
    #[inline(always)]
    fn within(&self, l: L, t_near: L::F) -> u32 {
        l.bits(l.le(t_near, l.mul(self.t_max, l.splat(FAR_SCALE))))
    }
}

impl<const W: usize> WideBvh<W> {
    /// Which of `rays` (at most `L::N`) are blocked: bit i for `rays[i]`, each exactly
    /// [`WideBvh::occluded`]'s answer; `leaf` tests a lane's ray at a leaf.
    ///
    /// Rays leave the packet at nodes where fewer than `single_below` are active (see the
    /// module doc; the answers do not depend on it).
    ///
    /// Panics if `rays` is empty or longer than `L::N`.
    ///
    /// # Safety
    /// `S` must be available on this CPU (see [`Isa`]).
    #[inline(always)]
    pub unsafe fn occluded_packet<S: Isa, L: Lanes, P: PacketLeaf>(
        &self,
        l: L,
        rays: &[Ray],
        leaf: &P,
        single_below: u32,
    ) -> u32 {
        let n = rays.len();
        assert!(n >= 1 && n <= L::N, "occluded_packet: 1 to {} rays", L::N);
        let root = self.root();
        if root == EMPTY_CHILD {
            return 0;
        }
        let mut nrs = [NodeRay::new(&rays[0]); MAX_LANES];
        for (nr, ray) in nrs.iter_mut().zip(rays).skip(1) {
            *nr = NodeRay::new(ray);
        }
        let nrs = &nrs[..n];
        let packet = PacketRays::<L>::new(l, nrs, rays);
        let all = u32::MAX >> (32 - n);
        let mut blocked = 0u32;
        let nodes: &[WideNode<W>] = self.nodes();
        let mut stack: [MaybeUninit<(u32, u32)>; STACK] = [const { MaybeUninit::uninit() }; STACK];
        let mut sp = 0usize;
        let (mut cur, mut active) = (root, all);
        loop {
            if cur & LEAF_BIT != 0 {
                // Only the root is reached as a leaf (leaf children are tested in their
                // parent); untraceable rays skip it as the single-ray traversal does.
                for i in lanes(active) {
                    if !nrs[i].t_min.is_nan() && test_leaf(leaf, i, cur, rays) {
                        blocked |= 1 << i;
                    }
                }
            } else if active.count_ones() < single_below {
                for i in lanes(active) {
                    // SAFETY: `cur` is a node index that ray i's slab test passed (the root, or
                    // a child reference followed below), `S` is available (this function's
                    // contract), and `nrs[i]` is ray i's.
                    if unsafe { self.occluded_from::<S>(cur, &rays[i], &nrs[i], &mut leaf.single(i)) } {
                        blocked |= 1 << i;
                    }
                }
            } else {
                // SAFETY: `cur` is the root or a reference without the leaf bit from a slot
                // that some ray's slab test passed; empty slots are never passed (see
                // `NodeRay::new`: lane i computes ray i's single-ray test), and `collapse` wrote
                // every other such reference as the index of a node it pushed.
                let node = unsafe { nodes.get_unchecked(cur as usize) };
                let leaf_bits = leaf_mask(node);
                let mut passed = [0u32; W];
                for (c, m) in passed.iter_mut().enumerate() {
                    // `collapse` fills a node's slots in order: the first empty one ends them.
                    if node.children[c] == EMPTY_CHILD {
                        break;
                    }
                    *m = packet.hits(l, node, c) & active;
                }
                // Leaves first, as the single-ray traversal does: a hit may end lanes.
                for c in lanes(leaf_bits) {
                    for i in lanes(passed[c] & !blocked) {
                        if test_leaf(leaf, i, node.children[c], rays) {
                            blocked |= 1 << i;
                        }
                    }
                }
                if blocked == all {
                    return blocked;
                }
                let mut next: Option<(u32, u32)> = None;
                for c in lanes(!leaf_bits & (u32::MAX >> (32 - W))) {
                    let m = passed[c] & !blocked;
                    if m == 0 {
                        continue;
                    }
                    match next {
                        None => next = Some((node.children[c], m)),
                        Some(_) => {
                            // SAFETY: a node pushes at most W - 1 entries (one child goes on
                            // as `cur`), the bound of the single-ray traversal's stack (see
                            // `STACK`), which `collapse` checked against the tree's depth.
                            unsafe { stack.get_unchecked_mut(sp).write((node.children[c], m)) };
                            sp += 1;
                        }
                    }
                }
                if let Some((c, m)) = next {
                    (cur, active) = (c, m);
                    continue;
                }
            }
            loop {
                if sp == 0 {
                    return blocked;
                }
                sp -= 1;
                // SAFETY: entries `0..sp` were written above.
                let (c, m) = unsafe { stack.get_unchecked(sp).assume_init() };
                if m & !blocked != 0 {
                    (cur, active) = (c, m & !blocked);
                    break;
                }
            }
        }
    }

    /// Closest hits of `rays` (at most `L::N`) in a packet: `leaves[i]` is ray i's leaf
    /// state (it records the hit, see [`ClosestLeaf`]) and `rays[i].t_max` shrinks as the
    /// single-ray traversal's does; each ray ends with the hit [`WideBvh::traverse`] gives it,
    /// bit for bit, by the tie rule (module doc). Rays leave the packet at nodes where fewer
    /// than `single_below` are active.
    ///
    /// Panics if `rays` is empty, longer than `L::N` or than `leaves`.
    ///
    /// # Safety
    /// `S` must be available on this CPU (see [`Isa`]).
    #[inline(always)]
    pub unsafe fn intersect_packet<S: Isa, L: Lanes, C: ClosestLeaf>(
        &self,
        l: L,
        rays: &mut [Ray],
        leaves: &mut [C],
        single_below: u32,
    ) {
        let n = rays.len();
        assert!(n >= 1 && n <= L::N && leaves.len() >= n, "intersect_packet: 1 to {} rays, a leaf each", L::N);
        let root = self.root();
        if root == EMPTY_CHILD {
            return;
        }
        let mut nrs = [NodeRay::new(&rays[0]); MAX_LANES];
        for (nr, ray) in nrs.iter_mut().zip(rays.iter()).skip(1) {
            *nr = NodeRay::new(ray);
        }
        let nrs = &nrs[..n];
        let mut packet = PacketRays::<L>::new(l, nrs, rays);
        // The lanes' `t_max`, reloaded into `packet` after leaf tests shorten some.
        let mut t_max = [0.0f32; MAX_LANES];
        l.store(packet.t_max, &mut t_max);
        let all = u32::MAX >> (32 - n);
        let nodes: &[WideNode<W>] = self.nodes();
        // (node, its active rays, their entry distances into its box).
        let mut stack: [MaybeUninit<(u32, u32, L::F)>; STACK] = [const { MaybeUninit::uninit() }; STACK];
        let mut sp = 0usize;
        let (mut cur, mut active) = (root, all);
        loop {
            if cur & LEAF_BIT != 0 {
                // The root as a leaf (see `occluded_packet`).
                for i in lanes(active) {
                    if !nrs[i].t_min.is_nan() {
                        let (first, count) = leaf_range(cur);
                        leaves[i].test(first, count, &mut rays[i]);
                    }
                }
            } else if active.count_ones() < single_below {
                for i in lanes(active) {
                    // SAFETY: `cur` is a node index that ray i's slab test passed (the root, or
                    // a child reference followed below), `S` is available (this function's
                    // contract), and `nrs[i]` is ray i's.
                    unsafe { self.traverse_from::<S>(cur, &mut rays[i], &nrs[i], &mut leaves[i]) };
                    t_max[i] = rays[i].t_max;
                }
                packet.t_max = l.load(&t_max);
            } else {
                // SAFETY: as in `occluded_packet`: `cur` is the root or a node reference from a
                // slot that some active ray's slab test passed.
                let node = unsafe { nodes.get_unchecked(cur as usize) };
                let leaf_bits = leaf_mask(node);
                let mut passed = [0u32; W];
                let mut near = [l.splat(0.0); W];
                let mut lane_leaves = [0u32; MAX_LANES];
                let mut any_leaf = false;
                for c in 0..W {
                    // `collapse` fills a node's slots in order: the first empty one ends them.
                    if node.children[c] == EMPTY_CHILD {
                        break;
                    }
                    let (bits, t_near) = packet.hits_near(l, node, c);
                    passed[c] = bits & active;
                    near[c] = t_near;
                    if leaf_bits >> c & 1 != 0 {
                        for i in lanes(passed[c]) {
                            lane_leaves[i] |= 1 << c;
                            any_leaf = true;
                        }
                    }
                }
                // Leaves first, as the single-ray traversal does, each ray's through its own
                // leaf state; a hit shortens the ray and culls the subtrees behind it.
                if any_leaf {
                    for i in lanes(active) {
                        if lane_leaves[i] != 0 {
                            leaves[i].test_leaves(&node.children, lane_leaves[i], &mut rays[i]);
                            t_max[i] = rays[i].t_max;
                        }
                    }
                    packet.t_max = l.load(&t_max);
                }
                // Interior children in the order of the first active ray's entry distances,
                // nearest on top (any order gives the same answers).
                let key_lane = active.trailing_zeros() as usize;
                let mut order = [(0u32, 0.0f32); W];
                let mut k = 0usize;
                let mut key = [0.0f32; MAX_LANES];
                for c in lanes(!leaf_bits & (u32::MAX >> (32 - W))) {
                    let m = if any_leaf { passed[c] & packet.within(l, near[c]) } else { passed[c] };
                    if m == 0 {
                        continue;
                    }
                    passed[c] = m;
                    l.store(near[c], &mut key);
                    let d = key[key_lane];
                    // Insertion by descending distance (NaN keys, of rays that do not pass,
                    // compare false and stay where they are).
                    let mut j = k;
                    while j > 0 && order[j - 1].1 < d {
                        order[j] = order[j - 1];
                        j -= 1;
                    }
                    order[j] = (c as u32, d);
                    k += 1;
                }
                if k > 0 {
                    for &(c, _) in &order[..k - 1] {
                        let c = c as usize;
                        // SAFETY: a node pushes at most W - 1 entries (one child goes on as
                        // `cur`), the single-ray traversal's bound (see `STACK`), which
                        // `collapse` checked against the tree's depth.
                        unsafe { stack.get_unchecked_mut(sp).write((node.children[c], passed[c], near[c])) };
                        sp += 1;
                    }
                    let c = order[k - 1].0 as usize;
                    (cur, active) = (node.children[c], passed[c]);
                    continue;
                }
            }
            // Pop, dropping the rays whose hits lie before the entry.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: entries `0..sp` were written above.
                let (c, m, t_near) = unsafe { stack.get_unchecked(sp).assume_init() };
                let m = m & packet.within(l, t_near);
                if m != 0 {
                    (cur, active) = (c, m);
                    break;
                }
            }
        }
    }
}

/// Lane `i`'s ray against the leaf `child`, through the single-ray leaf test.
#[inline(always)]
fn test_leaf<P: PacketLeaf>(leaf: &P, i: usize, child: u32, rays: &[Ray]) -> bool {
    let (first, count) = leaf_range(child);
    leaf.single(i).test(first, count, &rays[i])
}

/// The set bits of `mask`, lowest first.
#[inline(always)]
fn lanes(mask: u32) -> Bits {
    Bits(mask)
}

struct Bits(u32);

impl Iterator for Bits {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let i = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(i)
    }
}
