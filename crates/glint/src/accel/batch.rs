//! Many rays in flight: closest-hit and any-hit traversal of a batch of rays through a wide
//! BVH, several traversals interleaved on one thread.
//!
//! One ray's traversal is a chain of dependent steps (load a node, test it, choose the next,
//! load that), and the profile suggested a single ray mostly waits (BENCHMARKS.md, "What the
//! profile shows"). Here `LANES` traversals, each with its own stack, advance round-robin one node
//! visit per turn; after its turn a lane prefetches the node it visits next, and the other
//! lanes' turns run while that load is in flight. When a lane's ray is done the lane takes the
//! next ray of the batch.
//!
//! Each lane runs the algorithm of [`WideBvh::traverse`] and [`WideBvh::occluded`] step for
//! step, with the same float operations in the same order, so every ray's answer is
//! bit-identical to its single-ray query (the tests check this ray by ray). The single-ray
//! loops are kept as they are: their state lives in registers, which these turns cannot
//! keep across lanes. Measured (BENCHMARKS.md, "Many rays in flight"): 5 to 8% faster on
//! diffuse rays at best, 15 to 20% slower on primary rays; the renderer does not use it.

use super::simd::Isa;
use super::wide::{leaf_mask, leaf_range, AnyLeaf, ClosestLeaf, NodeRay, WideBvh, WideNode, EMPTY_CHILD, FAR_SCALE};
use super::wide::{push_nearest_last, LEAF_BIT, STACK};
use crate::math::Ray;
use std::marker::PhantomData;
use std::mem::MaybeUninit;

/// Traversals in flight per thread. 1, 4, 8 and 16 were measured (BENCHMARKS.md, "Many rays
/// in flight"): on diffuse rays 8 and 16 were about equal and ahead of 1 and 4; fewer lanes
/// keep the lanes' stacks' live entries in L1.
pub const LANES: usize = 8;

/// One ray's traversal in flight: the node it visits next and its stack.
struct Cursor<E> {
    cur: u32,
    sp: usize,
    stack: [MaybeUninit<E>; STACK],
}

impl<E> Cursor<E> {
    fn new() -> Cursor<E> {
        Cursor { cur: EMPTY_CHILD, sp: 0, stack: [const { MaybeUninit::uninit() }; STACK] }
    }
}

/// A lane: the ray (whose `t_max` closest-hit traversal shortens), its box-test constants,
/// its leaf state, the traversal, which ray of the batch it is (`None`: idle), and (for
/// any-hit traversal) whether the ray was found blocked.
struct Lane<L, E> {
    ray: Ray,
    nr: NodeRay,
    leaf: Option<L>,
    walk: Cursor<E>,
    index: Option<usize>,
    blocked: bool,
}

/// Asks the CPU to start loading node `i` (all of its cache lines) now.
#[inline(always)]
fn prefetch_node<const W: usize>(nodes: &[WideNode<W>], i: u32) {
    if let Some(node) = nodes.get(i as usize) {
        let p = (node as *const WideNode<W>).cast::<u8>();
        for offset in (0..std::mem::size_of::<WideNode<W>>()).step_by(64) {
            super::prefetch_address(p.wrapping_add(offset));
        }
    }
}

/// One node visit of a traversal kind. A trait with `#[inline(always)]` implementations, not
/// a closure: a closure is compiled as its own function without the caller's target
/// features, and the SIMD kernels inside it became calls per intrinsic (8x slower).
trait Step<L, E, const W: usize> {
    /// Visits `lane.walk.cur` and says whether the traversal goes on.
    ///
    /// # Safety
    /// The instruction set must be available; `lane` must have been started on the tree of
    /// `nodes` and every earlier step must have returned true.
    unsafe fn step(nodes: &[WideNode<W>], lane: &mut Lane<L, E>) -> bool;
}

struct ClosestStep<S>(PhantomData<S>);
struct AnyStep<S>(PhantomData<S>);

impl<S: Isa, L: ClosestLeaf, const W: usize> Step<L, (u32, f32), W> for ClosestStep<S> {
    #[inline(always)]
    unsafe fn step(nodes: &[WideNode<W>], lane: &mut Lane<L, (u32, f32)>) -> bool {
        // SAFETY: the contract of `Step::step` is `closest_step`'s.
        unsafe { closest_step::<S, L, W>(nodes, lane) }
    }
}

impl<S: Isa, L: AnyLeaf, const W: usize> Step<L, u32, W> for AnyStep<S> {
    #[inline(always)]
    unsafe fn step(nodes: &[WideNode<W>], lane: &mut Lane<L, u32>) -> bool {
        // SAFETY: as above, `any_step`'s contract.
        unsafe { any_step::<S, L, W>(nodes, lane) }
    }
}

