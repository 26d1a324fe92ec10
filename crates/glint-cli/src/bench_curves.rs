//! `glint bench --curves FILE`: ray throughput of glint's round curves (a Mitsuba curve
//! file, linear or B-spline) on a ray file, for bench/compare-embree-curves. As for
//! triangles, each kind of query is timed several times and the best run counts.

use crate::rays;
use glint::accel::{BvhSplit, SimdPath};
use glint::geometry::{CurveBasis, CurveHit, Curves};
use glint::io::curves::read_curves;
use glint::math::Ray;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the curve benchmark needs from the command line.
pub struct CurveBench<'a> {
    pub file: &'a Path,
    pub basis: CurveBasis,
    pub rays: &'a Path,
    pub hits: Option<&'a PathBuf>,
    pub repeat: usize,
    pub simd: SimdPath,
    pub split: BvhSplit,
    pub pool: &'a rayon::ThreadPool,
}

pub fn bench_curves(b: CurveBench) -> Result<serde_json::Value, String> {
    let file = read_curves(b.file, b.basis)?;
    let rays = rays::read_rays(b.rays)?;
    if rays.is_empty() {
        return Err(format!("{}: no rays", b.rays.display()));
    }
    // Build time: the best of three builds (the curve set's BVH is built with it).
    let mut build_s = f64::INFINITY;
    let mut curves = None;
    for _ in 0..3 {
        let start = Instant::now();
        let built = b.pool.install(|| Curves::new(b.basis, file.points.clone(), file.curve_starts.clone(), b.split))?;
        build_s = build_s.min(start.elapsed().as_secs_f64());
        curves = Some(built);
    }
    let curves = curves.expect("three builds ran");
    const CHUNK: usize = 256;
    let mut hits: Vec<Option<CurveHit>> = vec![None; rays.len()];
    let mut blocked = vec![false; rays.len()];
    let (mut closest_s, mut occluded_s) = (f64::INFINITY, f64::INFINITY);
    let timed = |f: &mut (dyn FnMut() + Send)| {
        let start = Instant::now();
        b.pool.install(&mut *f);
        start.elapsed().as_secs_f64()
    };
    let trace = |r: &Ray| curves.intersect_with(r, b.simd);
    for _ in 0..b.repeat {
        closest_s = closest_s.min(timed(&mut || {
            hits.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(h, r)| {
                for (h, r) in h.iter_mut().zip(r) {
                    *h = trace(r);
                }
            })
        }));
        occluded_s = occluded_s.min(timed(&mut || {
            blocked.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(o, r)| {
                for (o, r) in o.iter_mut().zip(r) {
                    *o = curves.occluded(r);
                }
            })
        }));
    }
    let hit_count = hits.iter().filter(|h| h.is_some()).count();
    if let Some(p) = b.hits {
        let bytes: Vec<u8> = hits.iter().flat_map(|h| h.map_or(f32::INFINITY, |h| h.t).to_le_bytes()).collect();
        std::fs::write(p, bytes).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    let n = rays.len() as f64;
    let segments = curves.segment_count();
    Ok(serde_json::json!({
        "curves": b.file.display().to_string(),
        "basis": b.basis.plugin(),
        "curve_count": curves.curve_count(),
        "segments": segments,
        "bvh_primitives": curves.primitive_count(),
        "rays": rays.len(),
        "simd": b.simd.to_string(),
        "build_ms": build_s * 1e3,
        "closest_mrays_per_s": n / closest_s / 1e6,
        "occluded_mrays_per_s": n / occluded_s / 1e6,
        "hit_fraction": hit_count as f64 / n,
        "bytes": curves.memory_bytes(),
        "bytes_per_segment": curves.memory_bytes() as f64 / segments as f64,
    }))
}
