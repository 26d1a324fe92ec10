//! The batch traversal API against single-ray queries, ray by ray: for random meshes and
//! batches of random rays (NaN, infinite and zero directions, NaN and infinite origins and
//! intervals, rays grazing flat surfaces in their plane, axis-aligned rays, rays aimed at
//! vertices and edges, rays starting on a surface), on every SIMD path this CPU has and every
//! acceleration structure, `intersect_batch` gives each ray exactly the hit (triangle, t and
//! barycentrics, bit for bit) that the single-ray query gives, and that hit's distance is the
//! reference binary BVH's; `occluded_batch` gives the single-ray occlusion answer. Batches of
//! 0, 1, odd and large sizes (more rays than lanes, so lanes are refilled) and empty and
//! one-leaf trees are covered, and hostile triangles (NaN, infinite) below `TriangleMesh`.
//! Packet occlusion (`occluded_packets`) and packet closest hits (`intersect_packets`) are
//! held to the same single-ray answers, with rays leaving the packet never, at the default
//! count, and always.

use glint::accel::{BuildOptions, Bvh, BvhSplit, SimdPath, TriangleHit, TriangleWideBvh, BATCH_LANES};
use glint::geometry::{MeshAccel, TriangleMesh};
use glint::math::{vec3, Ray, Vec3};
use proptest::prelude::*;

type Hit = Option<(u32, TriangleHit)>;

