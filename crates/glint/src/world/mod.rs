//! The render-ready world: geometry in a two-level BVH, materials, lights and the camera,
//! built from a scene description by `assemble` (the only module that creates one). Its fields
//! are private to the crate: front ends read it through the accessors below.
//!
//! Bottom level: one BVH per mesh, in the mesh's own space. Top level: a BVH over
//! instances, each a reference to a shape with its own transform, so a mesh placed many times
//! costs its memory once. Traversal returns a cheap [`Hit`]; the full
//! [`SurfaceInteraction`] is computed only for the hit that is shaded.

use crate::accel::{prefetch, BvhSplit, FlatMesh, TopLevelBvh};
use crate::camera::Camera;
use crate::geometry::{CurveHit, Curves, Cylinder, SdfGrid, Sphere, TriangleMesh};
use crate::lights::{self, Light, LightSample, LightSelection, LightTree};
use crate::materials::{DielectricSurface, Material, MaterialKind, Texture, TexturePoint};
use crate::math::{Aabb, Frame, Ray, Rgb, Transform, Vec3};
use crate::media::{Medium, MediumBoundary};
use crate::sampling::Distribution1d;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeRef {
    Mesh(u32),
    Sphere(u32),
    Cylinder(u32),
    SdfGrid(u32),
    /// A set of curves; a hit's `prim` is its segment's first control point, `b1` the
    /// segment parameter.
    Curves(u32),
}

#[derive(Clone, Debug)]
pub struct Instance {
    pub shape: ShapeRef,
    /// Object to world; `None` for the identity (the common case, traced without transforms).
    pub to_world: Option<Transform>,
    pub material: u32,
    /// Index into `Scene::lights` when the shape emits light.
    pub light: Option<u32>,
    pub flip_normals: bool,
    pub bounds: Aabb,
    /// The media on the shape's two sides (none: rays keep their medium).
    pub media: MediumBoundary,
}

/// How a batch of rays is traced: the answers are the same bits either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BatchTraversal {
    /// Each ray through the single-ray kernels, one after another.
    OneByOne,
    /// Several traversals in flight per thread, interleaved ([`World::intersect_batch`]).
    Interleaved,
    /// Closest hits and occlusion in packets of rays ([`World::intersect_packets`],
    /// [`World::occluded_packets`]).
    Packets,
}

/// Mesh data (positions, normals, uvs, indices) above which the wavefront prefetches hit
/// data: about a core's L2. Below it the prefetches cost 2% on the Cornell box and gain
/// nothing; above it they gained 2 to 4% on the 100k-triangle dragon (BENCHMARKS.md).
const PREFETCH_HITS_ABOVE_BYTES: usize = 1 << 20;

/// What traversal returns: enough to find the hit again, nothing more.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub instance: u32,
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
}

/// Everything shading needs about a hit point.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    pub p: Vec3,
    /// Geometric normal (unit, world), after `flip_normals`; not turned towards the ray.
    pub ng: Vec3,
    /// Shading frame (interpolated normal when the mesh has one).
    pub frame: Frame,
    pub uv: [f32; 2],
    pub instance: u32,
    pub material: u32,
    pub light: Option<u32>,
    pub t: f32,
    /// Position derivatives along the surface's uv (world space, not normalised), as Mitsuba
    /// defines them: from the triangle's uvs (its barycentrics when the mesh has none), the
    /// sphere's spherical coordinates. The shading frame's `s` is `dpdu` made orthogonal to
    /// the shading normal, as in Mitsuba, so tangent-space normal maps agree.
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    /// The hit primitive (triangle index; 0 for spheres) and its barycentrics (b1, b2), for
    /// per-vertex and per-face mesh attributes.
    pub prim: u32,
    pub bary: [f32; 2],
}

/// A light chosen for next-event estimation: its index, its triangle (where the light tree
/// chooses a mesh's triangles one by one), its probability, and the random number rescaled
/// within its share (for the point on the light).
#[derive(Clone, Copy, Debug)]
pub struct LightChoice {
    pub index: usize,
    pub triangle: Option<u32>,
    pub pmf: f32,
    pub remapped: f32,
}

