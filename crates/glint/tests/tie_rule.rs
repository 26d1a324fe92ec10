//! The tie rule of closest hits: of hits at exactly the same `t` (a ray through a shared
//! edge or vertex, coincident triangles, coincident instances) every kernel answers with the
//! smallest `(t, primitive)`, and across a scene's instances the smallest
//! `(t, instance, primitive)`, so that which kernel ran (single ray, batch, packets, the
//! binary reference, brute force) or the order nodes were visited in does not change an
//! image. The expected answer is computed here from the triangle test alone, triangle by
//! triangle; the test also checks that the rays really produce ties (else it would prove
//! nothing).

use glint::accel::{intersect_triangle, BvhSplit, ShearedRay, SimdPath, TriangleHit};
use glint::assemble::WorldBuilder;
use glint::camera::{Camera, FovAxis};
use glint::geometry::{MeshAccel, TriangleMesh};
use glint::lights::LightSelection;
use glint::materials::{DiffuseMaterial, Material, MaterialKind, Texture};
use glint::math::{vec3, Ray, Rgb, Transform, Vec3};
use glint::world::{BatchTraversal, Hit, World};
use std::sync::Arc;

const N: usize = 9;

/// An N x N grid of unit squares at height `y`, split along alternating diagonals, plus
/// coincident copies of some of its triangles (the same corners, appended after the grid, so
/// the copies have higher numbers), some with their corners rotated.
fn grid(y: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for j in 0..=N {
        for i in 0..=N {
            positions.push(vec3(i as f32 - 4.0, y, j as f32 - 4.0));
        }
    }
    let mut indices = Vec::new();
    let w = (N + 1) as u32;
    for j in 0..N as u32 {
        for i in 0..N as u32 {
            let a = j * w + i;
            let (b, c, d) = (a + 1, a + w, a + w + 1);
            if (i + j) % 2 == 0 {
                indices.push([a, b, d]);
                indices.push([a, d, c]);
            } else {
                indices.push([a, b, c]);
                indices.push([b, d, c]);
            }
        }
    }
    let n = indices.len();
    for k in (0..n).step_by(3) {
        let [a, b, c] = indices[k];
        indices.push(if k % 2 == 0 { [a, b, c] } else { [b, c, a] });
    }
    // And a copy placed before its original in the numbering would be: reverse a block so
    // that lower numbers are not always earlier in the tree's leaves.
    indices[..n / 2].reverse();
    (positions, indices)
}

fn mesh(y: f32, accel: MeshAccel) -> TriangleMesh {
    let (p, i) = grid(y);
    let mut m = TriangleMesh::new(p, None, None, i, BvhSplit::Sah).unwrap();
    m.build_accel(BvhSplit::Sah, accel);
    m
}

/// Rays aimed exactly at every vertex, edge midpoint and square centre of the grid: straight
/// down, and from a few oblique origins.
fn rays() -> Vec<Ray> {
    let mut out = Vec::new();
    for j in 0..=2 * N {
        for i in 0..=2 * N {
            let target = vec3(i as f32 * 0.5 - 4.0, 0.0, j as f32 * 0.5 - 4.0);
            out.push(Ray::new(target + vec3(0.0, 5.0, 0.0), vec3(0.0, -1.0, 0.0)));
            for origin in [vec3(0.25, 6.0, -1.5), vec3(-7.0, 3.0, 5.0), vec3(3.0, 2.0, 2.0)] {
                out.push(Ray::new(origin, target - origin));
            }
        }
    }
    out
}

/// The smallest `(t, triangle)` among every triangle's own test, and how many triangles
/// hit at that `t`.
fn expected(m: &TriangleMesh, ray: &Ray) -> (Option<(u32, TriangleHit)>, usize) {
    let sh = ShearedRay::new(ray.dir);
    let mut best: Option<(u32, TriangleHit)> = None;
    for tri in 0..m.indices.len() {
        let [a, b, c] = m.vertices(tri);
        if let Some(h) = intersect_triangle(ray, &sh, a, b, c) {
            if best.is_none_or(|(bt, bh)| h.t < bh.t || (h.t == bh.t && (tri as u32) < bt)) {
                best = Some((tri as u32, h));
            }
        }
    }
    let ties = match best {
        Some((_, bh)) => (0..m.indices.len())
            .filter(|&tri| {
                let [a, b, c] = m.vertices(tri);
                intersect_triangle(ray, &sh, a, b, c).is_some_and(|h| h.t == bh.t)
            })
            .count(),
        None => 0,
    };
    (best, ties)
}