/// Runs `N` traversals of kind `K` round-robin over `rays`. `start(ray)` makes a ray's
/// leaf state; `finish(index, lane)` takes a finished ray's answer.
///
/// # Safety
/// `K`'s instruction set must be available on this CPU.
#[inline(always)]
unsafe fn round_robin<K: Step<L, E, W>, L, E, const W: usize, const N: usize>(
    tree: &WideBvh<W>,
    rays: &[Ray],
    start: impl Fn(&Ray) -> L,
    mut finish: impl FnMut(usize, &mut Lane<L, E>),
) {
    let nodes = tree.nodes();
    let root = tree.root();
    let mut lanes: [Lane<L, E>; N] = std::array::from_fn(|_| Lane {
        ray: Ray::new(Default::default(), Default::default()),
        nr: NodeRay::new(&Ray::new(Default::default(), Default::default())),
        leaf: None,
        walk: Cursor::new(),
        index: None,
        blocked: false,
    });
    let mut next = 0usize;
    // Starts the next ray of the batch in `lane`, or leaves it idle; false if idle.
    let refill = |lane: &mut Lane<L, E>, next: &mut usize| -> bool {
        if *next >= rays.len() {
            lane.index = None;
            return false;
        }
        lane.ray = rays[*next];
        lane.nr = NodeRay::new(&lane.ray);
        lane.leaf = Some(start(&lane.ray));
        lane.walk.cur = root;
        lane.walk.sp = 0;
        lane.index = Some(*next);
        lane.blocked = false;
        *next += 1;
        prefetch_node(nodes, root);
        true
    };
    if root == EMPTY_CHILD {
        // An empty tree: every ray misses, with the leaf state it started with.
        let lane = &mut lanes[0];
        while refill(lane, &mut next) {
            finish(next - 1, lane);
        }
        return;
    }
    let mut active = 0;
    for lane in lanes.iter_mut() {
        active += refill(lane, &mut next) as usize;
    }
    while active > 0 {
        for lane in lanes.iter_mut() {
            let Some(index) = lane.index else { continue };
            // SAFETY: the lane was started by `refill` on this tree and has not finished; the
            // instruction set is available (this function's contract).
            if !unsafe { K::step(nodes, lane) } {
                finish(index, lane);
                if !refill(lane, &mut next) {
                    active -= 1;
                }
            }
        }
    }
}

impl<const W: usize> WideBvh<W> {
    /// Closest hits of `rays`, `LANES` at a time: `start(ray)` makes a ray's leaf state
    /// (which records its closest hit), `finish(index, ray, leaf)` takes the ray (its `t_max`
    /// shortened to the hit) and that state. Same answers as [`WideBvh::traverse`].
    ///
    /// # Safety
    /// `S` must be available on this CPU (see [`Isa`]).
    #[inline(always)]
    pub unsafe fn traverse_batch<S: Isa, L: ClosestLeaf>(
        &self,
        rays: &[Ray],
        start: impl Fn(&Ray) -> L,
        mut finish: impl FnMut(usize, &Ray, L),
    ) {
        // SAFETY: `S` is available (this function's contract).
        let f = |i, lane: &mut Lane<L, (u32, f32)>| {
            finish(i, &lane.ray, lane.leaf.take().expect("a started lane has its leaf state"))
        };
        unsafe { round_robin::<ClosestStep<S>, L, (u32, f32), W, LANES>(self, rays, start, f) };
    }

    /// Whether each ray of `rays` is blocked, `LANES` at a time; `start(ray)` makes a ray's
    /// leaf state. Same answers as [`WideBvh::occluded`].
    ///
    /// # Safety
    /// `S` must be available on this CPU (see [`Isa`]).
    #[inline(always)]
    pub unsafe fn occluded_batch<S: Isa, L: AnyLeaf>(
        &self,
        rays: &[Ray],
        start: impl Fn(&Ray) -> L,
        mut finish: impl FnMut(usize, bool),
    ) {
        // SAFETY: `S` is available (this function's contract).
        let f = |i, lane: &mut Lane<L, u32>| finish(i, lane.blocked);
        unsafe { round_robin::<AnyStep<S>, L, u32, W, LANES>(self, rays, start, f) };
    }
}

