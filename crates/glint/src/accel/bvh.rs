//! A binary bounding volume hierarchy that knows only boxes and centres.
//!
//! The same structure serves both levels of glint's acceleration: triangles inside a mesh
//! (bottom level) and transformed instances in the scene (top level). Traversal takes a
//! closure that intersects one primitive, so the BVH never needs to know what it holds.
//! This binary BVH is also the reference implementation against which faster traversal
//! kernels are checked.

use crate::math::{Aabb, Ray, Vec3};

pub use super::build::{MAX_DEPTH, SAH_DEPTH_LIMIT};

/// How the builder chooses splits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum BvhSplit {
    /// Binned surface area heuristic (Wald 2007): the default.
    #[default]
    Sah,
    /// The paper's strategy: split the longest axis at the median primitive.
    Median,
}

impl std::str::FromStr for BvhSplit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "sah" => Ok(BvhSplit::Sah),
            "median" => Ok(BvhSplit::Median),
            _ => Err(format!("unknown BVH split '{s}' (expected 'sah' or 'median')")),
        }
    }
}

/// One node: 32 bytes, two per cache line. An interior node's children sit at
/// `first` and `first + 1`; a leaf holds `count > 0` primitives from `prim_indices[first..]`.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct BvhNode {
    pub bounds: Aabb,
    pub first: u32,
    pub count: u32,
}

impl BvhNode {
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// Primitive indices in leaf order.
    pub prim_indices: Vec<u32>,
}

/// Costs of the SAH model (traversal step vs. primitive test), as in pbrt and Embree's
/// defaults; the absolute scale is arbitrary, the ratio matters.
pub const SAH_TRAVERSAL_COST: f32 = 1.0;
pub const SAH_INTERSECT_COST: f32 = 1.0;

/// What one counted traversal visited.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalVisits {
    /// Nodes whose box the ray entered.
    pub nodes: u64,
    /// Primitives tested in the leaves of those nodes.
    pub primitives: u64,
}

/// Statistics that `glint info` reports.
#[derive(Clone, Debug, Default)]
pub struct BvhStats {
    pub nodes: usize,
    pub leaves: usize,
    pub max_depth: usize,
    pub min_leaf: usize,
    pub max_leaf: usize,
    pub mean_leaf: f64,
    pub sah_cost: f64,
    pub bytes: usize,
}

/// Leaf-size policy of a build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuildOptions {
    /// Largest leaf the SAH may choose to make.
    pub max_leaf: usize,
    /// Nodes of this many primitives or fewer always become leaves.
    pub leaf_at_most: usize,
}

impl BuildOptions {
    /// The reference binary BVH: leaves of up to 8 where the SAH says a leaf is cheaper.
    pub const BINARY: BuildOptions = BuildOptions { max_leaf: 8, leaf_at_most: 1 };
    /// The tree the wide BVH is collapsed from: leaves of at most 4 triangles (one SIMD
    /// block), and every node of 4 or fewer is a leaf, since testing a block of four costs
    /// about what testing one triangle does.
    pub const WIDE: BuildOptions = BuildOptions { max_leaf: 4, leaf_at_most: 4 };
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions::BINARY
    }
}

impl Bvh {
    /// Builds over `bounds[i]` for each primitive `i`. Empty boxes are allowed (degenerate
    /// triangles) and end up in leaves that no ray can hit; so do boxes with NaN or infinite
    /// corners, which are treated as empty. The tree has at most [`MAX_DEPTH`] levels.
    pub fn build(bounds: &[Aabb], split: BvhSplit) -> Bvh {
        Bvh::build_with(bounds, split, BuildOptions::BINARY)
    }

