//! What the camera ray meets first, for the AOV layers: albedo, normal, depth and position
//! of the first hit, and what its closest-hit query cost in the reference BVHs. Traced
//! separately from `li` (one more ray per sample, only when layers are asked for), so the
//! radiance path and its random numbers are the same with or without layers.

use super::shading;
use crate::accel::{intersect_triangle, ShearedRay, TraversalVisits};
use crate::math::{Ray, Rgb, Vec3};
use crate::world::{ShapeRef, World};

/// The camera ray's first hit; all zero when the ray escapes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstHit {
    /// The material's reflectance there (see [`crate::materials::Material::albedo`]).
    pub albedo: Rgb,
    /// Shading normal, world space, turned towards the viewer where the material is
    /// two-sided (as shading sees it).
    pub normal: Vec3,
    /// Distance along the ray (camera rays are unit length, so this is in scene units).
    pub depth: f32,
    pub position: Vec3,
}

impl FirstHit {
    pub const NONE: FirstHit = FirstHit { albedo: Rgb::BLACK, normal: Vec3::ZERO, depth: 0.0, position: Vec3::ZERO };
}

/// The first hit of `ray` (a camera ray).
pub fn first_hit(scene: &World, ray: &Ray) -> FirstHit {
    let Some(hit) = scene.intersect(ray) else {
        return FirstHit::NONE;
    };
    let si = scene.interaction(ray, &hit);
    let (_, frame) = shading(scene, &si, -ray.dir);
    FirstHit {
        albedo: scene.materials[si.material as usize].albedo(si.uv),
        normal: frame.n,
        depth: hit.t,
        position: si.p,
    }
}

/// Nodes entered plus primitives tested by a closest-hit query for `ray`, counted in the
/// binary reference BVHs (the top level over instances and each mesh's own tree; meshes
/// without a transform, which the fast path merges into one tree, are each traced in
/// their own). A cost heat map, not a measure of the SIMD kernels.
pub fn closest_hit_cost(scene: &World, ray: &Ray) -> u64 {
    let mut r = *ray;
    let mut visits = TraversalVisits::default();
    // The same split as World::finish: untransformed meshes are flattened, the rest are
    // the top-level tree's primitives, in instance order.
    let is_flat = |i: &crate::world::Instance| matches!(i.shape, ShapeRef::Mesh(_)) && i.to_world.is_none();
    let rest: Vec<u32> =
        (0..scene.instances.len() as u32).filter(|&i| !is_flat(&scene.instances[i as usize])).collect();
    for inst in scene.instances.iter().filter(|i| is_flat(i)) {
        if let ShapeRef::Mesh(m) = inst.shape {
            mesh_counting(&scene.meshes[m as usize], &mut r, &mut visits);
        }
    }
    let top = &scene.top.binary;
    // Visits inside instances, kept apart from the top level's while it borrows its own.
    let mut inner = TraversalVisits::default();
    if top.prim_indices.len() == rest.len() {
        top.traverse_counting(&mut r, &mut visits, |p, r| {
            let inst = &scene.instances[rest[p as usize] as usize];
            match inst.shape {
                ShapeRef::Mesh(m) => {
                    let mut local = match &inst.to_world {
                        None => *r,
                        Some(t) => Ray { origin: t.inv_point(r.origin), dir: t.inv_vector(r.dir), ..*r },
                    };
                    let hit = mesh_counting(&scene.meshes[m as usize], &mut local, &mut inner);
                    if hit {
                        r.t_max = local.t_max;
                    }
                    hit
                }
                // The top level counted this test as its primitive.
                ShapeRef::Sphere(s) => match scene.spheres[s as usize].intersect(r) {
                    Some(t) => {
                        r.t_max = t;
                        true
                    }
                    None => false,
                },
                ShapeRef::Cylinder(c) => match scene.cylinders[c as usize].intersect(r) {
                    Some(t) => {
                        r.t_max = t;
                        true
                    }
                    None => false,
                },
                ShapeRef::SdfGrid(g) => match scene.sdf_grids[g as usize].intersect(r) {
                    Some((t, _)) => {
                        r.t_max = t;
                        true
                    }
                    None => false,
                },
                ShapeRef::Curves(c) => match scene.curves[c as usize].intersect(r) {
                    Some(h) => {
                        r.t_max = h.t;
                        true
                    }
                    None => false,
                },
            }
        });
    }
    visits.nodes + visits.primitives + inner.nodes + inner.primitives
}

