//! `glint bench`: ray throughput of glint's BVH on a ray file, for comparison with other
//! engines (bench/compare-embree). Every ray is traced for the closest hit and, separately,
//! for occlusion, several times; the best run counts, as timings on a shared machine only
//! ever err on the slow side. `--batch` also traces them through the batch API (several rays
//! in flight per thread), in runs interleaved with the single-ray ones so that the two are
//! measured under the same load, and checks that both give the same answers ray by ray;
//! occlusion is also traced in packets (8 or 16 rays per instruction, `packet.rs`).

use crate::bench_curves::{bench_curves, CurveBench};
use crate::{meshsrc, rays};
use clap::Args;
use glint::accel::{BvhSplit, SimdPath, TriangleHit, BATCH_LANES};
use glint::geometry::{CurveBasis, MeshAccel, TriangleMesh};
use glint::math::Ray;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct BenchArgs {
    /// Mesh file (.obj, .ply; all groups together) or synthetic:TRIANGLES.
    #[arg(long, required_unless_present = "curves", conflicts_with = "curves")]
    mesh: Option<String>,
    /// A Mitsuba curve file (x y z radius per line, a blank line between curves) to trace
    /// instead of a mesh; `--basis` says how its points make curves.
    #[arg(long)]
    curves: Option<PathBuf>,
    /// The curves' basis: linear (Mitsuba's linearcurve) or bspline (bsplinecurve).
    #[arg(long, default_value = "bspline", value_parser = ["linear", "bspline"])]
    basis: String,
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
    /// SIMD path: auto (best the CPU has), avx512, avx2, sse, scalar.
    #[arg(long, default_value = "auto")]
    simd: String,
    /// Split strategy of the binary build that the wide BVH is collapsed from.
    #[arg(long, default_value = "sah", value_parser = |s: &str| s.parse::<BvhSplit>())]
    split: BvhSplit,
    /// Also trace through the batch API and report its Mrays/s beside the single-ray figures.
    #[arg(long)]
    batch: bool,
    /// With --batch: rays leave a packet (occlusion and closest hit) where fewer than this
    /// many are active at a node (0: never).
    #[arg(long, default_value_t = glint::accel::SINGLE_BELOW)]
    packet_split: u32,
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
    let Some(mesh_name) = &a.mesh else {
        let file = a.curves.as_deref().expect("clap requires --mesh or --curves");
        let basis = if a.basis == "linear" { CurveBasis::Linear } else { CurveBasis::BSpline };
        let out = bench_curves(CurveBench {
            file,
            basis,
            rays: &a.rays,
            hits: a.hits.as_ref(),
            repeat: a.repeat,
            simd,
            split: a.split,
            pool: &pool,
        })?;
        print_result(&out, a.json);
        return Ok(());
    };
    let flat = meshsrc::load(mesh_name)?;
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
    let trace_closest = |r: &Ray| mesh.intersect_with(&mut r.clone(), simd);
    const CHUNK: usize = 1024;
    let mut hits: Vec<Option<(u32, TriangleHit)>> = vec![None; rays.len()];
    let mut batch_hits = hits.clone();
    let mut batch_blocked = vec![false; rays.len()];
    let mut packet_blocked = vec![false; rays.len()];
    let mut packet_occluded_s = f64::INFINITY;
    let mut packet_hits = hits.clone();
    let mut packet_closest_s = f64::INFINITY;
    let (mut closest_s, mut occluded_s) = (f64::INFINITY, f64::INFINITY);
    let (mut batch_closest_s, mut batch_occluded_s) = (f64::INFINITY, f64::INFINITY);
    let mut blocked = vec![false; rays.len()];
    // Best of `repeat` for each kind; with `--batch` the four kinds take turns in each round.
    let timed = |f: &mut (dyn FnMut() + Send)| {
        let start = Instant::now();
        pool.install(&mut *f);
        start.elapsed().as_secs_f64()
    };
    for _ in 0..a.repeat {
        closest_s = closest_s.min(timed(&mut || {
            hits.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(h, r)| {
                for (h, r) in h.iter_mut().zip(r) {
                    *h = trace_closest(r);
                }
            })
        }));
        if a.batch {
            batch_closest_s = batch_closest_s.min(timed(&mut || {
                batch_hits
                    .par_chunks_mut(CHUNK)
                    .zip(rays.par_chunks(CHUNK))
                    .for_each(|(h, r)| mesh.intersect_batch_with(r, h, simd))
            }));
            packet_closest_s = packet_closest_s.min(timed(&mut || {
                packet_hits
                    .par_chunks_mut(CHUNK)
                    .zip(rays.par_chunks(CHUNK))
                    .for_each(|(h, r)| mesh.intersect_packets_with(r, h, simd, a.packet_split))
            }));
        }
        occluded_s = occluded_s.min(timed(&mut || {
            blocked.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(b, r)| {
                for (b, r) in b.iter_mut().zip(r) {
                    *b = mesh.occluded_with(r, simd);
                }
            })
        }));
        if a.batch {
            batch_occluded_s = batch_occluded_s.min(timed(&mut || {
                batch_blocked
                    .par_chunks_mut(CHUNK)
                    .zip(rays.par_chunks(CHUNK))
                    .for_each(|(b, r)| mesh.occluded_batch_with(r, b, simd))
            }));
            packet_occluded_s = packet_occluded_s.min(timed(&mut || {
                packet_blocked
                    .par_chunks_mut(CHUNK)
                    .zip(rays.par_chunks(CHUNK))
                    .for_each(|(b, r)| mesh.occluded_packets_with(r, b, simd, a.packet_split))
            }));
        }
    }
    let hit_count = hits.iter().filter(|h| h.is_some()).count();
    let occluded = blocked.iter().filter(|&&b| b).count();
    if hit_count != occluded {
        return Err(format!("internal error: {hit_count} closest hits but {occluded} occluded rays"));
    }
    if a.batch {
        check_batch(&hits, &blocked, &batch_hits, &batch_blocked)?;
        // The packets' closest hits, held to the same bits (occlusion checked below).
        check_batch(&hits, &blocked, &packet_hits, &blocked)?;
        if let Some(i) = (0..rays.len()).find(|&i| packet_blocked[i] != blocked[i]) {
            let (s, p) = (blocked[i], packet_blocked[i]);
            return Err(format!("internal error: ray {i}: single-ray occlusion {s}, packet occlusion {p}"));
        }
    }
    if let Some(p) = &a.hits {
        let bytes: Vec<u8> = hits.iter().flat_map(|h| h.map_or(f32::INFINITY, |h| h.1.t).to_le_bytes()).collect();
        std::fs::write(p, bytes).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    let n = rays.len() as f64;
    let out = serde_json::json!({
        "mesh": mesh_name,
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
    let mut out = out;
    if a.batch {
        let o = out.as_object_mut().unwrap();
        o.insert("batch_lanes".into(), BATCH_LANES.into());
        o.insert("batch_closest_mrays_per_s".into(), (n / batch_closest_s / 1e6).into());
        o.insert("batch_occluded_mrays_per_s".into(), (n / batch_occluded_s / 1e6).into());
        // Same-run ratios: the figures that mean something on a shared machine.
        o.insert("batch_closest_speedup".into(), (closest_s / batch_closest_s).into());
        o.insert("batch_occluded_speedup".into(), (occluded_s / batch_occluded_s).into());
        o.insert("packet_lanes".into(), glint::accel::packet_lanes(simd).into());
        o.insert("packet_split".into(), a.packet_split.into());
        o.insert("packet_occluded_mrays_per_s".into(), (n / packet_occluded_s / 1e6).into());
        o.insert("packet_occluded_speedup".into(), (occluded_s / packet_occluded_s).into());
        o.insert("packet_closest_mrays_per_s".into(), (n / packet_closest_s / 1e6).into());
        o.insert("packet_closest_speedup".into(), (closest_s / packet_closest_s).into());
    }
    print_result(&out, a.json);
    Ok(())
}

fn print_result(out: &serde_json::Value, json: bool) {
    if json {
        println!("{out}");
    } else {
        for (k, v) in out.as_object().into_iter().flatten() {
            println!("{k:<26} {v}");
        }
    }
}

/// The batch API must give each ray the single-ray answer: the same triangle and the same
/// distance and barycentrics, bit for bit, and the same occlusion.
fn check_batch(
    single: &[Option<(u32, TriangleHit)>],
    single_blocked: &[bool],
    batch: &[Option<(u32, TriangleHit)>],
    batch_blocked: &[bool],
) -> Result<(), String> {
    let key = |h: &Option<(u32, TriangleHit)>| h.map(|(p, h)| (p, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()));
    for (i, (s, b)) in single.iter().zip(batch).enumerate() {
        if key(s) != key(b) {
            return Err(format!("internal error: ray {i}: single-ray hit {s:?}, batch hit {b:?}"));
        }
        if single_blocked[i] != batch_blocked[i] {
            let (s, b) = (single_blocked[i], batch_blocked[i]);
            return Err(format!("internal error: ray {i}: single-ray occlusion {s}, batch occlusion {b}"));
        }
    }
    Ok(())
}
