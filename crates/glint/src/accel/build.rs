//! The binary BVH build: top-down, binned SAH (or the paper's median split), leaves by the
//! policy of [`BuildOptions`].
//!
//! Large subtrees are built as two halves in parallel (rayon), each returning its part of the
//! tree; small ones are built sequentially in place. The parts are written into the final
//! arrays once, at the end, so that no node is copied more than once however deep the tree.
//! Layout: a node's two children are adjacent, and a subtree is [root, left child, right
//! child, rest of the left subtree, rest of the right subtree].

use super::binning::{best_split, grow, union, BinMap, Binned, Split};
use super::bvh::{BuildOptions, BvhNode, BvhSplit, SAH_INTERSECT_COST};
use crate::math::{Aabb, Vec3};

/// Subtrees above this size are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;

/// Depth (the root is 0) from which nodes are split at the object median instead of by the
/// SAH. The SAH can peel one reference off per level (exponentially spaced boxes, NaN
/// garbage), so without this a tree could be as deep as it has references; the median
/// halves the references per level, so at most 32 more levels follow for `u32` indices.
/// Real scenes stay far shallower (the bunny's SAH tree is about 30 deep), so this changes
/// no tree that the SAH builds sensibly.
pub const SAH_DEPTH_LIMIT: usize = 48;

/// Most levels (nodes on a root-to-leaf path) a built tree has: the SAH levels, then at most
/// 32 median splits of at most 2^32 references, then the leaf. Traversal stacks are sized
/// from this.
pub const MAX_DEPTH: usize = SAH_DEPTH_LIMIT + 33;

const PLACEHOLDER: BvhNode = BvhNode { bounds: Aabb::EMPTY, first: 0, count: 0 };

struct BuildRef {
    bounds: Aabb,
    centre: Vec3,
    index: u32,
}

impl Binned for BuildRef {
    #[inline(always)]
    fn bounds(&self) -> &Aabb {
        &self.bounds
    }
    #[inline(always)]
    fn centre(&self) -> Vec3 {
        self.centre
    }
}

/// A subtree built sequentially, with node links relative to its own first node and leaf
/// ranges relative to its own first primitive.
struct Subtree {
    nodes: Vec<BvhNode>,
    prims: u32,
}

/// Part of the tree as the parallel build returns it.
enum Part {
    Built(Subtree),
    Split { bounds: Aabb, left: Box<Part>, right: Box<Part>, nodes: usize, prims: u32 },
}

impl Part {
    fn node_count(&self) -> usize {
        match self {
            Part::Built(t) => t.nodes.len(),
            Part::Split { nodes, .. } => *nodes,
        }
    }

    fn prim_count(&self) -> u32 {
        match self {
            Part::Built(t) => t.prims,
            Part::Split { prims, .. } => *prims,
        }
    }
}

/// Builds over `bounds[i]` for each primitive `i`: (nodes, primitive indices in leaf order).
pub fn build(bounds: &[Aabb], split: BvhSplit, opts: BuildOptions) -> (Vec<BvhNode>, Vec<u32>) {
    assert!(bounds.len() <= u32::MAX as usize, "more primitives than u32 indices can name");
    let mut refs: Vec<BuildRef> = bounds
        .iter()
        .enumerate()
        .map(|(i, b)| {
            // A box with NaN or infinite corners (garbage geometry, a sphere at 1e39 that is
            // infinite as f32) is treated as empty: it is never hit, and it cannot spread
            // NaN or infinity into its ancestors' boxes, the bins or the SAH costs.
            let usable = !b.is_empty() && b.min.is_finite() && b.max.is_finite();
            let bounds = if usable { *b } else { Aabb::EMPTY };
            BuildRef { bounds, centre: if usable { b.center() } else { Vec3::ZERO }, index: i as u32 }
        })
        .collect();
    let part = build_part(&mut refs, split, opts, 0);
    let mut nodes = vec![PLACEHOLDER; part.node_count()];
    // Leaf order is reference order after the build's partitioning.
    let prims = refs.iter().map(|r| r.index).collect();
    write(part, &mut nodes, 0, 1, 0);
    (nodes, prims)
}

/// Writes `part` with its root at `nodes[root]`, the rest of its nodes from `nodes[rest]`,
/// and its primitives from `prims_at` in leaf order.
fn write(part: Part, nodes: &mut [BvhNode], root: usize, rest: usize, prims_at: u32) {
    match part {
        Part::Built(t) => {
            let relink = |n: BvhNode| -> BvhNode {
                if n.is_leaf() {
                    BvhNode { first: n.first + prims_at, ..n }
                } else {
                    // Subtree node j >= 1 goes to rest + j - 1; node 0 is never a child.
                    BvhNode { first: (rest + n.first as usize - 1) as u32, ..n }
                }
            };
            nodes[root] = relink(t.nodes[0]);
            for (slot, &n) in nodes[rest..rest + t.nodes.len() - 1].iter_mut().zip(&t.nodes[1..]) {
                *slot = relink(n);
            }
        }
        Part::Split { bounds, left, right, .. } => {
            nodes[root] = BvhNode { bounds, first: rest as u32, count: 0 };
            let left_prims = left.prim_count();
            let left_rest = rest + 2;
            let right_rest = left_rest + left.node_count() - 1;
            write(*left, nodes, rest, left_rest, prims_at);
            write(*right, nodes, rest + 1, right_rest, prims_at + left_prims);
        }
    }
}