/// Closest hit in one mesh's binary BVH, counting; shortens `ray.t_max` on a hit.
fn mesh_counting(mesh: &crate::geometry::TriangleMesh, ray: &mut Ray, visits: &mut TraversalVisits) -> bool {
    let sh = ShearedRay::new(ray.dir);
    mesh.bvh.traverse_counting(ray, visits, |tri, r| {
        let [a, b, c] = mesh.vertices(tri as usize);
        match intersect_triangle(r, &sh, a, b, c) {
            Some(h) => {
                r.t_max = h.t;
                true
            }
            None => false,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::BvhSplit;
    use crate::assemble::WorldBuilder;
    use crate::camera::{Camera, FovAxis};
    use crate::geometry::quad_mesh;
    use crate::lights::LightSelection;
    use crate::materials::{DiffuseMaterial, Material, MaterialKind, Texture};
    use crate::math::{vec3, Transform};
    use std::sync::Arc;

    /// `n` quads facing +z at z = -1, -2, ... (never the identity, which would not be instanced), added farthest first; instanced (kept
    /// with their transform) they go in the top-level tree instead of the flat one.
    fn wall_stack(n: usize, transformed: bool) -> World {
        let mut b = WorldBuilder::new(BvhSplit::Sah);
        let m = b.add_material(Material::new(
            "grey",
            MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.5)) }),
            true,
        ));
        for k in 0..n {
            let z = -((n - k) as f32);
            let p = [vec3(-1.0, -1.0, 0.0), vec3(1.0, -1.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(-1.0, 1.0, 0.0)];
            let xf = Transform::translate(vec3(0.0, 0.0, z));
            b.add_mesh_instance(&Arc::new(quad_mesh(p, BvhSplit::Sah)), &xf, transformed, m, None, false).unwrap();
        }
        let to_world = Transform::look_at(vec3(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y).unwrap();
        b.finish(Camera::new(to_world, 4, 4, 30.0, FovAxis::Y), LightSelection::Power).unwrap()
    }

    #[test]
    fn bvh_cost_counts_what_the_ray_meets() {
        let towards = Ray::new(vec3(0.1, 0.2, 5.0), vec3(0.0, 0.0, -1.0));
        let away = Ray::new(vec3(0.1, 0.2, 5.0), vec3(0.0, 0.0, 1.0));
        for transformed in [false, true] {
            let one = wall_stack(1, transformed);
            let five = wall_stack(5, transformed);
            assert_eq!(closest_hit_cost(&one, &away), 0, "a ray missing every box enters no node");
            let (c1, c5) = (closest_hit_cost(&one, &towards), closest_hit_cost(&five, &towards));
            if transformed {
                // The top-level root, the instance, the mesh's root and a triangle.
                assert!(c1 >= 4, "{c1}");
                assert!(c5 >= c1, "one wall {c1}, five walls {c5}");
            } else {
                // Flat meshes are traced one after another in instance order, here farthest
                // first, so each wall costs at least its root and a triangle.
                assert!(c1 >= 2, "{c1}");
                assert!(c5 >= c1 + 8, "one wall {c1}, five walls {c5}");
            }
            let hit = first_hit(&five, &towards);
            assert!((hit.depth - 6.0).abs() < 1e-5, "depth {}", hit.depth);
            assert!((hit.normal - Vec3::Z).length() < 1e-6, "normal {:?}", hit.normal);
        }
    }
}