    /// Builds with a given leaf-size policy.
    pub fn build_with(bounds: &[Aabb], split: BvhSplit, opts: BuildOptions) -> Bvh {
        if bounds.is_empty() {
            return Bvh::default();
        }
        let (nodes, prim_indices) = super::build::build(bounds, split, opts);
        Bvh { nodes, prim_indices }
    }

    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map(|n| n.bounds).unwrap_or(Aabb::EMPTY)
    }

    /// Closest-hit traversal. `hit_prim(prim, ray)` tests one primitive and, on a hit,
    /// shortens `ray.t_max` and returns true. Children are visited nearest first.
    #[inline]
    pub fn traverse<F: FnMut(u32, &mut Ray) -> bool>(&self, ray: &mut Ray, mut hit_prim: F) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv_dir = Vec3::ONE / ray.dir;
        // One far child per level at most: the build bounds the depth by MAX_DEPTH.
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node_idx = 0u32;
        let mut found = false;
        if self.nodes[0].bounds.intersect(ray, inv_dir).is_none() {
            return false;
        }
        loop {
            let node = &self.nodes[node_idx as usize];
            if node.is_leaf() {
                for i in node.first..node.first + node.count {
                    found |= hit_prim(self.prim_indices[i as usize], ray);
                }
            } else {
                let (a, b) = (node.first, node.first + 1);
                let ta = self.nodes[a as usize].bounds.intersect(ray, inv_dir);
                let tb = self.nodes[b as usize].bounds.intersect(ray, inv_dir);
                match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        let (near, far) = if ta <= tb { (a, b) } else { (b, a) };
                        stack[sp] = far;
                        sp += 1;
                        node_idx = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node_idx = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        node_idx = b;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop, skipping nodes the shortened ray no longer reaches.
            loop {
                if sp == 0 {
                    return found;
                }
                sp -= 1;
                let n = stack[sp];
                if self.nodes[n as usize].bounds.intersect(ray, inv_dir).is_some() {
                    node_idx = n;
                    break;
                }
            }
        }
    }

    /// Closest-hit traversal like [`Bvh::traverse`], counting the nodes entered and the
    /// primitives tested into `visits`. Only for statistics (the BVH-cost AOV): the fast
    /// kernels stay free of counters.
    pub fn traverse_counting<F: FnMut(u32, &mut Ray) -> bool>(
        &self,
        ray: &mut Ray,
        visits: &mut TraversalVisits,
        mut hit_prim: F,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv_dir = Vec3::ONE / ray.dir;
        let mut stack = vec![0u32];
        let mut found = false;
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            if node.bounds.intersect(ray, inv_dir).is_none() {
                continue;
            }
            visits.nodes += 1;
            if node.is_leaf() {
                for k in node.first..node.first + node.count {
                    visits.primitives += 1;
                    found |= hit_prim(self.prim_indices[k as usize], ray);
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let ta = self.nodes[a as usize].bounds.intersect(ray, inv_dir).unwrap_or(f32::INFINITY);
            let tb = self.nodes[b as usize].bounds.intersect(ray, inv_dir).unwrap_or(f32::INFINITY);
            // Far child first on the stack, so the near one is visited first.
            if ta <= tb {
                stack.extend([b, a]);
            } else {
                stack.extend([a, b]);
            }
        }
        found
    }

    /// Any-hit traversal for shadow rays: stops at the first primitive `hit_prim` accepts.
    #[inline]
    pub fn occluded<F: FnMut(u32, &Ray) -> bool>(&self, ray: &Ray, mut hit_prim: F) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv_dir = Vec3::ONE / ray.dir;
        // One pending sibling per level, plus the two children just pushed.
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut sp = 0usize;
        stack[sp] = 0;
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if node.bounds.intersect(ray, inv_dir).is_none() {
                continue;
            }
            if node.is_leaf() {
                for i in node.first..node.first + node.count {
                    if hit_prim(self.prim_indices[i as usize], ray) {
                        return true;
                    }
                }
            } else {
                stack[sp] = node.first + 1;
                stack[sp + 1] = node.first;
                sp += 2;
            }
        }
        false
    }

    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats { min_leaf: usize::MAX, ..Default::default() };
        if self.nodes.is_empty() {
            s.min_leaf = 0;
            return s;
        }
        let root_area = self.nodes[0].bounds.area().max(f32::MIN_POSITIVE) as f64;
        let mut stack = vec![(0u32, 1usize)];
        let mut leaf_prims = 0usize;
        while let Some((i, depth)) = stack.pop() {
            let n = &self.nodes[i as usize];
            s.nodes += 1;
            s.max_depth = s.max_depth.max(depth);
            let rel = n.bounds.area() as f64 / root_area;
            if n.is_leaf() {
                s.leaves += 1;
                leaf_prims += n.count as usize;
                s.min_leaf = s.min_leaf.min(n.count as usize);
                s.max_leaf = s.max_leaf.max(n.count as usize);
                s.sah_cost += rel * SAH_INTERSECT_COST as f64 * n.count as f64;
            } else {
                s.sah_cost += rel * SAH_TRAVERSAL_COST as f64;
                stack.push((n.first, depth + 1));
                stack.push((n.first + 1, depth + 1));
            }
        }
        s.mean_leaf = leaf_prims as f64 / s.leaves.max(1) as f64;
        s.bytes = self.nodes.len() * std::mem::size_of::<BvhNode>() + self.prim_indices.len() * 4;
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    fn boxes(n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let p = vec3((i % 17) as f32, ((i * 7) % 13) as f32, ((i * 3) % 11) as f32);
                Aabb { min: p, max: p + Vec3::splat(0.5) }
            })
            .collect()
    }

    #[test]
    fn every_primitive_appears_once_and_children_are_inside_parents() {
        for split in [BvhSplit::Sah, BvhSplit::Median] {
            let b = boxes(10_000);
            let bvh = Bvh::build(&b, split);
            let mut seen = bvh.prim_indices.clone();
            seen.sort();
            assert_eq!(seen, (0..10_000u32).collect::<Vec<_>>());
            for n in &bvh.nodes {
                if n.is_leaf() {
                    for &p in &bvh.prim_indices[n.first as usize..(n.first + n.count) as usize] {
                        assert_eq!(n.bounds.union(b[p as usize]), n.bounds);
                    }
                } else {
                    for c in [n.first, n.first + 1] {
                        let cb = bvh.nodes[c as usize].bounds;
                        assert_eq!(n.bounds.union(cb), n.bounds);
                    }
                }
            }
        }
    }

    #[test]
    fn sah_beats_median_on_clustered_input() {
        // Two dense clusters far apart plus a sparse line: median splits badly here.
        let mut b = Vec::new();
        for i in 0..2000 {
            let x = if i % 2 == 0 { 0.0 } else { 1000.0 } + (i as f32 * 0.001);
            b.push(Aabb { min: vec3(x, 0.0, 0.0), max: vec3(x + 0.01, 0.01, 0.01) });
        }
        for i in 0..200 {
            let x = i as f32 * 5.0;
            b.push(Aabb { min: vec3(x, 50.0, 0.0), max: vec3(x + 0.01, 50.01, 0.01) });
        }
        let sah = Bvh::build(&b, BvhSplit::Sah).stats().sah_cost;
        let median = Bvh::build(&b, BvhSplit::Median).stats().sah_cost;
        assert!(sah < median, "sah {sah} median {median}");
    }
}