pub struct World {
    pub(crate) meshes: Vec<Arc<TriangleMesh>>,
    pub(crate) spheres: Vec<Sphere>,
    pub(crate) cylinders: Vec<Cylinder>,
    pub(crate) sdf_grids: Vec<SdfGrid>,
    pub(crate) curves: Vec<Curves>,
    pub(crate) instances: Vec<Instance>,
    /// Over instances: the binary reference and the 8-wide tree that traversal uses.
    pub(crate) top: TopLevelBvh,
    pub(crate) materials: Vec<Material>,
    pub(crate) lights: Vec<Light>,
    /// Indices of infinite lights that a escaping ray sees (constant, envmap).
    pub(crate) environment_lights: Vec<u32>,
    pub(crate) camera: Camera,
    pub(crate) bounds: Aabb,
    pub(crate) light_distribution: Option<Distribution1d>,
    /// The light BVH under `LightSelection::Tree` (then `light_distribution` is `None`).
    pub(crate) light_tree: Option<LightTree>,
    pub(crate) light_selection: LightSelection,
    pub(crate) bvh_split: BvhSplit,
    pub(crate) bvh_build_seconds: f64,
    /// Some material has a mask (`mask`) or culled back faces (single-sided glTF): rays
    /// then look past what they hit.
    pub(crate) has_masks: bool,
    /// Some material is a passage for volpath (`null`, `thindielectric`): its shadow rays
    /// then look past what they hit. Kept here so that no path scans the materials.
    pub(crate) has_passage_materials: bool,
    /// The meshes are large enough that the hit data `interaction` reads is often out of
    /// cache: the wavefront then prefetches it (on small scenes that only costs time).
    pub(crate) prefetch_hits: bool,
    /// Participating media, indexed by [`Instance::media`] and `camera_medium`.
    pub(crate) media: Vec<Medium>,
    /// The medium the camera sits in.
    pub(crate) camera_medium: Option<u32>,
}

impl World {
    /// Builds the top-level BVH and the light-selection distribution. Called once by the
    /// scene builder after all instances and lights are in place.
    pub(crate) fn finish(&mut self, selection: LightSelection) {
        let boxes: Vec<Aabb> = self.instances.iter().map(|i| i.bounds).collect();
        // Untransformed mesh instances go into one merged triangle BVH (see TopLevelBvh).
        let flat: Vec<FlatMesh> = self
            .instances
            .iter()
            .enumerate()
            .filter_map(|(i, inst)| match (inst.shape, &inst.to_world) {
                (ShapeRef::Mesh(m), None) => {
                    let mesh = &self.meshes[m as usize];
                    Some(FlatMesh { instance: i as u32, positions: &mesh.positions, indices: &mesh.indices })
                }
                _ => None,
            })
            .collect();
        self.top = TopLevelBvh::build_flattening(&boxes, self.bvh_split, &flat);
        self.bounds = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        self.update_material_flags();
        let mesh_bytes: usize = self
            .meshes
            .iter()
            .map(|m| {
                let vertex =
                    std::mem::size_of::<Vec3>() * (1 + m.normals.is_some() as usize) + 8 * m.uvs.is_some() as usize;
                m.positions.len() * vertex + m.indices.len() * std::mem::size_of::<[u32; 3]>()
            })
            .sum();
        self.prefetch_hits = mesh_bytes > PREFETCH_HITS_ABOVE_BYTES;
        self.set_light_selection(selection);
    }

    /// Sets the flags that say which materials the scene has; called whenever they change.
    pub(crate) fn update_material_flags(&mut self) {
        self.has_masks = self.materials.iter().any(Material::may_pass_rays);
        self.has_passage_materials = self.materials.iter().any(|m| {
            matches!(&m.kind, MaterialKind::Null(_))
                || matches!(&m.kind, MaterialKind::Dielectric(d) if matches!(d.surface, DielectricSurface::Thin))
        });
    }

    /// The share of next-event light choices made by power under `LightSelection::Power`; the
    /// rest are uniform.
    pub const POWER_SHARE: f32 = 0.5;

    /// The bounded lights from which `LightSelection::Auto` takes the tree: the smallest
    /// many-light scene measured where it won (`tests/scenes/mitsuba/many-spheres.xml`, 400
    /// sphere lights: 0.48x power's error at equal spp; a street of 10,000: 0.25x its
    /// equal-error time). With a few lights it lost (BENCHMARKS.md, "Light selection").
    pub const AUTO_TREE_LIGHTS: usize = 400;

    /// What `LightSelection::Auto` means for these lights (see its doc).
    pub fn auto_light_selection(lights: &[Light]) -> LightSelection {
        let bounded = lights.iter().filter(|l| !l.is_infinite() && l.power() > 0.0).count();
        let varying_mesh = lights.iter().any(|l| {
            matches!(l, Light::Mesh { radiance, .. } if !matches!(radiance, Texture::Constant(_)))
                && lights::by_triangle(l)
        });
        if bounded >= Self::AUTO_TREE_LIGHTS || varying_mesh {
            LightSelection::Tree
        } else {
            LightSelection::Power
        }
    }