fn build_part(refs: &mut [BuildRef], split: BvhSplit, opts: BuildOptions, depth: usize) -> Part {
    let n = refs.len();
    if n <= PARALLEL_THRESHOLD {
        let mut tree = Subtree { nodes: Vec::with_capacity(2 * n), prims: 0 };
        tree.nodes.push(PLACEHOLDER);
        build_in_place(refs, split, opts, 0, &mut tree, depth);
        return Part::Built(tree);
    }
    let bounds = refs.iter().fold(Aabb::EMPTY, |b, r| union(b, &r.bounds));
    let Some(mid) = split_refs(refs, &bounds, split, opts, depth) else {
        return Part::Built(Subtree { nodes: vec![BvhNode { bounds, first: 0, count: n as u32 }], prims: n as u32 });
    };
    let (left, right) = refs.split_at_mut(mid);
    let (l, r) = rayon::join(|| build_part(left, split, opts, depth + 1), || build_part(right, split, opts, depth + 1));
    let (nodes, prims) = (1 + l.node_count() + r.node_count(), l.prim_count() + r.prim_count());
    Part::Split { bounds, left: Box::new(l), right: Box::new(r), nodes, prims }
}

/// Builds the node at `tree.nodes[at]` and its subtree sequentially, appending each node's
/// pair of children as it goes.
fn build_in_place(
    refs: &mut [BuildRef],
    split: BvhSplit,
    opts: BuildOptions,
    at: usize,
    tree: &mut Subtree,
    depth: usize,
) {
    let bounds = refs.iter().fold(Aabb::EMPTY, |b, r| union(b, &r.bounds));
    match split_refs(refs, &bounds, split, opts, depth) {
        None => {
            tree.nodes[at] = BvhNode { bounds, first: tree.prims, count: refs.len() as u32 };
            tree.prims += refs.len() as u32;
        }
        Some(mid) => {
            let first = tree.nodes.len();
            tree.nodes[at] = BvhNode { bounds, first: first as u32, count: 0 };
            tree.nodes.extend([PLACEHOLDER, PLACEHOLDER]);
            let (left, right) = refs.split_at_mut(mid);
            build_in_place(left, split, opts, first, tree, depth + 1);
            build_in_place(right, split, opts, first + 1, tree, depth + 1);
        }
    }
}

/// How a node's references divide: `None` makes them a leaf, `Some(mid)` splits them at
/// `mid`, after reordering them so that the left side comes first. From
/// [`SAH_DEPTH_LIMIT`] on, every split is at the median, so the tree depth stays within
/// [`MAX_DEPTH`] for any input.
fn split_refs(
    refs: &mut [BuildRef],
    bounds: &Aabb,
    split: BvhSplit,
    opts: BuildOptions,
    depth: usize,
) -> Option<usize> {
    let n = refs.len();
    if n <= opts.leaf_at_most.max(1) {
        return None;
    }
    let split = if depth >= SAH_DEPTH_LIMIT { BvhSplit::Median } else { split };
    let centre_bounds = refs.iter().fold(Aabb::EMPTY, |b, r| grow(b, r.centre));
    let axis = centre_bounds.extent().max_axis();
    let extent = centre_bounds.extent()[axis];
    Some(match split {
        BvhSplit::Median => {
            let m = n / 2;
            refs.select_nth_unstable_by(m, |a, b| a.centre[axis].total_cmp(&b.centre[axis]));
            m
        }
        BvhSplit::Sah if extent <= 0.0 => {
            // All centres coincide: no split separates them.
            if n <= opts.max_leaf {
                return None;
            }
            n / 2
        }
        BvhSplit::Sah => {
            let map = BinMap::new(&centre_bounds);
            match best_split(refs, &map, bounds.area(), n > PARALLEL_THRESHOLD) {
                Some(Split { axis, bin, cost }) => {
                    let leaf_cost = SAH_INTERSECT_COST * n as f32;
                    if cost >= leaf_cost && n <= opts.max_leaf {
                        return None;
                    }
                    let m = partition(refs, |r| map.bin(r.centre[axis], axis) < bin);
                    if m == 0 || m == n {
                        n / 2
                    } else {
                        m
                    }
                }
                None => n / 2,
            }
        }
    })
}

fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(&v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}
