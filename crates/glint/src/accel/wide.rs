//! A W-wide BVH (W = 4 or 8) collapsed from the binary SAH BVH, with child boxes stored
//! structure-of-arrays so that one SIMD instruction handles one slab of all children.
//!
//! Collapse (as in Embree's BVH4/8 and tinybvh): a wide node takes the children of a binary
//! node and keeps replacing its largest-area interior child by that child's two children
//! until it has W children or only leaves. Traversal tests a node's hit leaf children at once,
//! then visits its hit interior children nearest first, and culls popped entries that lie
//! beyond the closest hit found so far.
//!
//! The tree does not know what its leaves hold: a leaf is a range `(first, count)` of
//! "items" (blocks of four triangles for a mesh, primitive indices for the scene's top
//! level) that the caller's closure tests.

use super::bvh::{Bvh, BvhNode, MAX_DEPTH, SAH_INTERSECT_COST, SAH_TRAVERSAL_COST};
use super::huge_pages::PageBuf;
use super::simd::Isa;
use crate::math::{Aabb, Ray};
use std::mem::MaybeUninit;

/// Child reference: a node index, or (top bit set) a leaf with `count - 1` in bits 27..31
/// and `first` in bits 0..27.
pub const LEAF_BIT: u32 = 1 << 31;
const COUNT_SHIFT: u32 = 27;
const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;
/// Most items one leaf can reference.
pub const MAX_LEAF_ITEMS: usize = 16;
/// An unused child slot. It has the leaf bit set, but its range is not valid: soundness
/// rests on no ray ever hitting its empty box, which [`NodeRay::new`] guarantees.
pub(super) const EMPTY_CHILD: u32 = u32::MAX;

#[inline(always)]
pub fn leaf_ref(first: usize, count: usize) -> u32 {
    assert!((1..=MAX_LEAF_ITEMS).contains(&count) && first <= FIRST_MASK as usize, "leaf out of range");
    LEAF_BIT | ((count as u32 - 1) << COUNT_SHIFT) | first as u32
}

#[inline(always)]
pub fn leaf_range(child: u32) -> (u32, u32) {
    (child & FIRST_MASK, ((child >> COUNT_SHIFT) & 0xF) + 1)
}

/// Pushes the children that `mask` selects (bits below W) with their entry distances onto a
/// closest-hit stack at `out[0..n]` and returns n, the number of set bits: each in slot order
/// goes below the entries nearer than it, so the nearest ends on top and equal distances keep
/// slot order, the later slot higher. One routine for the single-ray and batch traversals, so
/// both visit the same nodes. (Placing each by its rank from two AVX-512 mask compares, with
/// no data-dependent loop, was 3 to 8% slower: BENCHMARKS.md.)
///
/// # Safety
/// `out` must be valid for writes of as many entries as `mask` has bits below W.
#[inline(always)]
pub(super) unsafe fn push_nearest_last<const W: usize>(
    children: &[u32; W],
    dist: &[f32; W],
    mask: u32,
    out: *mut (u32, f32),
) -> usize {
    let mut n = 0;
    let mut m = mask & (u32::MAX >> (32 - W));
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        let d = dist[i];
        let mut j = n;
        // SAFETY: entries `0..n` were written by this loop, and `n` < the number of set bits,
        // for which `out` is valid (the caller's contract).
        unsafe {
            while j > 0 && (*out.add(j - 1)).1 < d {
                *out.add(j) = *out.add(j - 1);
                j -= 1;
            }
            out.add(j).write((children[i], d));
        }
        n += 1;
    }
    n
}

/// One node: `bounds[0..3]` are the children's min x, y, z and `bounds[3..6]` their max x,
/// y, z, each an array over children. Unused slots hold an empty box, which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct WideNode<const W: usize> {
    pub bounds: [[f32; W]; 6],
    pub children: [u32; W],
}

impl<const W: usize> WideNode<W> {
    const EMPTY: WideNode<W> = WideNode {
        bounds: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        children: [EMPTY_CHILD; W],
    };