    pub fn set_light_selection(&mut self, selection: LightSelection) {
        self.light_selection = selection;
        self.light_tree = None;
        let weights: Vec<f32> = match selection {
            // Resolved here, so that `light_selection()` says which one runs.
            LightSelection::Auto => return self.set_light_selection(Self::auto_light_selection(&self.lights)),
            LightSelection::Tree => {
                self.light_tree = LightTree::new(&self.lights);
                self.light_distribution = None;
                return;
            }
            LightSelection::Uniform => vec![1.0; self.lights.len()],
            LightSelection::Power => {
                // An infinite light's "power" (radiance times the scene's cross-section) says
                // little about what it sends to any one point: by it a dim sky outweighs a sun-
                // like area light and starves it (3x the error on bench/scenes/dragon.xml). As
                // pbrt-v4's light BVH does, each infinite light is chosen as often as all the
                // bounded lights together, and those share their part by power.
                //
                // Half of the choices are then made uniformly (a defensive mixture): power says
                // how much light a light sends everywhere, not to a given point, and a weak
                // light close to what it lights (Veach's MIS scene: four small spheres of power
                // 1 beside one of 200) was picked so rarely that its rare picks, weighted by
                // the inverse probability, were fireflies: 4x Mitsuba's error (it picks
                // uniformly) on that documentation scene, and channel means 4% off at 256 spp.
                // With the mixture no light is picked less than half as often as uniformly.
                let bounded: f32 = self.lights.iter().filter(|l| !l.is_infinite()).map(|l| l.power()).sum();
                let infinite_weight = if bounded > 0.0 { bounded } else { 1.0 };
                let by_power: Vec<f32> =
                    self.lights.iter().map(|l| if l.is_infinite() { infinite_weight } else { l.power() }).collect();
                let total: f32 = by_power.iter().sum();
                let uniform = 1.0 / self.lights.len().max(1) as f32;
                if total > 0.0 && total.is_finite() {
                    by_power
                        .iter()
                        .map(|&w| Self::POWER_SHARE * (w / total) + (1.0 - Self::POWER_SHARE) * uniform)
                        .collect()
                } else {
                    by_power
                }
            }
            LightSelection::Area => {
                let areas: Vec<f32> = self.lights.iter().map(|l| l.area()).collect();
                let n_area = areas.iter().filter(|&&a| a > 0.0).count();
                let mean = if n_area > 0 { areas.iter().sum::<f32>() / n_area as f32 } else { 1.0 };
                areas.iter().map(|&a| if a > 0.0 { a } else { mean }).collect()
            }
        };
        self.light_distribution = Distribution1d::new(&weights);
    }

    /// Probability of choosing light `i` for next-event estimation under the selections that
    /// do not depend on the shading point (0 under `LightSelection::Tree`: see `light_pmf_at`).
    #[inline]
    pub fn light_pmf(&self, i: u32) -> f32 {
        self.light_distribution.as_ref().map_or(0.0, |d| d.pmf(i as usize))
    }

    /// Probability of choosing light `i` (its triangle `triangle`, where the light tree
    /// chooses a mesh's triangles one by one) for next-event estimation at `p`.
    #[inline]
    pub fn light_pmf_at(&self, p: Vec3, i: u32, triangle: u32) -> f32 {
        match &self.light_tree {
            Some(tree) => tree.pmf(p, i, triangle),
            None => self.light_pmf(i),
        }
    }

    /// The density with which next-event estimation at `p` reaches the point `q` (normal `n`,
    /// primitive `prim`) of light `li` along `wi`: the probability of choosing the light
    /// times the light's own density. What MIS weighs a BSDF-sampled ray that hit it by.
    #[inline]
    pub fn light_pdf(&self, p: Vec3, li: u32, prim: u32, wi: Vec3, q: Vec3, n: Vec3) -> f32 {
        let light = &self.lights[li as usize];
        match &self.light_tree {
            Some(tree) if tree.splits(li) => tree.pmf(p, li, prim) * light.pdf_li_triangle(p, wi, q, n, prim as usize),
            Some(tree) => tree.pmf(p, li, prim) * light.pdf_li(p, wi, q, n),
            None => self.light_pmf(li) * light.pdf_li(p, wi, q, n),
        }
    }

    /// Chooses a light for next-event estimation at `p` with `u`; `None` without lights, or
    /// where the tree finds that none reaches `p`.
    #[inline]
    pub fn choose_light(&self, p: Vec3, u: f32) -> Option<LightChoice> {
        if let Some(tree) = &self.light_tree {
            let s = tree.sample(p, u)?;
            return Some(LightChoice { index: s.index, triangle: s.triangle, pmf: s.pmf, remapped: s.remapped });
        }
        let pick = self.light_distribution.as_ref()?.sample(u);
        Some(LightChoice { index: pick.index, triangle: None, pmf: pick.pmf, remapped: pick.remapped })
    }

    /// Samples the chosen light from `p`, with `u[0]` replaced by the choice's rescaled one.
    #[inline]
    pub fn sample_chosen(&self, c: &LightChoice, p: Vec3, u1: f32) -> Option<LightSample> {
        let light = &self.lights[c.index];
        match c.triangle {
            Some(t) => light.sample_li_triangle(p, t as usize, [c.remapped, u1]),
            None => light.sample_li(p, [c.remapped, u1]),
        }
    }

