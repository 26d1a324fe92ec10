//! A light BVH for choosing the light to sample from a shading point (after Conty Estevez
//! and Kulla, "Importance Sampling of Many Lights with Adaptive Tree Splitting", 2018, and
//! pbrt-v4's light bounds; written from the papers' descriptions).
//!
//! Every bounded light is a leaf with its bounds: a box, the power it emits, and a cone of
//! the directions its surface normals take (`axis`, `cos_theta_o`) widened by the angle
//! past the normal that it still emits into (`cos_theta_e`). Inner nodes hold the union of
//! their children's. From a point, a node's *importance* bounds what it can send there:
//! power over squared distance, times the cosine of the smallest angle between the cone and
//! the direction to the point, zero where the cone proves the node sends nothing there.
//! Sampling walks from the root, choosing a child in proportion to importance; the
//! probability of a light is the product of the choices on its path, which
//! [`LightTree::pmf`] recomputes for a light that a BSDF-sampled ray hit (multiple
//! importance sampling needs both sides to agree). Infinite lights are kept beside the tree:
//! each is chosen as often as all bounded lights together, as under power selection.
//!
//! The build is deterministic (binned splits in a fixed order, ties to the lower index), so
//! checkpoints and distributed workers see the same tree.

use super::Light;
use crate::materials::Texture;
use crate::math::{Aabb, Vec3, PI};

/// A cone of directions: `axis` and the cosine of its half-angle (-1: every direction).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cone {
    axis: Vec3,
    cos_theta: f32,
}

impl Cone {
    const ALL: Cone = Cone { axis: Vec3 { x: 0.0, y: 0.0, z: 1.0 }, cos_theta: -1.0 };

    /// The smallest cone holding both.
    fn union(a: Cone, b: Cone) -> Cone {
        if a.cos_theta <= -1.0 || b.cos_theta <= -1.0 {
            return Cone::ALL;
        }
        // Most unions in a build are of a cone with one it already holds (the triangles of
        // a flat panel): tell those by cosines alone, leaving the borderline (by a margin
        // far above rounding) to the exact path below, which returns the same cone there.
        let cos_d = a.axis.dot(b.axis).clamp(-1.0, 1.0);
        let sin_d = (1.0 - cos_d * cos_d).max(0.0).sqrt();
        let holds = |outer: Cone, inner: Cone| {
            let sin_i = (1.0 - inner.cos_theta * inner.cos_theta).max(0.0).sqrt();
            // cos and sin of θd + θinner: within π and inside the outer cone's angle.
            let cos_sum = cos_d * inner.cos_theta - sin_d * sin_i;
            let sin_sum = sin_d * inner.cos_theta + cos_d * sin_i;
            sin_sum >= 0.0 && cos_sum >= outer.cos_theta + 1e-5
        };
        if holds(a, b) {
            return a;
        }
        if holds(b, a) {
            return b;
        }
        let (ta, tb) = (a.cos_theta.clamp(-1.0, 1.0).acos(), b.cos_theta.clamp(-1.0, 1.0).acos());
        let td = a.axis.dot(b.axis).clamp(-1.0, 1.0).acos();
        if (td + tb).min(PI) <= ta {
            return a;
        }
        if (td + ta).min(PI) <= tb {
            return b;
        }
        let to = 0.5 * (ta + td + tb);
        if to >= PI {
            return Cone::ALL;
        }
        // Turn a's axis towards b's by to - ta.
        let k = a.axis.cross(b.axis);
        if !(k.length_squared() > 0.0) {
            return Cone::ALL;
        }
        let k = k.normalize();
        let (s, c) = (to - ta).sin_cos();
        let axis = (a.axis * c + k.cross(a.axis) * s + k * (k.dot(a.axis) * (1.0 - c))).normalize();
        // A little wider than exact, so that rounding never excludes a direction.
        Cone { axis, cos_theta: (to + 1e-4).min(PI).cos() }
    }
}

/// What bounds a light or a group of lights (see the module doc).
#[derive(Clone, Copy, Debug)]
struct Bounds {
    aabb: Aabb,
    power: f32,
    normals: Cone,
    /// cos of the angle past the normals' cone that light still leaves at (π/2: a surface).
    cos_theta_e: f32,
    two_sided: bool,
}

