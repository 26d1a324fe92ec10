//! The BVH must return exactly what testing every primitive returns: the same closest-hit
//! distance (bit for bit: both use the same watertight triangle test) and the same occlusion
//! answer, for random meshes and rays, including rays aimed exactly at shared edges and
//! vertices and rays that start on a surface. Both split strategies, and the two-level scene
//! with transformed instances, are checked.

use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::camera::{Camera, FovAxis};
use glint::geometry::TriangleMesh;
use glint::lights::LightSelection;
use glint::materials::{DiffuseMaterial, Material, MaterialKind, Texture};
use glint::math::{vec3, Ray, Rgb, Transform, Vec3};
use glint::world::World;
use proptest::prelude::*;
use std::sync::Arc;

/// A mesh of random triangles plus a height-field grid (many shared edges and vertices).
fn mesh_from(seed_points: &[(f32, f32, f32)], grid_heights: &[f32], split: BvhSplit) -> TriangleMesh {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for tri in seed_points.chunks_exact(3) {
        let base = positions.len() as u32;
        for &(x, y, z) in tri {
            positions.push(vec3(x, y, z));
        }
        indices.push([base, base + 1, base + 2]);
    }
    let n = 6usize;
    let base = positions.len() as u32;
    for j in 0..n {
        for i in 0..n {
            let h = grid_heights[(j * n + i) % grid_heights.len()];
            positions.push(vec3(i as f32 - 2.5, h - 3.0, j as f32 - 2.5));
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = base + (j * n + i) as u32;
            let b = a + 1;
            let c = a + n as u32;
            let d = c + 1;
            indices.push([a, b, d]);
            indices.push([a, d, c]);
        }
    }
    TriangleMesh::new(positions, None, None, indices, split).unwrap()
}

/// Rays of three kinds: random, aimed exactly at a vertex or edge point, starting on a triangle.
fn rays_for(mesh: &TriangleMesh, params: &[(u8, f32, f32, f32, f32)]) -> Vec<Ray> {
    let mut rays = Vec::new();
    for &(kind, a, b, c, d) in params {
        let tri = ((a.abs() * 1000.0) as usize) % mesh.indices.len();
        let [p0, p1, p2] = mesh.vertices(tri);
        let origin = vec3(b * 8.0, c * 8.0, d * 8.0);
        let ray = match kind % 4 {
            0 => Ray::new(origin, vec3(a - 0.5, b - c, d + 0.1)),
            // Exactly at a vertex.
            1 => Ray::new(origin, p0 - origin),
            // Exactly at a point on an edge.
            2 => {
                let t = b.abs().fract();
                Ray::new(origin, p0.lerp(p1, t) - origin)
            }
            // Starting on the surface of a triangle, leaving in a random direction.
            _ => {
                let (u, v) = (b.abs().fract() * 0.5, c.abs().fract() * 0.5);
                let on = p0 * (1.0 - u - v) + p1 * u + p2 * v;
                Ray::new(on, vec3(d, a - 0.5, c))
            }
        };
        if ray.dir.length_squared() > 1e-12 {
            rays.push(ray);
        }
    }
    rays
}

fn coord() -> impl Strategy<Value = f32> {
    -4.0f32..4.0
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn mesh_bvh_matches_brute_force(
        points in prop::collection::vec((coord(), coord(), coord()), 3..300),
        heights in prop::collection::vec(-1.0f32..1.0, 36),
        ray_params in prop::collection::vec((any::<u8>(), -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), 64),
    ) {
        for split in [BvhSplit::Sah, BvhSplit::Median] {
            let mesh = mesh_from(&points, &heights, split);
            for ray in rays_for(&mesh, &ray_params) {
                let reference = mesh.intersect_brute_force(&ray);
                let mut r = ray;
                let got = mesh.intersect(&mut r);
                prop_assert_eq!(got.map(|h| h.1.t), reference.map(|h| h.1.t), "split {:?} ray {:?}", split, ray);
                prop_assert_eq!(mesh.occluded(&ray), reference.is_some(), "split {:?} ray {:?}", split, ray);
                // Shadow rays of limited length.
                let seg = Ray { t_max: 3.0, ..ray };
                let reference_seg = mesh.intersect_brute_force(&seg);
                prop_assert_eq!(mesh.occluded(&seg), reference_seg.is_some());
            }
        }
    }

    #[test]
    fn two_level_scene_matches_brute_force(
        points in prop::collection::vec((coord(), coord(), coord()), 3..90),
        heights in prop::collection::vec(-1.0f32..1.0, 36),
        placements in prop::collection::vec((coord(), coord(), coord(), 0.0f32..360.0, 0.3f32..2.0), 1..6),
        spheres in prop::collection::vec((coord(), coord(), coord(), 0.1f32..2.0), 0..4),
        ray_params in prop::collection::vec((any::<u8>(), -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), 48),
    ) {
        let mesh = Arc::new(mesh_from(&points, &heights, BvhSplit::Sah));
        let mut b = WorldBuilder::new(BvhSplit::Sah);
        let m = b.add_material(Material::new("m", MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.5)) }), true));
        for (i, &(x, y, z, angle, s)) in placements.iter().enumerate() {
            let t = Transform::translate(vec3(x, y, z))
                .then_after(&Transform::rotate(vec3(0.3, 1.0, 0.2), angle))
                .then_after(&Transform::scale(Vec3::splat(s)).unwrap());
            // Alternate shared instances (traced through the transform) and baked copies.
            b.add_mesh_instance(&mesh, &t, i % 2 == 0, m, None, false).unwrap();
        }
        for &(x, y, z, r) in &spheres {
            b.add_sphere(vec3(x, y, z), r, &Transform::IDENTITY, m, None, false).unwrap();
        }
        let cam = Camera::new(Transform::IDENTITY, 4, 4, 40.0, FovAxis::Y);
        let scene: World = b.finish(cam, LightSelection::Power).unwrap();
        for ray in rays_for(&mesh, &ray_params) {
            let reference = scene.intersect_brute_force(&ray);
            let got = scene.intersect(&ray);
            prop_assert_eq!(got.map(|h| h.t), reference.map(|h| h.t), "ray {:?}", ray);
            prop_assert_eq!(scene.occluded(&ray), reference.is_some(), "ray {:?}", ray);
        }
    }
}

#[test]
fn rays_through_every_grid_vertex_never_slip_through() {
    // Any ray aimed at an interior vertex of a grid must hit it (at a boundary vertex the
    // rounding of the aim may legitimately miss the mesh).
    let mesh = mesh_from(&[], &[0.0; 36], BvhSplit::Sah);
    for v in mesh.positions.iter().filter(|v| v.x.abs() < 2.0 && v.z.abs() < 2.0) {
        for origin in [vec3(0.1, 10.0, 0.2), vec3(-7.0, 3.0, 5.0), vec3(3.3, 1.0, -9.0)] {
            let mut r = Ray::new(origin, *v - origin);
            assert!(mesh.intersect(&mut r).is_some(), "slipped through vertex {v:?} from {origin:?}");
        }
    }
}