    /// Whether next-event estimation has any light to choose.
    #[inline]
    pub fn can_choose_lights(&self) -> bool {
        self.light_distribution.is_some() || self.light_tree.is_some()
    }

    /// Closest hit along the ray within its interval.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut r = *ray;
        let best: Option<Hit> = self.top.intersect_flat(&mut r).map(|(instance, prim, h)| Hit {
            t: h.t,
            instance,
            prim,
            b1: h.b1,
            b2: h.b2,
        });
        self.intersect_unflattened(&mut r, best)
    }

    /// Closest hits of many rays: `hits[i]` is [`World::intersect`] of `rays[i]`, bit for bit.
    /// The flat BVH (all of a scene's untransformed meshes) traces several rays in flight per
    /// thread; the instances outside it are then traced one ray at a time.
    ///
    /// Panics if the slices differ in length.
    pub fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "intersect_batch: one hit slot per ray");
        let mut flat = vec![None; rays.len()];
        self.top.intersect_flat_batch(rays, &mut flat);
        for ((ray, f), out) in rays.iter().zip(flat).zip(hits.iter_mut()) {
            let best = f.map(|(instance, prim, h)| Hit { t: h.t, instance, prim, b1: h.b1, b2: h.b2 });
            // As the single-ray flat traversal leaves it: shortened to the hit.
            let mut r = Ray { t_max: best.map_or(ray.t_max, |h| h.t), ..*ray };
            *out = self.intersect_unflattened(&mut r, best);
        }
    }

    /// Closest hits of many rays, the flat BVH traced in packets of rays: `hits[i]` is
    /// [`World::intersect`] of `rays[i]`, bit for bit (the tie rule makes the answer
    /// independent of visit order); the instances outside the flat BVH are then traced one
    /// ray at a time.
    ///
    /// Panics if the slices differ in length.
    pub fn intersect_packets(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "intersect_packets: one hit slot per ray");
        let mut flat = vec![None; rays.len()];
        self.top.intersect_flat_packets(rays, &mut flat);
        for ((ray, f), out) in rays.iter().zip(flat).zip(hits.iter_mut()) {
            let best = f.map(|(instance, prim, h)| Hit { t: h.t, instance, prim, b1: h.b1, b2: h.b2 });
            let mut r = Ray { t_max: best.map_or(ray.t_max, |h| h.t), ..*ray };
            *out = self.intersect_unflattened(&mut r, best);
        }
    }

    /// Closest hits of many rays traced as `traversal` says (same answers either way).
    pub fn intersect_many(&self, rays: &[Ray], hits: &mut [Option<Hit>], traversal: BatchTraversal) {
        match traversal {
            BatchTraversal::Interleaved => self.intersect_batch(rays, hits),
            BatchTraversal::Packets => self.intersect_packets(rays, hits),
            BatchTraversal::OneByOne => {
                assert_eq!(rays.len(), hits.len(), "intersect_many: one hit slot per ray");
                for (r, h) in rays.iter().zip(hits.iter_mut()) {
                    *h = self.intersect(r);
                }
            }
        }
    }

    /// Occlusion of many rays traced as `traversal` says (same answers either way).
    pub fn occluded_many(&self, rays: &[Ray], blocked: &mut [bool], traversal: BatchTraversal) {
        match traversal {
            BatchTraversal::Interleaved => self.occluded_batch(rays, blocked),
            BatchTraversal::Packets => self.occluded_packets(rays, blocked),
            BatchTraversal::OneByOne => {
                assert_eq!(rays.len(), blocked.len(), "occluded_many: one answer per ray");
                for (r, b) in rays.iter().zip(blocked.iter_mut()) {
                    *b = self.occluded(r);
                }
            }
        }
    }

    /// Whether each ray is blocked, the flat BVH traced in packets of rays: `blocked[i]` is
    /// [`World::occluded`] of `rays[i]`.
    ///
    /// Panics if the slices differ in length.
    pub fn occluded_packets(&self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "occluded_packets: one answer per ray");
        self.top.occluded_flat_packets(rays, blocked);
        for (ray, b) in rays.iter().zip(blocked.iter_mut()) {
            *b = *b || self.occluded_unflattened(ray);
        }
    }

    /// Whether each ray is blocked: `blocked[i]` is [`World::occluded`] of `rays[i]`.
    ///
    /// Panics if the slices differ in length.
    pub fn occluded_batch(&self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "occluded_batch: one answer per ray");
        self.top.occluded_flat_batch(rays, blocked);
        for (ray, b) in rays.iter().zip(blocked.iter_mut()) {
            *b = *b || self.occluded_unflattened(ray);
        }
    }

    /// The closest hit among the instances outside the flat BVH, or `best` (the flat BVH's,
    /// whose distance `r.t_max` already is) when none comes first.
    ///
    /// The order of hits (the tie rule, see `accel::wide::ClosestLeaf`): smallest
    /// `(t, instance, prim)`, so that which instance or primitive a ray through a shared edge
    /// or coincident surfaces reports does not depend on the order anything is visited in.
    /// `r.t_max` stays the best `t` (it culls the top-level tree, whose box test keeps boxes
    /// entered at exactly that `t`); each instance is asked with the next float up as its
    /// bound (see `intersect_instance`) and answers with its own smallest `(t, prim)`.
    #[inline]
    fn intersect_unflattened(&self, r: &mut Ray, mut best: Option<Hit>) -> Option<Hit> {
        if !self.top.has_unflattened() {
            return best; // not even the ray set-up of an empty traversal
        }
        self.top.traverse(r, |inst_idx, r| {
            let inst = &self.instances[inst_idx as usize];
            let found = self.intersect_instance(inst, r, best.is_some());
            match found {
                Some(h) if best.is_none_or(|b| hit_before(h.t, inst_idx, h.prim, &b)) => {
                    r.t_max = h.t;
                    best = Some(Hit { instance: inst_idx, ..h });
                    true
                }
                _ => false,
            }
        });
        best
    }

    /// One instance's closest hit within `r`'s interval, its own smallest `(t, prim)`; with
    /// `tie` (a best hit at `r.t_max` exists), hits at exactly `r.t_max` count too.
    ///
    /// Signed distance grids and curves are asked with `r` as it is: their root searches use
    /// the interval's end, so a bound one float higher could move their hits' bits. Their ties
    /// with another instance at exactly the same `t` keep the instance found first (rare, and
    /// so not yet order-independent); their own primitives follow the rule (curves compare
    /// `(t, point)`; grids' voxels are in their own BVH's order, also not yet).
    #[inline]
    fn intersect_instance(&self, inst: &Instance, r: &Ray, tie: bool) -> Option<Hit> {
        let widened;
        let r = match inst.shape {
            ShapeRef::Mesh(_) | ShapeRef::Sphere(_) | ShapeRef::Cylinder(_) if tie => {
                // `r.t_max` is a hit's `t`, finite, so the next float up is a valid bound.
                widened = Ray { t_max: r.t_max.next_up(), ..*r };
                &widened
            }
            _ => r,
        };
        match inst.shape {
            ShapeRef::Mesh(m) => {
                let mesh = &self.meshes[m as usize];
                let mut local = match &inst.to_world {
                    None => *r,
                    Some(t) => Ray { origin: t.inv_point(r.origin), dir: t.inv_vector(r.dir), ..*r },
                };
                mesh.intersect(&mut local).map(|(tri, h)| Hit { t: h.t, instance: 0, prim: tri, b1: h.b1, b2: h.b2 })
            }
            ShapeRef::Sphere(s) => {
                self.spheres[s as usize].intersect(r).map(|t| Hit { t, instance: 0, prim: 0, b1: 0.0, b2: 0.0 })
            }
            ShapeRef::Cylinder(c) => {
                self.cylinders[c as usize].intersect(r).map(|t| Hit { t, instance: 0, prim: 0, b1: 0.0, b2: 0.0 })
            }
            ShapeRef::SdfGrid(g) => {
                self.sdf_grids[g as usize].intersect(r).map(|(t, prim)| Hit { t, instance: 0, prim, b1: 0.0, b2: 0.0 })
            }
            ShapeRef::Curves(c) => self.curves[c as usize].intersect(r).map(|h| curve_hit(h, 0)),
        }
    }

    /// True when anything blocks the ray within its interval.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.top.occluded_flat(ray) || self.occluded_unflattened(ray)
    }

    /// Whether an instance outside the flat BVH blocks the ray.
    #[inline]
    fn occluded_unflattened(&self, ray: &Ray) -> bool {
        if !self.top.has_unflattened() {
            return false;
        }
        self.top.occluded(ray, |inst_idx, r| {
            let inst = &self.instances[inst_idx as usize];
            match inst.shape {
                ShapeRef::Mesh(m) => {
                    let mesh = &self.meshes[m as usize];
                    match &inst.to_world {
                        None => mesh.occluded(r),
                        Some(t) => {
                            mesh.occluded(&Ray { origin: t.inv_point(r.origin), dir: t.inv_vector(r.dir), ..*r })
                        }
                    }
                }
                ShapeRef::Sphere(s) => self.spheres[s as usize].intersect(r).is_some(),
                ShapeRef::Cylinder(c) => self.cylinders[c as usize].intersect(r).is_some(),
                ShapeRef::SdfGrid(g) => self.sdf_grids[g as usize].occluded(r),
                ShapeRef::Curves(c) => self.curves[c as usize].occluded(r),
            }
        })
    }

    /// Every primitive of every instance, for testing the BVH against brute force.
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<Hit> {
        let mut r = *ray;
        let mut best = None;
        for (i, inst) in self.instances.iter().enumerate() {
            let h = match inst.shape {
                ShapeRef::Mesh(m) => {
                    let local = match &inst.to_world {
                        None => r,
                        Some(t) => Ray { origin: t.inv_point(r.origin), dir: t.inv_vector(r.dir), ..r },
                    };
                    self.meshes[m as usize].intersect_brute_force(&local).map(|(tri, h)| Hit {
                        t: h.t,
                        instance: i as u32,
                        prim: tri,
                        b1: h.b1,
                        b2: h.b2,
                    })
                }
                ShapeRef::Sphere(s) => self.spheres[s as usize].intersect(&r).map(|t| Hit {
                    t,
                    instance: i as u32,
                    prim: 0,
                    b1: 0.0,
                    b2: 0.0,
                }),
                ShapeRef::Cylinder(c) => self.cylinders[c as usize].intersect(&r).map(|t| Hit {
                    t,
                    instance: i as u32,
                    prim: 0,
                    b1: 0.0,
                    b2: 0.0,
                }),
                ShapeRef::SdfGrid(g) => self.sdf_grids[g as usize].intersect(&r).map(|(t, prim)| Hit {
                    t,
                    instance: i as u32,
                    prim,
                    b1: 0.0,
                    b2: 0.0,
                }),
                ShapeRef::Curves(c) => {
                    self.curves[c as usize].intersect_brute_force(&r).map(|h| curve_hit(h, i as u32))
                }
            };
            if let Some(h) = h {
                r.t_max = h.t;
                best = Some(h);
            }
        }
        best
    }

    /// The full surface interaction for a hit found along `ray`.
    /// Where textures are looked up for `si`: its uv, and for meshes the triangle, its
    /// barycentrics and the mesh (for mesh attributes).
    pub fn texture_point(&self, si: &SurfaceInteraction) -> TexturePoint<'_> {
        let mesh = self.instances.get(si.instance as usize).and_then(|inst| match inst.shape {
            ShapeRef::Mesh(m) => self.meshes.get(m as usize).map(|m| &**m),
            ShapeRef::Sphere(_) | ShapeRef::Cylinder(_) | ShapeRef::SdfGrid(_) | ShapeRef::Curves(_) => None,
        });
        TexturePoint { uv: si.uv, prim: si.prim, bary: si.bary, mesh }
    }

    /// Radiance the surface at `si` emits back along a ray that travelled along `wi` (black
    /// unless it is an area light, read at its texture point).
    pub fn emitted(&self, si: &SurfaceInteraction, wi: Vec3) -> Rgb {
        match si.light.and_then(|l| self.lights.get(l as usize)) {
            Some(light) => light.emitted(&self.texture_point(si), si.ng, wi),
            None => Rgb::BLACK,
        }
    }

    /// Whether the wavefront prefetches hit data: the meshes are larger than about a core's
    /// L2 cache (see `PREFETCH_HITS_ABOVE_BYTES`).
    pub fn prefetches_hits(&self) -> bool {
        self.prefetch_hits
    }

    /// First of two prefetches for [`World::interaction`] of `hit`: starts loading the hit
    /// triangle's vertex indices. Changes nothing; the wavefront calls it a few paths ahead.
    #[inline]
    pub(crate) fn prefetch_hit_indices(&self, hit: &Hit) {
        if let Some(mesh) = self.hit_mesh(hit) {
            if let Some(ix) = mesh.indices.get(hit.prim as usize) {
                prefetch(ix);
            }
        }
    }

    /// Second prefetch for `hit`, once its indices are (likely) in cache: starts loading the
    /// vertices' positions, normals and uvs, which `interaction` reads at random places of
    /// large meshes (the wait for them was about 40% of its time on the 100k-triangle dragon).
    #[inline]
    pub(crate) fn prefetch_hit_vertices(&self, hit: &Hit) {
        let Some(mesh) = self.hit_mesh(hit) else { return };
        let Some(&ix) = mesh.indices.get(hit.prim as usize) else { return };
        for i in ix {
            if let Some(p) = mesh.positions.get(i as usize) {
                prefetch(p);
            }
            if let Some(n) = mesh.normals.as_ref().and_then(|n| n.get(i as usize)) {
                prefetch(n);
            }
            if let Some(t) = mesh.uvs.as_ref().and_then(|t| t.get(i as usize)) {
                prefetch(t);
            }
        }
    }

    #[inline]
    fn hit_mesh(&self, hit: &Hit) -> Option<&TriangleMesh> {
        match self.instances.get(hit.instance as usize)?.shape {
            ShapeRef::Mesh(m) => self.meshes.get(m as usize).map(|m| &**m),
            _ => None,
        }
    }

    pub fn interaction(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        let inst = &self.instances[hit.instance as usize];
        let (p, ng, mut ns, uv, dpdu, dpdv) = match inst.shape {
            ShapeRef::Mesh(m) => {
                let mesh = &self.meshes[m as usize];
                let tri = hit.prim as usize;
                let [i0, i1, i2] = mesh.indices[tri].map(|i| i as usize);
                let corners = mesh.vertices(tri);
                let normals = mesh.normals.as_ref().map(|n| [n[i0], n[i1], n[i2]]);
                let uvs = mesh.uvs.as_ref().map(|t| [t[i0], t[i1], t[i2]]);
                let TriangleSurface { p: p_obj, ng: ng_obj, ns: ns_obj, uv, dpdu, dpdv } =
                    TriangleSurface::at(corners, normals, uvs, hit.b1, hit.b2);
                match &inst.to_world {
                    None => (p_obj, ng_obj, ns_obj, uv, dpdu, dpdv),
                    Some(t) => {
                        // Orientation follows the winding in world space, as when vertices
                        // are transformed: a mirroring transform flips the normal.
                        let flip = if t.swaps_handedness() { -1.0 } else { 1.0 };
                        let ns = ns_obj.map(|n| t.normal(n));
                        (t.point(p_obj), t.normal(ng_obj) * flip, ns, uv, t.vector(dpdu), t.vector(dpdv))
                    }
                }
            }
            ShapeRef::Sphere(s) => {
                let sph = &self.spheres[s as usize];
                let mut p = ray.at(hit.t);
                let n = (p - sph.center) / sph.radius;
                // Re-project onto the surface to remove the error of the root.
                p = sph.center + n * sph.radius;
                let (dpdu, dpdv) = sphere_dpduv(sph.to_local(n), sph.radius);
                let (dpdu, dpdv) = (sph.to_world(dpdu), sph.to_world(dpdv));
                (p, n, None, sph.uv(n), dpdu, dpdv)
            }
            ShapeRef::Cylinder(c) => {
                let q = self.cylinders[c as usize].point(ray, hit.t);
                (q.p, q.n, None, q.uv, q.dpdu, q.dpdv)
            }
            ShapeRef::SdfGrid(g) => {
                // No uv parameterisation (as in Mitsuba): uv and its derivatives are zero.
                let q = self.sdf_grids[g as usize].point(ray, hit.t, hit.prim);
                (q.p, q.n, Some(q.shading_n), [0.0, 0.0], Vec3::ZERO, Vec3::ZERO)
            }
            ShapeRef::Curves(c) => {
                let q = self.curves[c as usize].point(ray, &CurveHit { t: hit.t, point: hit.prim, v: hit.b1 });
                (q.p, q.n, None, q.uv, q.dpdu, q.dpdv)
            }
        };
        let (ng, n_shading) = unit_normals(ng, ns.take(), inst.flip_normals);
        SurfaceInteraction {
            p,
            ng,
            frame: Frame::from_normal_tangent(n_shading, dpdu),
            uv,
            instance: hit.instance,
            material: inst.material,
            light: inst.light,
            t: hit.t,
            dpdu,
            dpdv,
            prim: hit.prim,
            bary: [hit.b1, hit.b2],
        }
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }
    pub fn meshes(&self) -> &[Arc<TriangleMesh>] {
        &self.meshes
    }
    pub fn spheres(&self) -> &[Sphere] {
        &self.spheres
    }
    pub fn cylinders(&self) -> &[Cylinder] {
        &self.cylinders
    }
    pub fn sdf_grids(&self) -> &[SdfGrid] {
        &self.sdf_grids
    }
    pub fn curves(&self) -> &[Curves] {
        &self.curves
    }
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }
    pub fn media(&self) -> &[Medium] {
        &self.media
    }
    pub fn camera_medium(&self) -> Option<u32> {
        self.camera_medium
    }
    pub fn top_level(&self) -> &TopLevelBvh {
        &self.top
    }
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
    pub fn light_selection(&self) -> LightSelection {
        self.light_selection
    }
    pub fn bvh_split(&self) -> BvhSplit {
        self.bvh_split
    }
    /// Seconds spent building BVHs (meshes and the top level) for this world.
    pub fn bvh_build_seconds(&self) -> f64 {
        self.bvh_build_seconds
    }

    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| match i.shape {
                ShapeRef::Mesh(m) => self.meshes[m as usize].indices.len(),
                ShapeRef::Sphere(_) | ShapeRef::Cylinder(_) | ShapeRef::SdfGrid(_) | ShapeRef::Curves(_) => 0,
            })
            .sum()
    }
}