impl Bounds {
    fn union(a: &Bounds, b: &Bounds) -> Bounds {
        if a.power == 0.0 {
            return *b;
        }
        if b.power == 0.0 {
            return *a;
        }
        Bounds {
            aabb: a.aabb.union(b.aabb),
            power: a.power + b.power,
            normals: Cone::union(a.normals, b.normals),
            cos_theta_e: a.cos_theta_e.min(b.cos_theta_e),
            two_sided: a.two_sided || b.two_sided,
        }
    }
}

/// A node's bounds in the form [`Importance::at`] reads: what `Bounds` gives, with the parts
/// that do not depend on the shading point (centre, half diagonal, the cone's sine) worked
/// out once at build time rather than at every visit (the same operations, the same bits).
#[derive(Clone, Copy, Debug)]
struct Importance {
    center: Vec3,
    half_diag: f32,
    axis: Vec3,
    cos_o: f32,
    sin_o: f32,
    cos_theta_e: f32,
    power: f32,
    two_sided: bool,
}

impl Importance {
    fn new(b: &Bounds) -> Importance {
        let cos_o = b.normals.cos_theta;
        Importance {
            center: b.aabb.center(),
            half_diag: (b.aabb.max - b.aabb.min).length() * 0.5,
            axis: b.normals.axis,
            cos_o,
            sin_o: (1.0 - cos_o * cos_o).max(0.0).sqrt(),
            cos_theta_e: b.cos_theta_e,
            power: b.power,
            two_sided: b.two_sided,
        }
    }

    /// An upper bound (up to a constant) of what the lights send to `p`.
    #[inline]
    fn at(&self, p: Vec3) -> f32 {
        if self.power == 0.0 {
            return 0.0;
        }
        let half_diag = self.half_diag;
        let d = p - self.center;
        let dist2 = d.length_squared().max(half_diag * half_diag);
        // The cone's angle to the direction towards p, less its own half-angle and the angle
        // the box subtends from p: the smallest angle any light's normal can make with p.
        let dist = d.length();
        let wi = if dist > 0.0 { d / dist } else { self.axis };
        let mut cos_w = self.axis.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        let (cos_b, sin_b) = if dist <= half_diag {
            (-1.0, 0.0)
        } else {
            let s = half_diag / dist;
            ((1.0 - s * s).max(0.0).sqrt(), s)
        };
        // cos(max(0, θw - θo)) then cos(max(0, that - θb)).
        let (cos_x, sin_x) = minus_clamped(cos_w, sin_w, self.cos_o, self.sin_o);
        let (cos_p, _) = minus_clamped(cos_x, sin_x, cos_b, sin_b);
        if cos_p <= self.cos_theta_e {
            return 0.0;
        }
        self.power * cos_p.max(0.0) / dist2
    }
}

/// cos and sin of max(0, a - b) from those of a and b (angles in [0, π]).
#[inline]
fn minus_clamped(cos_a: f32, sin_a: f32, cos_b: f32, sin_b: f32) -> (f32, f32) {
    if cos_a >= cos_b {
        return (1.0, 0.0);
    }
    (cos_a * cos_b + sin_a * sin_b, (sin_a * cos_b - cos_a * sin_b).max(0.0))
}

/// Whether the tree holds each triangle of this light as a leaf of its own (meshes other
/// than a single rectangle, which is sampled as a whole, by solid angle or by its texels,
/// and than a disk sampled by its texels).
pub fn by_triangle(light: &Light) -> bool {
    matches!(light, Light::Mesh { emitter, importance: None, .. }
        if emitter.rectangle.is_none() && emitter.triangles.len() > 1)
}

/// The bounds of triangle `t` of a mesh light split by triangle.
fn triangle_bounds(light: &Light, t: usize) -> Option<Bounds> {
    let Light::Mesh { emitter, radiance, two_sided, .. } = light else { return None };
    let [a, b, c] = emitter.triangles[t];
    let n = (b - a).cross(c - a);
    let area = 0.5 * n.length();
    let sides = if *two_sided { 2.0 } else { 1.0 };
    let luminance = match radiance {
        Texture::Constant(c) => c.luminance(),
        _ => textured_luminance(emitter, radiance, t),
    };
    let power = sides * PI * area * luminance;
    if !(power > 0.0 && power.is_finite()) {
        return None;
    }
    let normals = Cone { axis: n.normalize(), cos_theta: 1.0 };
    Some(Bounds { aabb: Aabb::EMPTY.grow(a).grow(b).grow(c), power, normals, cos_theta_e: 0.0, two_sided: *two_sided })
}