    fn set_child(&mut self, i: usize, b: &Aabb, child: u32) {
        for a in 0..3 {
            self.bounds[a][i] = b.min[a];
            self.bounds[3 + a][i] = b.max[a];
        }
        self.children[i] = child;
    }

    pub fn child_bounds(&self, i: usize) -> Aabb {
        let v = |r: usize| crate::math::vec3(self.bounds[r][i], self.bounds[r + 1][i], self.bounds[r + 2][i]);
        Aabb { min: v(0), max: v(3) }
    }
}

/// Per-ray constants of the box test. `near[a]` is the row of `bounds` that the ray enters
/// through on axis `a` (min when the direction is positive), `far[a]` the one it leaves by,
/// so the test needs no min/max per slab.
///
/// A ray whose origin or direction is not finite gets `t_min = NaN`, which makes every box
/// test of every path fail (see [`NodeRay::new`]): such a ray hits nothing. That is what
/// keeps empty child slots from ever being reported hit (see `EMPTY_CHILD`).
#[derive(Clone, Copy, Debug)]
pub struct NodeRay {
    pub o: [f32; 3],
    pub inv: [f32; 3],
    pub near: [usize; 3],
    pub far: [usize; 3],
    pub t_min: f32,
}

impl NodeRay {
    /// Why empty slots (min = +inf, max = -inf) are never hit, for every ray:
    /// - Finite origin and direction: `inv` is non-zero and not NaN (±inf for a zero
    ///   component), so each near slab is `(±inf - o) * inv = +inf` exactly and each far slab
    ///   `-inf`: the entry distance is +inf, the exit -inf, and `+inf <= -inf` is false.
    /// - Otherwise `t_min` is NaN. Every path computes `t_near = max(sx, max(sy, max(sz,
    ///   t_min)))` with `maxps` semantics (the second operand when either is NaN), so
    ///   `t_near` is NaN and the ordered comparison `t_near <= t_far` is false for every child.
    /// - A NaN `t_min` or `t_max` in the ray itself fails the same way.
    #[inline(always)]
    pub fn new(ray: &Ray) -> NodeRay {
        let inv = [1.0 / ray.dir.x, 1.0 / ray.dir.y, 1.0 / ray.dir.z];
        let neg = |a: usize| inv[a].is_sign_negative() as usize;
        // `x - x` is 0 for finite `x` and NaN for ±inf and NaN: branch-free, and cheaper
        // than six `is_finite` tests on this per-ray path.
        let (o, d) = (ray.origin, ray.dir);
        #[allow(clippy::eq_op)] // `x - x` on purpose
        let zero_if_finite = ((o.x - o.x) + (o.y - o.y)) + ((o.z - o.z) + (d.x - d.x)) + ((d.y - d.y) + (d.z - d.z));
        let traceable = zero_if_finite == 0.0;
        NodeRay {
            o: ray.origin.to_array(),
            inv,
            near: [3 * neg(0), 1 + 3 * neg(1), 2 + 3 * neg(2)],
            far: [3 - 3 * neg(0), 4 - 3 * neg(1), 5 - 3 * neg(2)],
            t_min: if traceable { ray.t_min } else { f32::NAN },
        }
    }
}

/// Widening of the far distance that keeps boxes touched exactly by a ray (flat boxes,
/// rounding) from being missed; the same factor as the binary BVH's slab test.
#[allow(clippy::excessive_precision)] // the literal of the paper; rounds to 1 + 2 ulp
pub const FAR_SCALE: f32 = 1.000_000_24;

#[derive(Clone, Debug, Default)]
pub struct WideBvh<const W: usize> {
    /// Private: traversal relies on every child reference being in range.
    nodes: PageBuf<WideNode<W>>,
    /// The root: a node index, or a leaf when the whole tree is one leaf.
    root: u32,
    pub bounds: Aabb,
    /// Longest root-to-leaf path, in wide nodes (sizes the traversal stack).
    pub depth: usize,
}