/// What a triangle's corners, vertex normals and uvs (where the mesh has them) give at the
/// barycentrics (b1, b2): the point, the face normal (not normalised, counter-clockwise
/// winding in front), the interpolated normal, the uv and dp/du, dp/dv (see
/// [`SurfaceInteraction`]).
pub(crate) struct TriangleSurface {
    pub p: Vec3,
    pub ng: Vec3,
    pub ns: Option<Vec3>,
    pub uv: [f32; 2],
    pub dpdu: Vec3,
    pub dpdv: Vec3,
}

impl TriangleSurface {
    #[inline]
    pub(crate) fn at(
        [a, b, c]: [Vec3; 3],
        normals: Option<[Vec3; 3]>,
        uvs: Option<[[f32; 2]; 3]>,
        b1: f32,
        b2: f32,
    ) -> TriangleSurface {
        let (p, b0) = barycentric_point([a, b, c], b1, b2);
        let ng = (b - a).cross(c - a);
        let ns = normals.map(|n| n[0] * b0 + n[1] * b1 + n[2] * b2);
        let (uv, dpdu, dpdv) = match uvs {
            None => ([b1, b2], b - a, c - a),
            Some([t0, t1, t2]) => {
                let uv = [t0[0] * b0 + t1[0] * b1 + t2[0] * b2, t0[1] * b0 + t1[1] * b1 + t2[1] * b2];
                let (dpdu, dpdv) = triangle_dpduv([a, b, c], [t0, t1, t2], ng);
                (uv, dpdu, dpdv)
            }
        };
        TriangleSurface { p, ng, ns, uv, dpdu, dpdv }
    }
}

