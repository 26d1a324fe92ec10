//! The acceleration structures are memory-safe for every float input: triangles, boxes and
//! rays with NaN, ±inf, values that overflow f32 (1e39), huge and tiny values, degenerate
//! triangles. Each case builds the binary BVH and the wide BVHs of both widths and traces
//! on every SIMD path this CPU has; a memory error would crash the test binary, a bad
//! reference would panic. Where everything is finite and of moderate size, the fast kernels
//! must also agree with testing every triangle.
//!
//! These go below `TriangleMesh`, which rejects non-finite vertices: accel must be sound on
//! its own.

use glint::accel::{
    intersect_triangle, BuildOptions, Bvh, BvhSplit, ShearedRay, SimdPath, TopLevelBvh, TriangleWideBvh, MAX_DEPTH,
};
use glint::math::{vec3, Aabb, Ray, Vec3};
use proptest::prelude::*;

/// 1e39 is finite as f64 but infinite as f32: what a scene value of 1e39 becomes.
const OVERFLOWED: f32 = 1e39f64 as f32;

/// Coordinates: mostly ordinary, sometimes hostile.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        8 => -4.0f32..4.0,
        1 => prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(f32::NEG_INFINITY),
            Just(OVERFLOWED),
            Just(-OVERFLOWED),
            Just(f32::MAX),
            Just(-3e38f32),
            Just(1e30f32),
            Just(1e-40f32),
            Just(-1e-45f32),
            Just(0.0f32),
            Just(-0.0f32),
        ],
    ]
}

fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| vec3(x, y, z))
}

/// Triangles, some degenerate (a repeated corner, or all three equal).
fn triangles() -> impl Strategy<Value = Vec<[Vec3; 3]>> {
    prop::collection::vec((point(), point(), point(), 0u8..8), 1..70).prop_map(|v| {
        v.into_iter()
            .map(|(a, b, c, kind)| match kind {
                0 => [a, a, b],
                1 => [a, a, a],
                _ => [a, b, c],
            })
            .collect()
    })
}

fn ray() -> impl Strategy<Value = Ray> {
    let t = prop_oneof![
        4 => Just((0.0f32, f32::INFINITY)),
        1 => (coord(), coord()),
    ];
    (point(), point(), t).prop_map(|(origin, dir, (t_min, t_max))| Ray { origin, dir, t_min, t_max })
}

fn is_moderate(v: Vec3) -> bool {
    v.is_finite() && v.abs().max_component() < 1e6
}

fn tri_bounds(tris: &[[Vec3; 3]]) -> Vec<Aabb> {
    tris.iter().map(|t| Aabb::from_points(t)).collect()
}

/// The closest hit distance by testing every triangle.
fn brute_force(tris: &[[Vec3; 3]], ray: &Ray) -> Option<f32> {
    let sh = ShearedRay::new(ray.dir);
    let mut r = *ray;
    let mut best = None;
    for t in tris {
        if let Some(h) = intersect_triangle(&r, &sh, t[0], t[1], t[2]) {
            r.t_max = h.t;
            best = Some(h.t);
        }
    }
    best
}

/// One structure's answer for a ray: the closest hit's distance, and whether it is occluded.
type Answer = (Option<f32>, bool);

