//! `glint bench`: ray throughput of glint's BVH on a ray file, for comparison with other
//! engines (bench/compare-embree). Every ray is traced for the closest hit and, separately,
//! for occlusion, several times; the best run counts, as timings on a shared machine only
//! ever err on the slow side.

use crate::{meshsrc, rays};
use clap::Args;
use glint::accel::{BvhSplit, SimdPath};
use glint::geometry::{MeshAccel, TriangleMesh};
use glint::math::Ray;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct BenchArgs {
    /// Mesh file (.obj, .ply; all groups together) or synthetic:TRIANGLES.
    #[arg(long)]
    mesh: String,
    /// Ray file: float32 records (ox, oy, oz, tmin, dx, dy, dz, tmax).
    #[arg(long)]
    rays: PathBuf,
    /// Write the closest-hit distance of each ray (float32, +inf for a miss).
    #[arg(long)]
    hits: Option<PathBuf>,
    /// Threads for building and tracing.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Timed runs of each kind; the best counts.
    #[arg(long, default_value_t = 5)]
    repeat: usize,
    /// Acceleration structure: wide (the renderer's), wide4, wide8, or binary (the reference).
    #[arg(long, default_value = "wide", value_parser = ["wide", "wide4", "wide8", "binary"])]
    bvh: String,
    /// SIMD path: auto (best the CPU has), avx2, sse, scalar.
    #[arg(long, default_value = "auto")]
    simd: String,
    /// Split strategy of the binary build that the wide BVH is collapsed from.
    #[arg(long, default_value = "sah", value_parser = |s: &str| s.parse::<BvhSplit>())]
    split: BvhSplit,
}

pub fn bench_cmd(a: BenchArgs) -> Result<(), String> {
    if a.threads == 0 || a.repeat == 0 {
        return Err("--threads and --repeat must be at least 1".into());
    }
    let simd = if a.simd == "auto" { SimdPath::detect() } else { a.simd.parse::<SimdPath>()? };
    if !simd.is_available() {
        return Err(format!("SIMD path {simd} is not available on this CPU"));
    }
    let accel = match a.bvh.as_str() {
        "binary" => MeshAccel::Binary,
        "wide4" => MeshAccel::Wide4,
        "wide8" => MeshAccel::Wide8,
        _ => MeshAccel::default(),
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(a.threads).build().map_err(|e| e.to_string())?;
    let flat = meshsrc::load(&a.mesh)?;
    let rays = rays::read_rays(&a.rays)?;
    if rays.is_empty() {
        return Err(format!("{}: no rays", a.rays.display()));
    }
    let triangles = flat.indices.len();
    let mut mesh = TriangleMesh::new(flat.positions, None, None, flat.indices, a.split)?;
    // Build time: the best of three builds of the acceleration structure that is traced.
    let mut build_s = f64::INFINITY;
    for _ in 0..3 {
        let start = Instant::now();
        pool.install(|| mesh.build_accel(a.split, accel));
        build_s = build_s.min(start.elapsed().as_secs_f64());
    }
    let stats = mesh.accel_stats();
    let trace_closest = |r: &Ray| -> f32 {
        let mut r = *r;
        mesh.intersect_with(&mut r, simd).map_or(f32::INFINITY, |(_, h)| h.t)
    };
    const CHUNK: usize = 1024;
    let mut hits = vec![0f32; rays.len()];
    let mut closest_s = f64::INFINITY;
    let mut occluded_s = f64::INFINITY;
    let mut occluded = 0usize;
    for _ in 0..a.repeat {
        let start = Instant::now();
        pool.install(|| {
            hits.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(h, r)| {
                for (h, r) in h.iter_mut().zip(r) {
                    *h = trace_closest(r);
                }
            })
        });
        closest_s = closest_s.min(start.elapsed().as_secs_f64());
        let start = Instant::now();
        occluded = pool
            .install(|| rays.par_chunks(CHUNK).map(|c| c.iter().filter(|r| mesh.occluded_with(r, simd)).count()).sum());
        occluded_s = occluded_s.min(start.elapsed().as_secs_f64());
    }
    let hit_count = hits.iter().filter(|t| t.is_finite()).count();
    if hit_count != occluded {
        return Err(format!("internal error: {hit_count} closest hits but {occluded} occluded rays"));
    }
    if let Some(p) = &a.hits {
        let bytes: Vec<u8> = hits.iter().flat_map(|t| t.to_le_bytes()).collect();
        std::fs::write(p, bytes).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    let n = rays.len() as f64;
    let out = serde_json::json!({
        "mesh": a.mesh,
        "triangles": triangles,
        "rays": rays.len(),
        "threads": a.threads,
        "bvh": stats.kind,
        "simd": simd.to_string(),
        "build_ms": build_s * 1e3,
        "closest_mrays_per_s": n / closest_s / 1e6,
        "occluded_mrays_per_s": n / occluded_s / 1e6,
        "hit_fraction": hit_count as f64 / n,
        "bvh_bytes": stats.bytes,
        "bytes_per_triangle": stats.bytes as f64 / triangles as f64,
        "sah_cost": stats.sah_cost,
        "binary_sah_cost": stats.binary_sah_cost,
        "nodes": stats.nodes,
        "leaves": stats.leaves,
    });
    if a.json {
        println!("{out}");
    } else {
        for (k, v) in out.as_object().into_iter().flatten() {
            println!("{k:<22} {v}");
        }
    }
    Ok(())
}