/// Statistics of a wide tree, with the SAH cost in the binary tree's units: a wide node
/// costs one traversal step, a leaf one intersection per item.
#[derive(Clone, Debug, Default)]
pub struct WideStats {
    pub nodes: usize,
    pub leaves: usize,
    pub depth: usize,
    pub sah_cost: f64,
    pub node_bytes: usize,
    /// Mean number of used child slots per node.
    pub fill: f64,
}

/// What closest-hit traversal does at a leaf: test items `first..first + count`, shorten
/// `ray.t_max` on a hit and say whether there was one. A trait rather than a closure so that
/// implementations can be `#[inline(always)]`: a call per leaf would spill the vector
/// registers that hold the ray.
///
/// **The tie rule.** Every closest-hit kernel (single ray, batch, packet, the binary
/// reference and brute force) answers with the hit of smallest `(t, primitive)`: the nearest,
/// and among hits at exactly the same `t` (a ray through a shared edge or vertex, coincident
/// triangles) the lowest primitive number, so that the answer does not depend on the order
/// leaves are visited in. Implementations keep it by setting `ray.t_max` to the next float
/// above the best `t` (so hits at an equal `t` are still reported by tests that accept
/// `t < t_max`, and boxes entered at that `t` are not culled) and comparing `(t, primitive)`
/// when they take a hit. Across a scene's instances the order is `(t, instance, primitive)`
/// (`World::intersect`).
pub trait ClosestLeaf {
    fn test(&mut self, first: u32, count: u32, ray: &mut Ray) -> bool;

    /// Tests the leaves `children[i]` for the set bits `i` of `mask`, lowest first, with the
    /// answer and the shortened ray that `test` on each in turn gives. Implementations may
    /// test items of several leaves at once (two blocks of four triangles per AVX2 test).
    #[inline(always)]
    fn test_leaves<const W: usize>(&mut self, children: &[u32; W], mask: u32, ray: &mut Ray) -> bool {
        let mut found = false;
        let mut m = mask;
        while m != 0 {
            let (first, count) = leaf_range(children[m.trailing_zeros() as usize]);
            found |= self.test(first, count, ray);
            m &= m - 1;
        }
        found
    }
}

/// What any-hit traversal does at a leaf: true if anything blocks the ray.
pub trait AnyLeaf {
    fn test(&mut self, first: u32, count: u32, ray: &Ray) -> bool;
}

/// Closures work too (the scene's top level uses them; a call per instance is cheap there).
pub struct FnLeaf<F>(pub F);

impl<F: FnMut(u32, u32, &mut Ray) -> bool> ClosestLeaf for FnLeaf<F> {
    #[inline(always)]
    fn test(&mut self, first: u32, count: u32, ray: &mut Ray) -> bool {
        (self.0)(first, count, ray)
    }
}

impl<F: FnMut(u32, u32, &Ray) -> bool> AnyLeaf for FnLeaf<F> {
    #[inline(always)]
    fn test(&mut self, first: u32, count: u32, ray: &Ray) -> bool {
        (self.0)(first, count, ray)
    }
}

/// Traversal stack size in entries. A node pushes at most W children and pops one of them at
/// once, so at a node of depth d the stack holds at most (d - 1)(W - 1) entries before it
/// pushes, W after: d(W - 1) + 1. A wide tree is no deeper than the binary tree it was
/// collapsed from, which the build keeps within `MAX_DEPTH`; `collapse` checks this.
pub(super) const STACK: usize = MAX_DEPTH * 7 + 1;