/// Traces `ray` through every structure on every path; checks every reported triangle is
/// real, and returns the wide trees' closest distances and occlusion answers.
fn trace_everything(tris: &[[Vec3; 3]], rays: &[Ray]) -> Vec<(Ray, Vec<Answer>)> {
    let bounds = tri_bounds(tris);
    let verts = |i: u32| tris[i as usize];
    let mut out = Vec::new();
    let mut trees = Vec::new();
    for split in [BvhSplit::Sah, BvhSplit::Median] {
        for opts in [BuildOptions::BINARY, BuildOptions::WIDE] {
            let bvh = Bvh::build_with(&bounds, split, opts);
            assert!(bvh.stats().max_depth <= MAX_DEPTH);
            trees.push((TriangleWideBvh::<4>::build(&bvh, verts), TriangleWideBvh::<8>::build(&bvh, verts), bvh));
        }
    }
    for ray in rays {
        let mut answers = Vec::new();
        for (w4, w8, bvh) in &trees {
            // The binary reference: safe code, but it must not panic either.
            let sh = ShearedRay::new(ray.dir);
            let mut r = *ray;
            bvh.traverse(&mut r, |p, r| {
                match intersect_triangle(r, &sh, tris[p as usize][0], tris[p as usize][1], tris[p as usize][2]) {
                    Some(h) => {
                        r.t_max = h.t;
                        true
                    }
                    None => false,
                }
            });
            bvh.occluded(ray, |p, r| {
                intersect_triangle(r, &sh, tris[p as usize][0], tris[p as usize][1], tris[p as usize][2]).is_some()
            });
            for path in SimdPath::available() {
                let (mut r4, mut r8) = (*ray, *ray);
                let h4 = w4.intersect(&mut r4, path);
                let h8 = w8.intersect(&mut r8, path);
                for h in [h4, h8].into_iter().flatten() {
                    assert!((h.0 as usize) < tris.len(), "hit names triangle {} of {}", h.0, tris.len());
                }
                answers.push((h4.map(|h| h.1.t), w4.occluded(ray, path)));
                answers.push((h8.map(|h| h.1.t), w8.occluded(ray, path)));
            }
        }
        out.push((*ray, answers));
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn hostile_triangles_and_rays_never_crash_and_finite_ones_agree_with_brute_force(
        tris in triangles(),
        rays in prop::collection::vec(ray(), 1..12),
    ) {
        let all_moderate = tris.iter().flatten().all(|&p| is_moderate(p));
        for (ray, answers) in trace_everything(&tris, &rays) {
            let ray_moderate = is_moderate(ray.origin) && is_moderate(ray.dir)
                && ray.t_min == 0.0 && ray.t_max == f32::INFINITY && ray.dir.length_squared() > 1e-12;
            if all_moderate && ray_moderate {
                let want = brute_force(&tris, &ray);
                for &(t, occluded) in &answers {
                    prop_assert_eq!(t, want, "closest hit of {:?}", ray);
                    prop_assert_eq!(occluded, want.is_some(), "occlusion of {:?}", ray);
                }
            }
            // A ray that cannot be traced hits nothing, on every structure and path.
            if !(ray.origin.is_finite() && ray.dir.is_finite()) {
                for &(t, occluded) in &answers {
                    prop_assert!(t.is_none() && !occluded, "untraceable ray {:?} hit", ray);
                }
            }
        }
    }

    /// The scene's top level with instance boxes of every kind: the leaf closure is only
    /// ever handed real instance numbers.
    #[test]
    fn top_level_only_reports_real_instances(
        corners in prop::collection::vec((point(), point()), 1..40),
        rays in prop::collection::vec(ray(), 1..12),
    ) {
        let boxes: Vec<Aabb> = corners.iter().map(|&(a, b)| Aabb { min: a.min(b), max: a.max(b) }).collect();
        let n = boxes.len() as u32;
        let top = TopLevelBvh::build(&boxes, BvhSplit::Sah);
        for ray in &rays {
            let mut r = *ray;
            top.traverse(&mut r, |i, _| {
                assert!(i < n, "instance {i} of {n}");
                false
            });
            top.occluded(ray, |i, _| {
                assert!(i < n, "instance {i} of {n}");
                false
            });
        }
    }
}

/// A few triangles leave most child slots of the wide root empty.
fn small_mesh() -> Vec<[Vec3; 3]> {
    (0..5)
        .map(|i| {
            let x = i as f32 * 2.0;
            [vec3(x, 0.0, 0.0), vec3(x + 1.0, 0.0, 0.0), vec3(x, 1.0, 0.0)]
        })
        .collect()
}

/// The crashes from the issue: a NaN direction, an infinite origin and a direction with an
/// infinite component once made empty child slots look hit (an out-of-bounds read in the
/// SIMD shadow-ray traversal, or "range start index 134217727 out of range" in safe code).
#[test]
fn untraceable_rays_from_the_issue_hit_nothing() {
    let tris = small_mesh();
    let rays = [
        Ray::new(vec3(0.5, 0.25, -1.0), vec3(f32::NAN, f32::NAN, f32::NAN)),
        Ray::new(vec3(0.5, 0.25, -1.0), vec3(0.0, f32::NAN, 1.0)),
        Ray::new(vec3(f32::INFINITY, 0.25, -1.0), vec3(0.0, 0.0, 1.0)),
        Ray::new(vec3(f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY), vec3(1.0, -1.0, 1.0)),
        Ray::new(vec3(0.5, 0.25, -1.0), vec3(f32::INFINITY, f32::INFINITY, f32::INFINITY)),
        Ray::new(vec3(0.5, 0.25, -1.0), vec3(0.0, OVERFLOWED, 1.0)),
    ];
    for (ray, answers) in trace_everything(&tris, &rays) {
        for (t, occluded) in answers {
            assert!(t.is_none() && !occluded, "{ray:?}");
        }
    }
    // The same mesh still works for an ordinary ray.
    let ok = Ray::new(vec3(0.25, 0.25, -1.0), vec3(0.0, 0.0, 1.0));
    for (_, answers) in trace_everything(&tris, &[ok]) {
        for (t, occluded) in answers {
            assert_eq!(t, Some(1.0));
            assert!(occluded);
        }
    }
}

/// A triangle at infinity (a vertex at 1e39 as f32) and one with a NaN vertex among ordinary
/// ones: they are never hit, and do not hide the ordinary triangles.
#[test]
fn triangles_at_infinity_and_nan_are_never_hit() {
    let mut tris = small_mesh();
    tris.push([vec3(OVERFLOWED, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0)]);
    tris.push([vec3(f32::NAN, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0)]);
    tris.push([vec3(-OVERFLOWED, -OVERFLOWED, 0.0), vec3(OVERFLOWED, -OVERFLOWED, 0.0), vec3(0.0, OVERFLOWED, 0.0)]);
    let rays = [
        Ray::new(vec3(0.25, 0.25, -1.0), vec3(0.0, 0.0, 1.0)),
        Ray::new(vec3(4.25, 0.25, -1.0), vec3(0.0, 0.0, 1.0)),
        Ray::new(vec3(-5.0, 0.25, -1.0), vec3(0.0, 0.0, 1.0)),
    ];
    let want = [Some(1.0), Some(1.0), None];
    for ((_, answers), want) in trace_everything(&tris, &rays).into_iter().zip(want) {
        for (t, occluded) in answers {
            assert_eq!(t, want);
            assert_eq!(occluded, want.is_some());
        }
    }
}

/// A sphere-sized instance box centred at 1e39 (infinite as f32) next to an ordinary one:
/// the top level never hands the closure a bad range, and still finds the ordinary instance.
#[test]
fn instance_box_at_infinity_is_ignored() {
    let boxes = [
        Aabb { min: Vec3::splat(OVERFLOWED - 1.0), max: Vec3::splat(OVERFLOWED + 1.0) },
        Aabb { min: vec3(-1.0, -1.0, -1.0), max: vec3(1.0, 1.0, 1.0) },
        Aabb { min: Vec3::splat(f32::NAN), max: Vec3::splat(f32::NAN) },
    ];
    let top = TopLevelBvh::build(&boxes, BvhSplit::Sah);
    for ray in
        [Ray::new(vec3(0.0, 0.0, -5.0), vec3(0.0, 0.0, 1.0)), Ray::new(vec3(0.0, 0.0, -5.0), vec3(f32::NAN, 0.0, 1.0))]
    {
        let mut seen = Vec::new();
        let mut r = ray;
        top.traverse(&mut r, |i, _| {
            seen.push(i);
            false
        });
        // The three share one leaf, so all may be offered; none beyond them.
        assert!(seen.iter().all(|&i| i < 3), "{seen:?}");
        if ray.dir.is_finite() {
            assert!(seen.contains(&1), "{seen:?}");
        }
    }
}

/// Boxes spaced exponentially make the SAH peel a few off per level; the build's depth limit
/// keeps the tree within `MAX_DEPTH`, so the traversal stacks cannot overflow.
#[test]
fn adversarial_spacing_stays_within_the_depth_bound() {
    let mut boxes = Vec::new();
    for k in -120..120 {
        for j in 0..40 {
            let x = 2f32.powi(k) * (1.0 + j as f32 / 64.0);
            boxes.push(Aabb { min: vec3(x, 0.0, 0.0), max: vec3(x, 1.0, 1.0) });
        }
    }
    for split in [BvhSplit::Sah, BvhSplit::Median] {
        for opts in [BuildOptions::BINARY, BuildOptions::WIDE] {
            let bvh = Bvh::build_with(&boxes, split, opts);
            let depth = bvh.stats().max_depth;
            assert!(depth <= MAX_DEPTH, "{split:?} {opts:?}: depth {depth}");
            let tris: Vec<[Vec3; 3]> =
                boxes.iter().map(|b| [b.min, vec3(b.min.x, 1.0, 0.0), vec3(b.min.x, 0.0, 1.0)]).collect();
            let w = TriangleWideBvh::<8>::build(&bvh, |i| tris[i as usize]);
            let ray = Ray::new(vec3(-1.0, 0.1, 0.1), vec3(1.0, 0.0, 0.0));
            for path in SimdPath::available() {
                assert!(w.occluded(&ray, path));
            }
        }
    }
}