/// The point at barycentrics (b1, b2) of a triangle, and the first barycentric.
#[inline(always)]
pub(crate) fn barycentric_point([a, b, c]: [Vec3; 3], b1: f32, b2: f32) -> (Vec3, f32) {
    let b0 = 1.0 - b1 - b2;
    (a * b0 + b * b1 + c * b2, b0)
}

/// The unit geometric normal and the shading normal of a hit from the shape's normal `ng`
/// (any length) and interpolated normal `ns`, both turned where the instance flips normals:
/// the shading normal is `ns` where there is one and it is not zero, else `ng`, and `ng`
/// again where it is not finite.
#[inline]
pub(crate) fn unit_normals(ng: Vec3, ns: Option<Vec3>, flip_normals: bool) -> (Vec3, Vec3) {
    let mut ng = ng.normalize();
    if flip_normals {
        ng = -ng;
    }
    let mut n_shading = match ns {
        Some(n) if n.length_squared() > 0.0 => {
            let n = n.normalize();
            if flip_normals {
                -n
            } else {
                n
            }
        }
        _ => ng,
    };
    if !n_shading.is_finite() {
        n_shading = ng;
    }
    (ng, n_shading)
}

/// Whether a hit at `t` on `(instance, prim)` comes before `best` in the order of closest
/// hits: smallest `(t, instance, prim)`.
#[inline(always)]
fn hit_before(t: f32, instance: u32, prim: u32, best: &Hit) -> bool {
    t < best.t || (t == best.t && (instance, prim) < (best.instance, best.prim))
}