fn bits(h: &Option<(u32, TriangleHit)>) -> Option<(u32, u32, u32, u32)> {
    h.map(|(p, h)| (p, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
}

#[test]
fn every_mesh_kernel_takes_the_smallest_t_and_triangle() {
    let rays = rays();
    let mut tied = 0;
    for accel in [MeshAccel::Binary, MeshAccel::Wide4, MeshAccel::Wide8] {
        let m = mesh(0.0, accel);
        let want: Vec<_> = rays.iter().map(|r| expected(&m, r)).collect();
        tied = want.iter().filter(|(_, ties)| *ties >= 2).count();
        for (ray, (w, _)) in rays.iter().zip(&want) {
            assert_eq!(bits(&m.intersect_brute_force(ray)), bits(w), "brute force, ray {ray:?}");
            let mut r = *ray;
            assert_eq!(bits(&m.intersect_reference(&mut r)), bits(w), "binary reference, ray {ray:?}");
            assert_eq!(r.t_max.to_bits(), w.map_or(ray.t_max, |(_, h)| h.t).to_bits());
        }
        for path in SimdPath::available() {
            for (ray, (w, _)) in rays.iter().zip(&want) {
                let mut r = *ray;
                let got = m.intersect_with(&mut r, path);
                assert_eq!(bits(&got), bits(w), "{accel:?} {path:?} single ray {ray:?}");
                assert_eq!(
                    r.t_max.to_bits(),
                    w.map_or(ray.t_max, |(_, h)| h.t).to_bits(),
                    "t_max shortened to the hit"
                );
            }
            let mut hits = vec![None; rays.len()];
            m.intersect_batch_with(&rays, &mut hits, path);
            for ((ray, (w, _)), h) in rays.iter().zip(&want).zip(&hits) {
                assert_eq!(bits(h), bits(w), "{accel:?} {path:?} batch, ray {ray:?}");
            }
            for split in [0, glint::accel::SINGLE_BELOW, 17] {
                let mut hits = vec![None; rays.len()];
                m.intersect_packets_with(&rays, &mut hits, path, split);
                for ((ray, (w, _)), h) in rays.iter().zip(&want).zip(&hits) {
                    assert_eq!(bits(h), bits(w), "{accel:?} {path:?} packets split {split}, ray {ray:?}");
                }
            }
        }
    }
    // Vertical rays hit the flat grid at exactly t = 5 from every triangle around the target.
    assert!(tied > rays.len() / 8, "only {tied} of {} rays had ties: the test proves little", rays.len());
}

fn world() -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let m = b.add_material(Material::new(
        "m",
        MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.5)) }),
        true,
    ));
    let at_zero = Arc::new(mesh(0.0, MeshAccel::Wide8));
    let below = Arc::new(mesh(-1.0, MeshAccel::Wide8));
    let up = Transform::translate(vec3(0.0, 1.0, 0.0));
    // 0 and 3: traced through their transform (the top-level tree); 1 and 2: in the flat
    // BVH. All four are the same surface.
    b.add_mesh_instance(&below, &up, true, m, None, false).unwrap();
    b.add_mesh_instance(&at_zero, &Transform::IDENTITY, false, m, None, false).unwrap();
    b.add_mesh_instance(&at_zero, &Transform::IDENTITY, false, m, None, false).unwrap();
    b.add_mesh_instance(&below, &up, true, m, None, false).unwrap();
    let cam = Camera::new(Transform::IDENTITY, 4, 4, 40.0, FovAxis::Y);
    b.finish(cam, LightSelection::Power).unwrap()
}

fn hit_bits(h: &Option<Hit>) -> Option<(u32, u32, u32, u32, u32)> {
    h.map(|h| (h.instance, h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
}

#[test]
fn coincident_instances_give_the_smallest_t_instance_and_triangle() {
    let scene = world();
    let reference = mesh(0.0, MeshAccel::Wide8);
    let rays: Vec<Ray> = rays().into_iter().filter(|r| r.dir == vec3(0.0, -1.0, 0.0)).collect();
    let mut first_instance = 0;
    for ray in &rays {
        let want = scene.intersect_brute_force(ray);
        let got = scene.intersect(ray);
        assert_eq!(hit_bits(&got), hit_bits(&want), "ray {ray:?}");
        // Straight down, every instance hits at t = 5: the first instance wins, with the
        // smallest triangle of the mesh's own rule.
        if let Some(h) = got {
            assert_eq!(h.t, 5.0);
            assert_eq!(h.instance, 0, "ray {ray:?}");
            assert_eq!(Some(h.prim), expected(&reference, ray).0.map(|(p, _)| p), "ray {ray:?}");
            first_instance += 1;
        }
    }
    assert!(first_instance > rays.len() / 2);
    let all = self::rays();
    for traversal in [BatchTraversal::OneByOne, BatchTraversal::Interleaved, BatchTraversal::Packets] {
        let mut hits = vec![None; all.len()];
        scene.intersect_many(&all, &mut hits, traversal);
        for (ray, h) in all.iter().zip(&hits) {
            assert_eq!(hit_bits(h), hit_bits(&scene.intersect(ray)), "{traversal:?} ray {ray:?}");
            assert_eq!(hit_bits(h), hit_bits(&scene.intersect_brute_force(ray)), "{traversal:?} ray {ray:?}");
        }
    }
}