/// Barycentric points spread over a triangle (the centroids of its 16 sub-triangles after
/// two rounds of midpoint subdivision, then its corners), where a textured triangle's
/// radiance is read for its power.
const TRIANGLE_READS: [[f32; 2]; 19] = {
    let mut points = [[0.0f32; 2]; 19];
    // Sub-triangle (i, j) of a 4 x 4 grid in barycentric coordinates: upward ones have
    // centroid ((i + 1/3), (j + 1/3)) / 4, downward ones ((i + 2/3), (j + 2/3)) / 4.
    let mut k = 0;
    let mut i = 0;
    while i < 4 {
        let mut j = 0;
        while i + j < 4 {
            points[k] = [(i as f32 + 1.0 / 3.0) / 4.0, (j as f32 + 1.0 / 3.0) / 4.0];
            k += 1;
            if i + j < 3 {
                points[k] = [(i as f32 + 2.0 / 3.0) / 4.0, (j as f32 + 2.0 / 3.0) / 4.0];
                k += 1;
            }
            j += 1;
        }
        i += 1;
    }
    points[16] = [0.0, 0.0];
    points[17] = [1.0, 0.0];
    points[18] = [0.0, 1.0];
    points
};

/// The luminance of a textured mesh light over triangle `t`, for the tree's importance: the
/// mean of the texture read at [`TRIANGLE_READS`] (as a hit there reads it), but at least a
/// thousandth of the texture's mean, so that a triangle whose reads miss a small bright
/// region is still chosen now and then. Only the choice of triangle depends on it; the
/// probabilities are exact whatever it says.
fn textured_luminance(emitter: &super::MeshEmitter, radiance: &Texture, t: usize) -> f32 {
    let sum: f32 =
        TRIANGLE_READS.iter().map(|&e| radiance.eval_at(&emitter.texture_point(t, e)).luminance().max(0.0)).sum();
    let mean = sum / TRIANGLE_READS.len() as f32;
    let floor = 1e-3 * radiance.mean().luminance().max(0.0);
    if mean.is_finite() {
        mean.max(floor)
    } else {
        floor
    }
}

/// The bounds of one light; `None` for infinite lights and lights that emit nothing.
fn light_bounds(light: &Light) -> Option<Bounds> {
    let power = light.power();
    if light.is_infinite() || !(power > 0.0 && power.is_finite()) {
        return None;
    }
    let point = |p: Vec3| Aabb { min: p, max: p };
    let surface =
        |aabb: Aabb, normals: Cone, two_sided: bool| Bounds { aabb, power, normals, cos_theta_e: 0.0, two_sided };
    Some(match light {
        Light::Point { position, .. } => {
            Bounds { aabb: point(*position), power, normals: Cone::ALL, cos_theta_e: 0.0, two_sided: false }
        }
        Light::Spot { position, frame, cutoff, .. } => Bounds {
            aabb: point(*position),
            power,
            normals: Cone { axis: frame.to_world(Vec3::Z), cos_theta: cutoff.cos() },
            // Nothing beyond the cutoff: the cone is the whole of it.
            cos_theta_e: 1.0 - 1e-6,
            two_sided: false,
        },
        Light::Projected(l) => {
            Bounds { aabb: point(l.position()), power, normals: Cone::ALL, cos_theta_e: 0.0, two_sided: false }
        }
        Light::Mesh { emitter, two_sided, .. } => {
            let mut aabb = Aabb::EMPTY;
            let mut normals: Option<Cone> = None;
            for [a, b, c] in &emitter.triangles {
                aabb = aabb.grow(*a).grow(*b).grow(*c);
                let n = (*b - *a).cross(*c - *a);
                if n.length_squared() > 0.0 {
                    let cone = Cone { axis: n.normalize(), cos_theta: 1.0 };
                    normals = Some(normals.map_or(cone, |m| Cone::union(m, cone)));
                }
            }
            surface(aabb, normals.unwrap_or(Cone::ALL), *two_sided)
        }
        Light::Sphere { sphere, .. } => surface(sphere.bounds(), Cone::ALL, false),
        Light::Cylinder { cylinder, .. } => surface(cylinder.bounds(), Cone::ALL, false),
        Light::Directional { .. } | Light::Constant { .. } | Light::EnvMap(_) => return None,
    })
}