/// The traversal hit of a curve: `prim` its segment's first control point, `b1` the
/// segment parameter.
fn curve_hit(h: CurveHit, instance: u32) -> Hit {
    Hit { t: h.t, instance, prim: h.point, b1: h.v, b2: 0.0 }
}

/// dp/du and dp/dv of a triangle from its uvs, as Mitsuba computes them; where the uvs are
/// degenerate (zero determinant, or a non-finite result), an arbitrary tangent basis of the
/// face normal `ng` (not normalised), as Mitsuba falls back to.
fn triangle_dpduv(p: [Vec3; 3], t: [[f32; 2]; 3], ng: Vec3) -> (Vec3, Vec3) {
    let (dp0, dp1) = (p[1] - p[0], p[2] - p[0]);
    let (du0, dv0) = (t[1][0] - t[0][0], t[1][1] - t[0][1]);
    let (du1, dv1) = (t[2][0] - t[0][0], t[2][1] - t[0][1]);
    let det = du0 * dv1 - dv0 * du1;
    if det != 0.0 {
        let inv = 1.0 / det;
        let dpdu = (dp0 * dv1 - dp1 * dv0) * inv;
        let dpdv = (dp1 * du0 - dp0 * du1) * inv;
        if dpdu.is_finite() && dpdv.is_finite() {
            return (dpdu, dpdv);
        }
    }
    let f = Frame::from_normal(ng.normalize());
    (f.s, f.t)
}

/// dp/du and dp/dv of the sphere's (u, v) = (phi / 2 pi, theta / pi) at the unit direction
/// `local` from its centre (Mitsuba's, including its choice at the poles).
fn sphere_dpduv(local: Vec3, radius: f32) -> (Vec3, Vec3) {
    use std::f32::consts::PI;
    let dpdu = Vec3 { x: -local.y, y: local.x, z: 0.0 } * (2.0 * PI * radius);
    let rd = (local.x * local.x + local.y * local.y).sqrt();
    let dpdv = if rd > 0.0 {
        Vec3 { x: local.z * local.x / rd, y: local.z * local.y / rd, z: -rd }
    } else {
        Vec3 { x: 1.0, y: 0.0, z: 0.0 }
    };
    (dpdu, dpdv * (PI * radius))
}
