//! The wide BVH against the reference: for random meshes and rays (including rays aimed
//! exactly at vertices and edges, rays grazing flat surfaces in their plane, and rays that
//! start on a surface), every SIMD path this CPU has, at both widths, returns the same
//! closest-hit distance as the binary BVH and as testing every triangle, the same occlusion
//! answer, and the same hit (triangle and barycentrics) as every other path.

use glint::accel::{intersect_triangle, BvhSplit, ShearedRay, SimdPath};
use glint::geometry::{MeshAccel, TriangleMesh};
use glint::math::{vec3, Ray};
use proptest::prelude::*;

fn mesh_from(points: &[(f32, f32, f32)], heights: &[f32], accel: MeshAccel) -> TriangleMesh {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for tri in points.chunks_exact(3) {
        let base = positions.len() as u32;
        positions.extend(tri.iter().map(|&(x, y, z)| vec3(x, y, z)));
        indices.push([base, base + 1, base + 2]);
    }
    // A height field: many shared edges and vertices; flat where heights repeat.
    let n = 7usize;
    let base = positions.len() as u32;
    for j in 0..n {
        for i in 0..n {
            let h = heights[(j * n + i) % heights.len()];
            positions.push(vec3(i as f32 - 3.0, h - 3.0, j as f32 - 3.0));
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
    let mut m = TriangleMesh::new(positions, None, None, indices, BvhSplit::Sah).unwrap();
    m.build_accel(BvhSplit::Sah, accel);
    m
}

fn rays_for(mesh: &TriangleMesh, params: &[(u8, f32, f32, f32, f32)]) -> Vec<Ray> {
    let mut rays = Vec::new();
    for &(kind, a, b, c, d) in params {
        let tri = ((a.abs() * 1000.0) as usize) % mesh.indices.len();
        let [p0, p1, p2] = mesh.vertices(tri);
        let origin = vec3(b * 8.0, c * 8.0, d * 8.0);
        let ray = match kind % 6 {
            0 => Ray::new(origin, vec3(a - 0.5, b - c, d + 0.1)),
            1 => Ray::new(origin, p0 - origin),
            2 => Ray::new(origin, p0.lerp(p1, b.abs().fract()) - origin),
            // Grazing: in the plane y = p0.y, along the surface of a flat grid.
            3 => Ray::new(vec3(origin.x, p0.y, origin.z), vec3(a, 0.0, c - 0.3)),
            // Axis-aligned (zero direction components: infinite slab reciprocals).
            4 => Ray::new(
                origin,
                [vec3(1.0, 0.0, 0.0), vec3(0.0, -1.0, 0.0), vec3(0.0, 0.0, 1.0)][(kind as usize / 6) % 3],
            ),
            _ => {
                let (u, v) = (b.abs().fract() * 0.5, c.abs().fract() * 0.5);
                Ray::new(p0 * (1.0 - u - v) + p1 * u + p2 * v, vec3(d, a - 0.5, c))
            }
        };
        if ray.dir.length_squared() > 1e-12 {
            rays.push(ray);
            rays.push(Ray { t_max: 2.5, ..ray });
        }
    }
    rays
}

fn coord() -> impl Strategy<Value = f32> {
    -4.0f32..4.0
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn wide_bvh_matches_reference_on_every_path(
        points in prop::collection::vec((coord(), coord(), coord()), 3..240),
        heights in prop::collection::vec(prop_oneof![Just(0.0f32), -1.0f32..1.0], 1..49),
        ray_params in prop::collection::vec((any::<u8>(), -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), 48),
    ) {
        for accel in [MeshAccel::Wide4, MeshAccel::Wide8] {
            let mesh = mesh_from(&points, &heights, accel);
            for ray in rays_for(&mesh, &ray_params) {
                let brute = mesh.intersect_brute_force(&ray);
                let reference = mesh.intersect_reference(&mut ray.clone());
                prop_assert_eq!(reference.map(|h| h.1.t), brute.map(|h| h.1.t), "reference BVH, ray {:?}", ray);
                let mut first = None;
                for path in SimdPath::available() {
                    let mut r = ray;
                    let got = mesh.intersect_with(&mut r, path);
                    prop_assert_eq!(got.map(|h| h.1.t), brute.map(|h| h.1.t), "{:?} {} ray {:?}", accel, path, ray);
                    prop_assert_eq!(mesh.occluded_with(&ray, path), brute.is_some(), "{:?} {} ray {:?}", accel, path, ray);
                    // The triangle reported is one the ray meets at that distance, with those
                    // barycentrics (blocks tested in pairs must map lanes back to triangles).
                    if let Some((prim, hit)) = got {
                        let [p0, p1, p2] = mesh.vertices(prim as usize);
                        let alone = intersect_triangle(&ray, &ShearedRay::new(ray.dir), p0, p1, p2);
                        prop_assert_eq!(alone, Some(hit), "{:?} {} triangle {}, ray {:?}", accel, path, prim, ray);
                    }
                    // Identical hits (triangle, t, barycentrics) whatever the path.
                    match first {
                        None => first = Some(got),
                        Some(f) => prop_assert_eq!(got, f, "{:?} {} differs from the first path", accel, path),
                    }
                }
            }
        }
    }
}

#[test]
fn every_triangle_is_in_exactly_one_block_lane() {
    for accel in [MeshAccel::Wide4, MeshAccel::Wide8] {
        let pts: Vec<(f32, f32, f32)> =
            (0..3000).map(|i| ((i % 17) as f32 * 0.3, (i % 7) as f32 * 0.2, (i % 13) as f32 * 0.1)).collect();
        let mesh = mesh_from(&pts, &[0.5, -0.2], accel);
        let blocks = match &mesh.wide {
            glint::geometry::WideTris::W4(w) => w.blocks().to_vec(),
            glint::geometry::WideTris::W8(w) => w.blocks().to_vec(),
            glint::geometry::WideTris::None => unreachable!(),
        };
        // Unused lanes repeat the block's first triangle.
        let mut seen: Vec<u32> = blocks
            .iter()
            .flat_map(|b| {
                let used = 1 + b.prim[1..].iter().position(|&p| p == b.prim[0]).unwrap_or(3);
                b.prim[..used].to_vec()
            })
            .collect();
        seen.sort();
        assert_eq!(seen, (0..mesh.indices.len() as u32).collect::<Vec<_>>());
    }
}