#[derive(Clone, Debug)]
struct Node {
    bounds: Importance,
    /// Inner node: its children's indices; leaf: `[light, LEAF]`.
    children: [u32; 2],
    parent: u32,
    /// A leaf's triangle (for a mesh light split by triangle), or `WHOLE`.
    triangle: u32,
}

/// A leaf: a light and, for a mesh split by triangle, the triangle.
type LeafKey = (u32, u32);

const LEAF: u32 = u32::MAX;
const WHOLE: u32 = u32::MAX;
const NO_PARENT: u32 = u32::MAX;
const BINS: usize = 12;

/// The tree and the lights beside it (see the module doc).
#[derive(Clone, Debug)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// Per light: its leaf, or `None` for lights outside the tree or split by triangle.
    leaf_of: Vec<Option<u32>>,
    /// Per light split by triangle: where its triangles' leaves start in `triangle_leaves`.
    first_triangle_leaf: Vec<Option<u32>>,
    triangle_leaves: Vec<u32>,
    infinite: Vec<u32>,
    /// The probability of each infinite light, and of the tree.
    p_infinite: f32,
    p_tree: f32,
}

/// The light chosen (and its triangle, for a mesh split by triangle: the point is then
/// sampled on that triangle), its probability and the random number rescaled for reuse.
#[derive(Clone, Copy, Debug)]
pub struct TreeSample {
    pub index: usize,
    pub triangle: Option<u32>,
    pub pmf: f32,
    pub remapped: f32,
}

impl LightTree {
    /// `None` when no light can be chosen.
    pub fn new(lights: &[Light]) -> Option<LightTree> {
        let infinite: Vec<u32> = (0..lights.len() as u32).filter(|&i| lights[i as usize].is_infinite()).collect();
        let mut leaves: Vec<(LeafKey, Bounds)> = Vec::new();
        let mut first_triangle_leaf = vec![None; lights.len()];
        let mut triangle_count = 0;
        for (i, l) in lights.iter().enumerate() {
            if let (true, Light::Mesh { emitter, .. }) = (by_triangle(l), l) {
                first_triangle_leaf[i] = Some(triangle_count as u32);
                triangle_count += emitter.triangles.len();
                for t in 0..emitter.triangles.len() {
                    leaves.extend(triangle_bounds(l, t).map(|b| ((i as u32, t as u32), b)));
                }
            } else if let Some(b) = light_bounds(l) {
                leaves.push(((i as u32, WHOLE), b));
            }
        }
        let mut nodes = Vec::with_capacity(2 * leaves.len());
        let mut leaf_of = vec![None; lights.len()];
        let mut triangle_leaves = vec![NO_PARENT; triangle_count];
        if !leaves.is_empty() {
            let mut slots =
                LeafSlots { whole: &mut leaf_of, first: &first_triangle_leaf, triangles: &mut triangle_leaves };
            build(&mut nodes, &mut slots, &mut leaves, NO_PARENT);
        }
        let parts = infinite.len() + usize::from(!nodes.is_empty());
        if parts == 0 {
            return None;
        }
        let p = 1.0 / parts as f32;
        Some(LightTree {
            p_tree: if nodes.is_empty() { 0.0 } else { p },
            nodes,
            leaf_of,
            first_triangle_leaf,
            triangle_leaves,
            infinite,
            p_infinite: p,
        })
    }