/// One node visit of closest-hit traversal: `WideBvh::traverse`'s loop body, with `continue`
/// turned into "return true" and the stack held in the lane.
///
/// # Safety
/// `S` must be available on this CPU; `lane.walk.cur` must be the tree's root or a reference
/// that a previous step set, and `nodes` the tree's nodes.
#[inline(always)]
unsafe fn closest_step<S: Isa, L: ClosestLeaf, const W: usize>(
    nodes: &[WideNode<W>],
    lane: &mut Lane<L, (u32, f32)>,
) -> bool {
    let Lane { ray, nr, leaf, walk, .. } = lane;
    // SAFETY of `unwrap_unchecked`: `round_robin` steps only started lanes, which have state.
    let leaf = unsafe { leaf.as_mut().unwrap_unchecked() };
    let stack = &mut walk.stack;
    let mut sp = walk.sp;
    let cur = walk.cur;
    if cur & LEAF_BIT == 0 {
        // SAFETY: as in `WideBvh::traverse`: `cur` is the root or the reference of a hit
        // slot, which `collapse` wrote as the index of a node; empty slots are never hit.
        let node = unsafe { nodes.get_unchecked(cur as usize) };
        let mut dist = [0.0f32; W];
        // SAFETY: `S` is available; `nr` comes from `NodeRay::new`.
        let mut mask = unsafe { S::node(node, nr, ray.t_max, &mut dist) };
        let leaf_bits = leaf_mask(node);
        let mut leaves = mask & leaf_bits;
        if leaves != 0 {
            while leaves != 0 {
                let (first, count) = leaf_range(node.children[leaves.trailing_zeros() as usize]);
                leaf.test(first, count, ray);
                leaves &= leaves - 1;
            }
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
                walk.cur = node.children[mask.trailing_zeros() as usize];
                walk.sp = sp;
                prefetch_node(nodes, walk.cur);
                return true;
            }
            // SAFETY: as in `WideBvh::traverse`: `sp + n <= STACK`
            // because `collapse` checked `depth * (W - 1) + 1 <= STACK`.
            sp += unsafe { push_nearest_last(&node.children, &dist, mask, stack.as_mut_ptr().add(sp).cast()) };
            sp -= 1;
            // SAFETY: at least two entries were pushed, so `sp` is below them.
            walk.cur = unsafe { stack.get_unchecked(sp).assume_init() }.0;
            walk.sp = sp;
            prefetch_node(nodes, walk.cur);
            return true;
        }
    } else if !nr.t_min.is_nan() {
        // The root as a leaf (see `WideBvh::traverse`).
        let (first, count) = leaf_range(cur);
        leaf.test(first, count, ray);
    }
    // Pop, skipping entries that lie beyond the closest hit so far.
    loop {
        if sp == 0 {
            walk.sp = 0;
            return false;
        }
        sp -= 1;
        // SAFETY: entries `0..sp` were written and `sp <= STACK` (see `push`).
        let (c, d) = unsafe { stack.get_unchecked(sp).assume_init() };
        if d <= ray.t_max * FAR_SCALE {
            walk.cur = c;
            walk.sp = sp;
            prefetch_node(nodes, c);
            return true;
        }
    }
}

/// One node visit of any-hit traversal: `WideBvh::occluded`'s loop body. False when the
/// traversal is over, with `lane.blocked` set if a leaf blocked the ray.
///
/// # Safety
/// As for [`closest_step`].
#[inline(always)]
unsafe fn any_step<S: Isa, L: AnyLeaf, const W: usize>(nodes: &[WideNode<W>], lane: &mut Lane<L, u32>) -> bool {
    let Lane { ray, nr, leaf, walk, blocked, .. } = lane;
    // SAFETY of `unwrap_unchecked`: `round_robin` steps only started lanes.
    let leaf = unsafe { leaf.as_mut().unwrap_unchecked() };
    let cur = walk.cur;
    if cur & LEAF_BIT == 0 {
        // SAFETY: as in `closest_step`.
        let node = unsafe { nodes.get_unchecked(cur as usize) };
        let mut dist = [0.0f32; W];
        // SAFETY: `S` is available; `nr` comes from `NodeRay::new`.
        let mut mask = unsafe { S::node(node, nr, ray.t_max, &mut dist) };
        let leaf_bits = leaf_mask(node);
        let mut leaves = mask & leaf_bits;
        while leaves != 0 {
            let (first, count) = leaf_range(node.children[leaves.trailing_zeros() as usize]);
            if leaf.test(first, count, ray) {
                *blocked = true;
                return false;
            }
            leaves &= leaves - 1;
        }
        mask &= !leaf_bits;
        if mask != 0 {
            walk.cur = node.children[mask.trailing_zeros() as usize];
            mask &= mask - 1;
            while mask != 0 {
                // SAFETY: as in `WideBvh::occluded`: at most W - 1 entries per level of the
                // current path, so `sp < depth * (W - 1) + 1 <= STACK`.
                unsafe { walk.stack.get_unchecked_mut(walk.sp) }.write(node.children[mask.trailing_zeros() as usize]);
                walk.sp += 1;
                mask &= mask - 1;
            }
            prefetch_node(nodes, walk.cur);
            return true;
        }
    } else if !nr.t_min.is_nan() {
        let (first, count) = leaf_range(cur);
        if leaf.test(first, count, ray) {
            *blocked = true;
            return false;
        }
    }
    if walk.sp == 0 {
        return false;
    }
    walk.sp -= 1;
    // SAFETY: entries `0..sp` were written, and `sp < STACK`.
    walk.cur = unsafe { walk.stack.get_unchecked(walk.sp).assume_init() };
    prefetch_node(nodes, walk.cur);
    true
}