/// A hit as comparable bits (NaN-safe, and -0 differs from +0).
fn bits(h: &Hit) -> Option<(u32, u32, u32, u32)> {
    h.map(|(p, h)| (p, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
}

/// Random triangles plus a 7x7 height field (shared edges and vertices; flat where
/// heights repeat, for grazing rays).
fn mesh_from(points: &[(f32, f32, f32)], heights: &[f32], accel: MeshAccel) -> TriangleMesh {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for tri in points.chunks_exact(3) {
        let base = positions.len() as u32;
        positions.extend(tri.iter().map(|&(x, y, z)| vec3(x, y, z)));
        indices.push([base, base + 1, base + 2]);
    }
    if !heights.is_empty() {
        let n = 7usize;
        let base = positions.len() as u32;
        for j in 0..n {
            for i in 0..n {
                positions.push(vec3(i as f32 - 3.0, heights[(j * n + i) % heights.len()] - 3.0, j as f32 - 3.0));
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = base + (j * n + i) as u32;
                let (b, c) = (a + 1, a + n as u32);
                indices.push([a, b, c + 1]);
                indices.push([a, c + 1, c]);
            }
        }
    }
    let mut m = TriangleMesh::new(positions, None, None, indices, BvhSplit::Sah).unwrap();
    m.build_accel(BvhSplit::Sah, accel);
    m
}

/// A ray of one of many kinds, some of them untraceable on purpose.
fn ray_for(mesh: &TriangleMesh, (kind, a, b, c, d): (u8, f32, f32, f32, f32)) -> Ray {
    let origin = vec3(b * 8.0, c * 8.0, d * 8.0);
    let corner = |k: usize| {
        if mesh.indices.is_empty() {
            vec3(a, b, c)
        } else {
            mesh.vertices(((a.abs() * 1000.0) as usize) % mesh.indices.len())[k]
        }
    };
    let (p0, p1, p2) = (corner(0), corner(1), corner(2));
    let ray = match kind % 12 {
        0 => Ray::new(origin, vec3(a - 0.5, b - c, d + 0.1)),
        1 => Ray::new(origin, p0 - origin),
        2 => Ray::new(origin, p0.lerp(p1, b.abs().fract()) - origin),
        // Grazing: in the plane of a flat part of the height field.
        3 => Ray::new(vec3(origin.x, p0.y, origin.z), vec3(a, 0.0, c - 0.3)),
        4 => {
            Ray::new(origin, [vec3(1.0, 0.0, 0.0), vec3(0.0, -1.0, 0.0), vec3(0.0, 0.0, 1.0)][(kind as usize / 12) % 3])
        }
        5 => {
            let (u, v) = (b.abs().fract() * 0.5, c.abs().fract() * 0.5);
            Ray::new(p0 * (1.0 - u - v) + p1 * u + p2 * v, vec3(d, a - 0.5, c))
        }
        6 => Ray::new(origin, Vec3::ZERO),
        7 => Ray::new(origin, vec3(f32::NAN, b, c)),
        8 => Ray::new(vec3(f32::INFINITY, c, d), vec3(-1.0, 0.0, 0.0)),
        9 => Ray::new(origin, vec3(f32::INFINITY, 1.0, 0.0)),
        10 => Ray { t_min: f32::NAN, ..Ray::new(origin, p0 - origin) },
        _ => Ray {
            t_min: 0.0,
            t_max: [f32::NAN, 0.0, 2.5, -1.0][(kind as usize / 12) % 4],
            ..Ray::new(origin, p0 - origin)
        },
    };
    // Some rays get a short interval, so that culling by `t_max` is exercised.
    if kind >= 128 && ray.t_max == f32::INFINITY {
        Ray { t_max: 2.5, ..ray }
    } else {
        ray
    }
}

/// Checks both batch queries against the single-ray ones (and closest distances against the
/// reference BVH) for `rays`, on every path.
fn check_batch(mesh: &TriangleMesh, rays: &[Ray]) -> Result<(), TestCaseError> {
    for path in SimdPath::available() {
        let mut hits: Vec<Hit> = vec![Some((u32::MAX, TriangleHit { t: -1.0, b1: 0.0, b2: 0.0 })); rays.len()];
        let mut blocked = vec![true; rays.len()];
        mesh.intersect_batch_with(rays, &mut hits, path);
        // Start from `false` on half the batches, so that a query that left a slot alone
        // cannot pass by the slot's initial value.
        #[allow(clippy::manual_is_multiple_of)] // is_multiple_of needs Rust 1.87
        if rays.len() % 2 == 0 {
            blocked.fill(false);
        }
        mesh.occluded_batch_with(rays, &mut blocked, path);
        let packets: Vec<Vec<bool>> = PACKET_SPLITS
            .iter()
            .map(|&split| {
                let mut b = vec![rays.len() % 2 == 1; rays.len()];
                mesh.occluded_packets_with(rays, &mut b, path, split);
                b
            })
            .collect();
        let closest_packets: Vec<Vec<Hit>> = PACKET_SPLITS
            .iter()
            .map(|&split| {
                let mut h: Vec<Hit> = vec![Some((7, TriangleHit { t: -2.0, b1: 0.0, b2: 0.0 })); rays.len()];
                mesh.intersect_packets_with(rays, &mut h, path, split);
                h
            })
            .collect();
        for (i, ray) in rays.iter().enumerate() {
            for (b, split) in packets.iter().zip(PACKET_SPLITS) {
                prop_assert_eq!(b[i], blocked[i], "{} packets split below {}: ray {} {:?}", path, split, i, ray);
            }
            for (h, split) in closest_packets.iter().zip(PACKET_SPLITS) {
                prop_assert_eq!(
                    bits(&h[i]),
                    bits(&hits[i]),
                    "{} closest-hit packets split below {}: ray {} {:?}",
                    path,
                    split,
                    i,
                    ray
                );
            }
            let single = mesh.intersect_with(&mut ray.clone(), path);
            prop_assert_eq!(bits(&hits[i]), bits(&single), "{} ray {} of {}: {:?}", path, i, rays.len(), ray);
            let reference = mesh.intersect_reference(&mut ray.clone());
            prop_assert_eq!(
                hits[i].map(|h| h.1.t.to_bits()),
                reference.map(|h| h.1.t.to_bits()),
                "{} ray {:?}",
                path,
                ray
            );
            prop_assert_eq!(blocked[i], mesh.occluded_with(ray, path), "{} ray {} occlusion: {:?}", path, i, ray);
            prop_assert_eq!(blocked[i], mesh.occluded_reference(ray), "{} ray {:?}", path, ray);
            if !(ray.origin.is_finite() && ray.dir.is_finite()) {
                prop_assert!(hits[i].is_none() && !blocked[i], "untraceable ray {:?} hit", ray);
            }
        }
    }
    Ok(())
}

/// Where rays leave a packet: never (every node through the lanes), the renderer's count, and
/// always (the single-ray fall-back from the root).
const PACKET_SPLITS: [u32; 3] = [0, glint::accel::SINGLE_BELOW, 17];

fn ray_param() -> impl Strategy<Value = (u8, f32, f32, f32, f32)> {
    (any::<u8>(), -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn batch_answers_equal_single_ray_answers_ray_by_ray(
        points in prop::collection::vec((-4.0f32..4.0, -4.0f32..4.0, -4.0f32..4.0), 0..150),
        heights in prop::collection::vec(prop_oneof![Just(0.0f32), -1.0f32..1.0], 0..49),
        // 0, 1, fewer than the lanes, odd, and several times the lanes.
        params in prop::collection::vec(ray_param(), 0..(5 * BATCH_LANES + 3)),
    ) {
        for accel in [MeshAccel::Wide8, MeshAccel::Wide4, MeshAccel::Binary] {
            let mesh = mesh_from(&points, &heights, accel);
            let rays: Vec<Ray> = params.iter().map(|&p| ray_for(&mesh, p)).collect();
            check_batch(&mesh, &rays)?;
        }
    }

    /// Below `TriangleMesh` (which rejects them): triangles with NaN and infinite corners
    /// make NaN and infinite boxes; the batch kernels must stay in bounds and agree.
    #[test]
    fn batch_is_sound_and_agrees_on_hostile_triangles(
        tris in prop::collection::vec(prop::array::uniform3(prop::array::uniform3(prop_oneof![
            6 => -4.0f32..4.0,
            1 => prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY), Just(f32::MAX)],
        ])), 1..60),
        origins in prop::collection::vec(prop::array::uniform3(-5.0f32..5.0), 1..40),
        dirs in prop::collection::vec(prop::array::uniform3(prop_oneof![
            6 => -1.0f32..1.0,
            1 => prop_oneof![Just(0.0f32), Just(f32::NAN), Just(f32::INFINITY)],
        ]), 1..40),
    ) {
        let tris: Vec<[Vec3; 3]> = tris.iter().map(|t| t.map(|[x, y, z]| vec3(x, y, z))).collect();
        let bounds: Vec<glint::math::Aabb> = tris.iter().map(|t| glint::math::Aabb::from_points(t)).collect();
        let rays: Vec<Ray> = origins
            .iter()
            .zip(dirs.iter().cycle())
            .map(|(&[ox, oy, oz], &[dx, dy, dz])| Ray::new(vec3(ox, oy, oz), vec3(dx, dy, dz)))
            .collect();
        for opts in [BuildOptions::BINARY, BuildOptions::WIDE] {
            let bvh = Bvh::build_with(&bounds, BvhSplit::Sah, opts);
            let w4 = TriangleWideBvh::<4>::build(&bvh, |i| tris[i as usize]);
            let w8 = TriangleWideBvh::<8>::build(&bvh, |i| tris[i as usize]);
            for path in SimdPath::available() {
                let mut h4 = vec![None; rays.len()];
                let mut h8 = vec![None; rays.len()];
                let (mut b4, mut b8) = (vec![false; rays.len()], vec![false; rays.len()]);
                w4.intersect_batch(&rays, &mut h4, path);
                w8.intersect_batch(&rays, &mut h8, path);
                w4.occluded_batch(&rays, &mut b4, path);
                w8.occluded_batch(&rays, &mut b8, path);
                let (mut p4, mut p8) = (vec![true; rays.len()], vec![true; rays.len()]);
                w4.occluded_packets_split(&rays, &mut p4, path, 0);
                w8.occluded_packets_split(&rays, &mut p8, path, 0);
                prop_assert_eq!(&p4, &b4, "{} packets, wide4", path);
                prop_assert_eq!(&p8, &b8, "{} packets, wide8", path);
                for split in PACKET_SPLITS {
                    let (mut c4, mut c8) = (vec![None; rays.len()], vec![None; rays.len()]);
                    w4.intersect_packets_split(&rays, &mut c4, path, split);
                    w8.intersect_packets_split(&rays, &mut c8, path, split);
                    for i in 0..rays.len() {
                        prop_assert_eq!(bits(&c4[i]), bits(&h4[i]), "{} closest packets, wide4, split {}", path, split);
                        prop_assert_eq!(bits(&c8[i]), bits(&h8[i]), "{} closest packets, wide8, split {}", path, split);
                    }
                }
                for (i, ray) in rays.iter().enumerate() {
                    prop_assert_eq!(bits(&h4[i]), bits(&w4.intersect(&mut ray.clone(), path)), "{} {:?}", path, ray);
                    prop_assert_eq!(bits(&h8[i]), bits(&w8.intersect(&mut ray.clone(), path)), "{} {:?}", path, ray);
                    prop_assert_eq!(b4[i], w4.occluded(ray, path));
                    prop_assert_eq!(b8[i], w8.occluded(ray, path));
                    for h in [h4[i], h8[i]].into_iter().flatten() {
                        prop_assert!((h.0 as usize) < tris.len(), "hit names triangle {} of {}", h.0, tris.len());
                    }
                }
            }
        }
    }
}

/// Rays of every kind from a fixed grid of parameters.
fn grid_rays(mesh: &TriangleMesh, n: usize) -> Vec<Ray> {
    (0..n)
        .map(|i| {
            let f = |k: usize| (((i * 2654435761 + k * 40503) % 2000) as f32 / 1000.0) - 1.0;
            ray_for(mesh, ((i * 37 % 256) as u8, f(1), f(2), f(3), f(4)))
        })
        .collect()
}

#[test]
fn large_batch_refills_lanes_and_agrees() {
    let pts: Vec<(f32, f32, f32)> =
        (0..3000).map(|i| ((i % 17) as f32 * 0.3 - 2.0, (i % 7) as f32 * 0.2 - 0.5, (i % 13) as f32 * 0.1)).collect();
    for accel in [MeshAccel::Wide8, MeshAccel::Wide4] {
        let mesh = mesh_from(&pts, &[0.5, -0.2, 0.0, 0.0], accel);
        let rays = grid_rays(&mesh, 4099);
        check_batch(&mesh, &rays).unwrap();
        // Not a vacuous pass: the batch found hits and misses, and blocked rays.
        let mut hits = vec![None; rays.len()];
        mesh.intersect_batch_with(&rays, &mut hits, SimdPath::detect());
        let n_hit = hits.iter().filter(|h| h.is_some()).count();
        assert!(n_hit > 400 && n_hit < rays.len() - 400, "{n_hit} hits of {}", rays.len());
    }
}

#[test]
fn empty_and_one_leaf_trees() {
    // No triangles: every query misses, batch or not.
    let empty = mesh_from(&[], &[], MeshAccel::Wide8);
    assert!(empty.indices.is_empty());
    let rays = grid_rays(&empty, 37);
    let mut hits = vec![Some((0, TriangleHit { t: 1.0, b1: 0.0, b2: 0.0 })); rays.len()];
    let mut blocked = vec![true; rays.len()];
    for path in SimdPath::available() {
        empty.intersect_batch_with(&rays, &mut hits, path);
        empty.occluded_batch_with(&rays, &mut blocked, path);
        assert!(hits.iter().all(|h| h.is_none()) && blocked.iter().all(|&b| !b), "{path}");
        blocked.fill(true);
        empty.occluded_packets_with(&rays, &mut blocked, path, 0);
        assert!(blocked.iter().all(|&b| !b), "{path} packets");
        hits.fill(Some((0, TriangleHit { t: 1.0, b1: 0.0, b2: 0.0 })));
        empty.intersect_packets_with(&rays, &mut hits, path, 0);
        assert!(hits.iter().all(|h| h.is_none()), "{path} closest-hit packets");
    }
    // One triangle: the root is a leaf.
    let one = mesh_from(&[(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)], &[], MeshAccel::Wide8);
    let glint::geometry::WideTris::W8(w) = &one.wide else { unreachable!() };
    assert!(w.is_single_leaf());
    let toward = Ray::new(vec3(0.25, 0.25, -1.0), vec3(0.0, 0.0, 1.0));
    let mut rays = grid_rays(&one, 40);
    rays.push(toward);
    check_batch(&one, &rays).unwrap();
    let mut hits = vec![None; 1];
    one.intersect_batch_with(&[toward], &mut hits, SimdPath::detect());
    assert_eq!(hits[0].map(|h| (h.0, h.1.t)), Some((0, 1.0)));
}

#[test]
fn empty_batch_touches_nothing() {
    let mesh = mesh_from(&[], &[0.0, 0.3], MeshAccel::Wide8);
    for path in SimdPath::available() {
        mesh.intersect_batch_with(&[], &mut [], path);
        mesh.occluded_batch_with(&[], &mut [], path);
        mesh.occluded_packets_with(&[], &mut [], path, 0);
        mesh.intersect_packets_with(&[], &mut [], path, 0);
    }
}

#[test]
#[should_panic(expected = "one hit slot per ray")]
fn batch_slices_must_match() {
    let mesh = mesh_from(&[], &[0.0, 0.3], MeshAccel::Wide8);
    let rays = grid_rays(&mesh, 3);
    mesh.intersect_batch_with(&rays, &mut [None; 2], SimdPath::detect());
}