impl<const W: usize> WideBvh<W> {
    /// Collapses `bvh`. `leaf(first, count)` turns a binary leaf (a range of
    /// `bvh.prim_indices`) into a leaf reference of the wide tree (it may repack the items).
    ///
    /// Panics if `bvh` is deeper than `MAX_DEPTH` (never for a tree from `Bvh::build`): the
    /// traversal stack is sized for that depth.
    pub fn collapse(bvh: &Bvh, mut leaf: impl FnMut(u32, u32) -> u32) -> WideBvh<W> {
        assert!(W == 4 || W == 8);
        let mut out = WideBvh { nodes: PageBuf::default(), root: EMPTY_CHILD, bounds: bvh.bounds(), depth: 0 };
        if bvh.nodes.is_empty() {
            return out;
        }
        let root = &bvh.nodes[0];
        if root.is_leaf() {
            out.root = leaf(root.first, root.count);
            return out;
        }
        out.root = 0;
        let mut nodes = vec![WideNode::EMPTY];
        // (wide node index, binary node index, depth); children are appended breadth-first
        // per node so that siblings' nodes sit together.
        let mut work = vec![(0usize, 0u32, 1usize)];
        while let Some((wi, bi, depth)) = work.pop() {
            // Checked as we go, so that a hand-made `Bvh` with a cycle fails instead of
            // looping.
            assert!(depth <= MAX_DEPTH, "BVH deeper than the traversal stack allows");
            out.depth = out.depth.max(depth);
            let mut kids: Vec<u32> = vec![bvh.nodes[bi as usize].first, bvh.nodes[bi as usize].first + 1];
            while kids.len() < W {
                // Open the interior child with the largest surface area.
                let best = kids
                    .iter()
                    .enumerate()
                    .filter(|(_, &k)| !bvh.nodes[k as usize].is_leaf())
                    .max_by(|a, b| area(&bvh.nodes[*a.1 as usize]).total_cmp(&area(&bvh.nodes[*b.1 as usize])));
                let Some((i, &k)) = best else { break };
                let first = bvh.nodes[k as usize].first;
                kids[i] = first;
                kids.push(first + 1);
            }
            let mut node = WideNode::<W>::EMPTY;
            for (slot, &k) in kids.iter().enumerate() {
                let bn = &bvh.nodes[k as usize];
                let child = if bn.is_leaf() {
                    leaf(bn.first, bn.count)
                } else {
                    let idx = nodes.len();
                    nodes.push(WideNode::EMPTY);
                    work.push((idx, k, depth + 1));
                    idx as u32
                };
                node.set_child(slot, &bn.bounds, child);
            }
            nodes[wi] = node;
        }
        // What the traversal's unchecked stack accesses rely on: d(W - 1) + 1 <= STACK.
        assert!(out.depth * (W - 1) < STACK, "BVH too deep for the wide traversal stack");
        out.nodes = PageBuf::new(nodes);
        out
    }

    pub fn nodes(&self) -> &[WideNode<W>] {
        &self.nodes
    }

    pub fn root(&self) -> u32 {
        self.root
    }

    pub fn stats(&self, leaf_items: impl Fn(u32) -> f64) -> WideStats {
        let mut s = WideStats {
            depth: self.depth,
            node_bytes: self.nodes.len() * std::mem::size_of::<WideNode<W>>(),
            ..Default::default()
        };
        if self.root == EMPTY_CHILD {
            return s;
        }
        let root_area = self.bounds.area().max(f32::MIN_POSITIVE) as f64;
        if self.root & LEAF_BIT != 0 {
            s.leaves = 1;
            s.sah_cost = SAH_INTERSECT_COST as f64 * leaf_items(self.root);
            return s;
        }
        s.sah_cost = SAH_TRAVERSAL_COST as f64; // the root, relative area 1
        let mut used = 0usize;
        for n in self.nodes.iter() {
            s.nodes += 1;
            for i in 0..W {
                let c = n.children[i];
                if c == EMPTY_CHILD {
                    continue;
                }
                used += 1;
                let rel = n.child_bounds(i).area() as f64 / root_area;
                if c & LEAF_BIT != 0 {
                    s.leaves += 1;
                    s.sah_cost += rel * SAH_INTERSECT_COST as f64 * leaf_items(c);
                } else {
                    s.sah_cost += rel * SAH_TRAVERSAL_COST as f64;
                }
            }
        }
        s.fill = used as f64 / s.nodes.max(1) as f64;
        s
    }

    /// Closest-hit traversal; `leaf` tests a leaf's items (see [`ClosestLeaf`]).
    ///
    /// # Safety
    /// `S` must be available on this CPU (see [`Isa`]).
    #[inline(always)]
    pub unsafe fn traverse<S: Isa>(&self, ray: &mut Ray, leaf: &mut impl ClosestLeaf) -> bool {
        if self.root == EMPTY_CHILD {
            return false;
        }
        // SAFETY: the root of a non-empty tree; `S` is the caller's.
        unsafe { self.traverse_from::<S>(self.root, ray, &NodeRay::new(ray), leaf) }
    }