    /// A light for the point `p`, chosen with `u`; `None` where no light can reach `p`.
    pub fn sample(&self, p: Vec3, u: f32) -> Option<TreeSample> {
        let mut u = u;
        // The infinite lights first, each with p_infinite, then the tree.
        if !self.infinite.is_empty() {
            let k = (u / self.p_infinite) as usize;
            if k < self.infinite.len() {
                let remapped = (u / self.p_infinite - k as f32).clamp(0.0, 0.999_999_94);
                return Some(TreeSample {
                    index: self.infinite[k] as usize,
                    triangle: None,
                    pmf: self.p_infinite,
                    remapped,
                });
            }
            if self.nodes.is_empty() {
                return None;
            }
            let start = self.p_infinite * self.infinite.len() as f32;
            u = ((u - start) / self.p_tree).clamp(0.0, 0.999_999_94);
        }
        let mut pmf = self.p_tree as f64;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.children[1] == LEAF {
                let triangle = (n.triangle != WHOLE).then_some(n.triangle);
                return Some(TreeSample { index: n.children[0] as usize, triangle, pmf: pmf as f32, remapped: u });
            }
            let [l, r] = n.children.map(|c| c as usize);
            let p_left = choice(self.nodes[l].bounds.at(p), self.nodes[r].bounds.at(p))?;
            if u < p_left {
                u = (u / p_left).min(0.999_999_94);
                pmf *= p_left as f64;
                node = l;
            } else {
                u = ((u - p_left) / (1.0 - p_left)).clamp(0.0, 0.999_999_94);
                pmf *= (1.0 - p_left) as f64;
                node = r;
            }
        }
    }

    /// The probability that [`LightTree::sample`] at `p` chooses light `i` (its triangle
    /// `triangle`, for a mesh split by triangle; ignored for other lights).
    pub fn pmf(&self, p: Vec3, i: u32, triangle: u32) -> f32 {
        let leaf = match self.first_triangle_leaf.get(i as usize).copied().flatten() {
            Some(first) => self.triangle_leaves.get((first + triangle) as usize).copied().filter(|&l| l != NO_PARENT),
            None => self.leaf_of.get(i as usize).copied().flatten(),
        };
        let Some(leaf) = leaf else {
            return if self.infinite.contains(&i) { self.p_infinite } else { 0.0 };
        };
        let mut pmf = self.p_tree as f64;
        let mut node = leaf as usize;
        while self.nodes[node].parent != NO_PARENT {
            let parent = self.nodes[node].parent as usize;
            let [l, r] = self.nodes[parent].children.map(|c| c as usize);
            let Some(p_left) = choice(self.nodes[l].bounds.at(p), self.nodes[r].bounds.at(p)) else {
                return 0.0;
            };
            pmf *= if node == l { p_left } else { 1.0 - p_left } as f64;
            node = parent;
        }
        pmf as f32
    }

    /// Whether light `i`'s triangles are leaves of their own.
    pub fn splits(&self, i: u32) -> bool {
        self.first_triangle_leaf.get(i as usize).is_some_and(|f| f.is_some())
    }
}

/// The probability of the left child from the two importances; `None` when both are zero.
#[inline]
fn choice(left: f32, right: f32) -> Option<f32> {
    let total = left + right;
    (total > 0.0).then(|| left / total)
}

/// Where the build records each leaf's node.
struct LeafSlots<'a> {
    whole: &'a mut [Option<u32>],
    first: &'a [Option<u32>],
    triangles: &'a mut [u32],
}

/// Builds the subtree over `items` at the end of `nodes`; returns its index.
fn build(nodes: &mut Vec<Node>, slots: &mut LeafSlots, items: &mut [(LeafKey, Bounds)], parent: u32) -> u32 {
    let index = nodes.len() as u32;
    if let [((light, triangle), b)] = items {
        nodes.push(Node { bounds: Importance::new(b), children: [*light, LEAF], parent, triangle: *triangle });
        match slots.first[*light as usize] {
            Some(first) => slots.triangles[(first + *triangle) as usize] = index,
            None => slots.whole[*light as usize] = Some(index),
        }
        return index;
    }
    let all = items.iter().fold(items[0].1, |acc, (_, b)| Bounds::union(&acc, b));
    nodes.push(Node { bounds: Importance::new(&all), children: [0, 0], parent, triangle: WHOLE });
    let mid = split(items, &all);
    let (left, right) = items.split_at_mut(mid);
    let l = build(nodes, slots, left, index);
    let r = build(nodes, slots, right, index);
    nodes[index as usize].children = [l, r];
    index
}

