//! The SDF grid's intersection (a cubic per voxel, found through a BVH of the voxels that can
//! hold the surface) agrees with brute force: a fine march of the grid's trilinear
//! interpolant along the ray, refined by bisection, for random grids (a sphere's distance
//! plus noise, so that surfaces fold and split within voxels) and random rays, inside and
//! outside the grid.

use glint::accel::BvhSplit;
use glint::geometry::SdfGridData;
use proptest::prelude::*;

const STEPS: usize = 6000;

/// A sphere's signed distance (index units) on an n^3 grid, plus noise in [-amp, amp].
fn grid(n: u32, noise: &[f32], amp: f32) -> Option<SdfGridData> {
    let c = (n - 1) as f32 * 0.5;
    let r = (n - 1) as f32 * 0.3;
    let mut values = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let d = ((x as f32 - c).powi(2) + (y as f32 - c).powi(2) + (z as f32 - c).powi(2)).sqrt() - r;
                values.push(d + amp * noise[values.len() % noise.len()]);
            }
        }
    }
    SdfGridData::new([n; 3], values, BvhSplit::Sah).ok()
}

/// The ray's parameter interval inside the grid's box [0, n-1]^3 (within [0, t_max]).
fn inside_interval(o: [f64; 3], d: [f64; 3], hi: f64, t_max: f64) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, t_max);
    for a in 0..3 {
        if d[a] == 0.0 {
            if !(0.0..=hi).contains(&o[a]) {
                return None;
            }
            continue;
        }
        let (mut ta, mut tb) = ((0.0 - o[a]) / d[a], (hi - o[a]) / d[a]);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        t0 = t0.max(ta);
        t1 = t1.min(tb);
    }
    (t0 < t1).then_some((t0, t1))
}

/// The first sign change of the interpolant along the ray, found by marching and bisection.
fn brute_force(g: &SdfGridData, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<f64> {
    let hi = (g.resolution()[0] - 1) as f64;
    let (t0, t1) = inside_interval(o, d, hi, t_max)?;
    let f = |t: f64| g.eval(std::array::from_fn(|a| o[a] + d[a] * t));
    let step = (t1 - t0) / STEPS as f64;
    let (mut a, mut fa) = (t0, f(t0));
    if fa == 0.0 {
        return Some(a);
    }
    for i in 1..=STEPS {
        let b = if i == STEPS { t1 } else { t0 + step * i as f64 };
        let fb = f(b);
        if fa * fb <= 0.0 {
            let (mut lo, mut hi) = (a, b);
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if f(m) * fa <= 0.0 {
                    hi = m;
                } else {
                    lo = m;
                }
            }
            return Some(hi);
        }
        (a, fa) = (b, fb);
    }
    None
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn intersection_matches_a_fine_march(
        n in 3u32..9,
        noise in prop::collection::vec(-1.0f32..1.0, 7..64),
        amp in 0.0f32..1.5,
        o in prop::array::uniform3(-4.0f64..12.0),
        target in prop::array::uniform3(0.0f64..1.0),
        jitter in prop::array::uniform3(-0.2f64..0.2),
        t_max in prop_oneof![Just(f32::INFINITY), 0.5f32..40.0],
    ) {
        let Some(g) = grid(n, &noise, amp) else { return Ok(()) };
        // Rays in f32 as the renderer gives them, mostly aimed into the grid (from outside
        // or inside it), of arbitrary length.
        let hi = (n - 1) as f64;
        let o = o.map(|v| v as f32 as f64);
        let d: [f64; 3] = std::array::from_fn(|a| ((target[a] * hi - o[a]) * 0.3 + jitter[a] * hi) as f32 as f64);
        prop_assume!(d.iter().any(|&v| v.abs() > 1e-3));
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let got = g.intersect(o, d, 0.0, t_max);
        let expect = brute_force(&g, o, d, t_max as f64);
        prop_assert_eq!(got.is_some(), g.occluded(o, d, 0.0, t_max));
        let f = |t: f64| g.eval(std::array::from_fn(|a| o[a] + d[a] * t));
        // Tolerance in t: the root is returned in f32.
        let eps = 1e-5 * (1.0 + t_max.min(100.0) as f64) / len.max(1e-3);
        if let Some((t, _)) = got {
            let t = t as f64;
            prop_assert!(t > 0.0 && t < t_max as f64);
            // A root: the interpolant changes sign within eps of t (or vanishes there).
            let (fa, fb) = (f((t - eps).max(0.0)), f(t + eps));
            prop_assert!(fa * fb <= 0.0 || f(t).abs() < 1e-6, "t {} f {} {} {}", t, fa, f(t), fb);
            // Nothing the march finds lies clearly before it.
            if let Some(tb) = expect {
                prop_assert!(tb >= t - eps, "march {} before {}", tb, t);
            }
        }
        if let Some(tb) = expect {
            // Whatever the march finds, the intersection finds no later.
            let (t, _) = got.ok_or_else(|| TestCaseError::fail(format!("march found {tb}, intersection nothing")))?;
            prop_assert!((t as f64) <= tb + eps, "intersection {} after march {}", t, tb);
        }
    }
}