    /// Closest-hit traversal of the subtree at `start` (the packet traversal's single-ray
    /// fall-back starts below the root).
    ///
    /// # Safety
    /// `S` must be available on this CPU; `start` must be the root of a non-empty tree or a
    /// node reference from a slot whose box the ray passes; `nr` must be `NodeRay::new(ray)`
    /// (of the ray's origin and direction, which traversal does not change).
    #[inline(always)]
    pub(super) unsafe fn traverse_from<S: Isa>(
        &self,
        start: u32,
        ray: &mut Ray,
        nr: &NodeRay,
        leaf: &mut impl ClosestLeaf,
    ) -> bool {
        let nr = *nr;
        let nodes: &[WideNode<W>] = &self.nodes;
        let mut stack: [MaybeUninit<(u32, f32)>; STACK] = [const { MaybeUninit::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = start;
        let mut found = false;
        loop {
            if cur & LEAF_BIT == 0 {
                // SAFETY: `cur` is the root or a child reference without the leaf bit, taken
                // from a slot whose box was hit; `collapse` writes every such reference as the
                // index of a node it pushed, and empty slots (whose reference is not an index)
                // are never hit (see `NodeRay::new`). So `cur < nodes.len()`.
                let node = unsafe { nodes.get_unchecked(cur as usize) };
                let mut dist = [0.0f32; W];
                let mut mask = S::node(node, &nr, ray.t_max, &mut dist);
                // Leaf children are tested at once, before any subtree: a leaf is one test,
                // and its hit shortens the ray, which culls the subtrees behind it (without
                // this, each leaf went through the sorted stack and a mispredicted pop).
                let leaf_bits = leaf_mask(node);
                let leaves = mask & leaf_bits;
                if leaves != 0 {
                    found |= leaf.test_leaves(&node.children, leaves, ray);
                    mask &= !leaf_bits;
                    let mut m = mask;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        if dist[i] > ray.t_max * FAR_SCALE {
                            mask &= !(1 << i);
                        }
                    }
                }
                if mask != 0 {
                    if mask & (mask - 1) == 0 {
                        cur = node.children[mask.trailing_zeros() as usize];
                        continue;
                    }
                    // Several children hit: push them in order, farthest deepest, and go on
                    // with the nearest.
                    // SAFETY: `sp + n <= STACK` for the n <= W children pushed, because the
                    // tree is at most `depth` deep and `collapse` checked `depth * (W - 1) + 1
                    // <= STACK` (see `STACK`). The cast keeps the layout (`MaybeUninit<T>` is
                    // laid out as `T`).
                    sp += unsafe { push_nearest_last(&node.children, &dist, mask, stack.as_mut_ptr().add(sp).cast()) };
                    sp -= 1;
                    // SAFETY: at least two entries were pushed, so `sp` is below them.
                    cur = unsafe { stack.get_unchecked(sp).assume_init() }.0;
                    continue;
                }
            } else if !nr.t_min.is_nan() {
                // Only the root is reached as a leaf here (hit leaf children are tested in
                // their parent); an untraceable ray skips it as it would skip its box.
                let (first, count) = leaf_range(cur);
                found |= leaf.test(first, count, ray);
            }
            // Pop, skipping entries that lie beyond the closest hit so far.
            loop {
                if sp == 0 {
                    return found;
                }
                sp -= 1;
                // SAFETY: entries `0..sp` were written and `sp <= STACK` (see `push`).
                let (c, d) = unsafe { stack.get_unchecked(sp).assume_init() };
                if d <= ray.t_max * FAR_SCALE {
                    cur = c;
                    break;
                }
            }
        }
    }

    /// Any-hit traversal: true as soon as `leaf` reports a hit.
    ///
    /// # Safety
    /// `S` must be available on this CPU (see [`Isa`]).
    #[inline(always)]
    pub unsafe fn occluded<S: Isa>(&self, ray: &Ray, leaf: &mut impl AnyLeaf) -> bool {
        if self.root == EMPTY_CHILD {
            return false;
        }
        // SAFETY: the root of a non-empty tree; `S` is the caller's.
        unsafe { self.occluded_from::<S>(self.root, ray, &NodeRay::new(ray), leaf) }
    }

    /// Any-hit traversal of the subtree at `start` (the packet traversal's single-ray
    /// fall-back starts below the root).
    ///
    /// # Safety
    /// `S` must be available on this CPU; `start` must be the root of a non-empty tree or a
    /// node reference from a slot whose box the ray passes; `nr` must be `NodeRay::new(ray)`.
    #[inline(always)]
    pub(super) unsafe fn occluded_from<S: Isa>(
        &self,
        start: u32,
        ray: &Ray,
        nr: &NodeRay,
        leaf: &mut impl AnyLeaf,
    ) -> bool {
        let nodes: &[WideNode<W>] = &self.nodes;
        let mut stack: [MaybeUninit<u32>; STACK] = [const { MaybeUninit::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = start;
        loop {
            if cur & LEAF_BIT == 0 {
                // SAFETY: as in `traverse`: only hit slots' references are followed, and
                // those are node indices written by `collapse`.
                let node = unsafe { nodes.get_unchecked(cur as usize) };
                let mut dist = [0.0f32; W];
                let mut mask = S::node(node, nr, ray.t_max, &mut dist);
                // Leaves first: one leaf test may end the query, where a subtree costs many
                // node tests before it can (large occluders such as walls sit in shallow
                // leaves).
                let leaf_bits = leaf_mask(node);
                let mut leaves = mask & leaf_bits;
                while leaves != 0 {
                    let (first, count) = leaf_range(node.children[leaves.trailing_zeros() as usize]);
                    if leaf.test(first, count, ray) {
                        return true;
                    }
                    leaves &= leaves - 1;
                }
                mask &= !leaf_bits;
                if mask != 0 {
                    // Go on with the first hit child and push the others (one compress on
                    // AVX-512).
                    cur = node.children[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    // SAFETY: a node at depth d starts with `sp <= (d - 1)(W - 1)` (each level
                    // of the current path leaves at most W - 1 entries), so the W slots
                    // `compress_refs` may write end at index `(d - 1)(W - 1) + W - 1 = d(W - 1)
                    // < STACK`, which `collapse` checked; `MaybeUninit<u32>` is laid out as `u32`.
                    sp += unsafe { S::compress_refs(&node.children, mask, stack.as_mut_ptr().add(sp).cast()) };
                    continue;
                }
            } else if !nr.t_min.is_nan() {
                // The root as a leaf (see `traverse`).
                let (first, count) = leaf_range(cur);
                if leaf.test(first, count, ray) {
                    return true;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entries `0..sp` were written, and `sp < STACK`.
            cur = unsafe { stack.get_unchecked(sp).assume_init() };
        }
    }
}

/// The children that are leaves (empty slots count as leaves, but no ray hits them): the
/// sign bits of the child references, gathered by `movmskps` (SSE2, always present on
/// x86-64) four at a time.
#[inline(always)]
pub(super) fn leaf_mask<const W: usize>(node: &WideNode<W>) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if W.is_multiple_of(4) {
        use std::arch::x86_64::{_mm_castsi128_ps, _mm_loadu_si128, _mm_movemask_ps};
        let mut m = 0;
        for q in 0..W / 4 {
            // SAFETY: reads four in-range `u32`s; SSE2 is part of the x86-64 baseline.
            let bits =
                unsafe { _mm_movemask_ps(_mm_castsi128_ps(_mm_loadu_si128(node.children.as_ptr().add(4 * q).cast()))) };
            m |= (bits as u32) << (4 * q);
        }
        return m;
    }
    let mut m = 0;
    for (i, c) in node.children.iter().enumerate() {
        m |= (c >> 31) << i;
    }
    m
}

fn area(n: &BvhNode) -> f32 {
    n.bounds.area()
}