/// Sorts `items` so that the best split is at the returned index (1..len): binned centroids
/// along each axis, cost by power × orientation measure × surface area (pbrt-v4's
/// light-bounds cost); the middle of the longest axis's order when nothing separates them.
fn split(items: &mut [(LeafKey, Bounds)], all: &Bounds) -> usize {
    let centroid = |b: &Bounds| (b.aabb.min + b.aabb.max) * 0.5;
    let cb = items.iter().fold(Aabb::EMPTY, |a, (_, b)| {
        let c = centroid(b);
        a.grow(c)
    });
    let extent = cb.max - cb.min;
    let mut best: Option<(f32, usize, f32)> = None; // cost, axis, boundary
    for axis in 0..3 {
        let (lo, span) = (cb.min[axis], extent[axis]);
        if !(span > 0.0) {
            continue;
        }
        let bin = |b: &Bounds| (((centroid(b)[axis] - lo) / span * BINS as f32) as usize).min(BINS - 1);
        let mut bins: [Option<Bounds>; BINS] = [None; BINS];
        for (_, b) in items.iter() {
            let k = bin(b);
            bins[k] = Some(bins[k].map_or(*b, |acc| Bounds::union(&acc, b)));
        }
        // Extent ratio: splits across a long box are cheaper than across a thin one.
        let full = all.aabb.max - all.aabb.min;
        let k_r = full.x.max(full.y).max(full.z) / full[axis].max(1e-20);
        // The bounds of bins [0, cut) and [cut, BINS) for every cut, in one sweep each way.
        let merge = |acc: Option<Bounds>, b: &Option<Bounds>| match (acc, b) {
            (Some(a), Some(b)) => Some(Bounds::union(&a, b)),
            (a, b) => a.or(*b),
        };
        let mut below: [Option<Bounds>; BINS] = [None; BINS];
        for cut in 1..BINS {
            below[cut] = merge(below[cut - 1], &bins[cut - 1]);
        }
        let mut above: Option<Bounds> = None;
        for cut in (1..BINS).rev() {
            above = merge(above, &bins[cut]);
            let (Some(l), Some(r)) = (below[cut], above) else { continue };
            let cost = k_r * (cost_of(&l) + cost_of(&r));
            // Ties go to the lower cut, as when the cuts were tried in increasing order.
            if best.is_none_or(|(c, a, _)| cost < c || (cost == c && a == axis)) {
                best = Some((cost, axis, lo + span * cut as f32 / BINS as f32));
            }
        }
    }
    let mid = match best {
        Some((_, axis, boundary)) => {
            let n = partition(items, |b| centroid(b)[axis] < boundary);
            if n == 0 || n == items.len() {
                None
            } else {
                Some(n)
            }
        }
        None => None,
    };
    mid.unwrap_or_else(|| {
        // Nothing to separate: halve the list in a fixed order.
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        items.sort_by(|a, b| centroid(&a.1)[axis].total_cmp(&centroid(&b.1)[axis]).then(a.0.cmp(&b.0)));
        items.len() / 2
    })
}

/// Moves the items for which `left` holds to the front, keeping each side's order; returns
/// their count.
fn partition(items: &mut [(LeafKey, Bounds)], left: impl Fn(&Bounds) -> bool) -> usize {
    let (l, r): (Vec<_>, Vec<_>) = items.iter().copied().partition(|(_, b)| left(b));
    let n = l.len();
    for (slot, item) in items.iter_mut().zip(l.into_iter().chain(r)) {
        *slot = item;
    }
    n
}

/// pbrt-v4's cost of a node: power × the solid-angle measure of its emission cone × the
/// surface area of its box.
fn cost_of(b: &Bounds) -> f32 {
    let theta_o = b.normals.cos_theta.clamp(-1.0, 1.0).acos();
    let theta_e = b.cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let (sin_o, cos_o) = theta_o.sin_cos();
    let m_omega = 2.0 * PI * (1.0 - cos_o)
        + PI / 2.0 * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o + cos_o);
    let d = b.aabb.max - b.aabb.min;
    let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    b.power * m_omega * area.max(1e-12)
}
