//! `glint rays` and `glint bench`: the JSON is well-formed with the documented fields, and
//! the `--hits` file agrees ray by ray with the reference binary BVH (bit for bit) and with
//! testing every triangle. With `--batch` the batch figures are there too (and `bench`
//! itself fails if the batch answers differ from the single-ray ones on any ray). No timing
//! is asserted: benchmarks are not tests.

use glint::accel::BvhSplit;
use glint::geometry::TriangleMesh;
use glint::math::{Ray, Vec3};
use std::path::PathBuf;
use std::process::Command;

/// The library's scratch folders for tests (removed when dropped, even on a panic).
#[path = "../../glint/tests/common/scratch.rs"]
mod scratch;

fn glint(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_glint")).args(args).output().unwrap();
    assert!(o.status.success(), "glint {args:?} failed: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

fn floats(path: &PathBuf) -> Vec<f32> {
    std::fs::read(path).unwrap().chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

#[test]
fn bench_json_is_well_formed_and_hits_match_the_reference() {
    let dir = scratch::ScratchDir::new("bench-cli");
    // A small closed-ish mesh: a bumpy grid plus a tetrahedron floating above it.
    let mut obj = String::new();
    let n = 24;
    for j in 0..n {
        for i in 0..n {
            let h = ((i * 7 + j * 3) % 5) as f32 * 0.05;
            obj += &format!("v {} {h} {}\n", i as f32 * 0.1, j as f32 * 0.1);
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i + 1;
            obj += &format!("f {} {} {}\nf {} {} {}\n", a, a + 1, a + n + 1, a, a + n + 1, a + n);
        }
    }
    obj += "v 1 1 1\nv 1.5 1 1\nv 1 1.5 1\nv 1 1 1.5\nf -4 -3 -2\nf -4 -2 -1\nf -4 -1 -3\nf -3 -1 -2\n";
    let mesh_path = dir.join("mesh.obj");
    std::fs::write(&mesh_path, &obj).unwrap();
    let mesh_arg = mesh_path.to_str().unwrap();

    for kind in ["primary", "diffuse"] {
        let rays_path = dir.join(format!("{kind}.rays"));
        let hits_path = dir.join(format!("{kind}.hits"));
        glint(&["rays", "--mesh", mesh_arg, "--kind", kind, "--count", "3000", "-o", rays_path.to_str().unwrap()]);
        // Diffuse rays through the batch API as well; primary rays without it.
        let batch = kind == "diffuse";
        let mut args = vec![
            "bench",
            "--mesh",
            mesh_arg,
            "--rays",
            rays_path.to_str().unwrap(),
            "--json",
            "--repeat",
            "2",
            "--hits",
            hits_path.to_str().unwrap(),
        ];
        if batch {
            args.push("--batch");
        }
        let out = glint(&args);
        let j: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
        let batch_keys = [
            "batch_closest_mrays_per_s",
            "batch_occluded_mrays_per_s",
            "batch_closest_speedup",
            "batch_occluded_speedup",
            "packet_closest_mrays_per_s",
            "packet_occluded_mrays_per_s",
            "packet_closest_speedup",
            "packet_occluded_speedup",
        ];
        for key in batch_keys {
            if batch {
                let v = j[key].as_f64().unwrap_or_else(|| panic!("{key} missing or not a number in {out}"));
                assert!(v.is_finite() && v > 0.0, "{key} = {v}");
            } else {
                assert!(j.get(key).is_none(), "{key} without --batch: {out}");
            }
        }
        if batch {
            assert_eq!(j["batch_lanes"].as_u64(), Some(glint::accel::BATCH_LANES as u64));
            // The speedups are the ratios of the figures they sit beside.
            for api in ["batch", "packet"] {
                for kind in ["closest", "occluded"] {
                    let ratio = j[format!("{api}_{kind}_mrays_per_s")].as_f64().unwrap()
                        / j[format!("{kind}_mrays_per_s")].as_f64().unwrap();
                    let speedup = j[format!("{api}_{kind}_speedup")].as_f64().unwrap();
                    assert!((ratio / speedup - 1.0).abs() < 1e-9, "{api} {kind}: {ratio} against {speedup}");
                }
            }
        }
        for key in [
            "triangles",
            "rays",
            "build_ms",
            "closest_mrays_per_s",
            "occluded_mrays_per_s",
            "hit_fraction",
            "bvh_bytes",
            "sah_cost",
        ] {
            let v = j[key].as_f64().unwrap_or_else(|| panic!("{key} missing or not a number in {out}"));
            assert!(v.is_finite() && v >= 0.0, "{key} = {v}");
        }
        assert_eq!(j["triangles"].as_u64(), Some(2 * 23 * 23 + 4));
        assert_eq!(j["rays"].as_u64(), Some(3000));

        // The reference: the binary BVH over the same triangles, and brute force.
        let f = floats(&rays_path);
        let rays: Vec<Ray> = f
            .chunks_exact(8)
            .map(|c| Ray {
                origin: Vec3 { x: c[0], y: c[1], z: c[2] },
                t_min: c[3],
                dir: Vec3 { x: c[4], y: c[5], z: c[6] },
                t_max: c[7],
            })
            .collect();
        let g = glint::io::obj::read_obj(&mesh_path).unwrap();
        let (mut positions, mut indices) = (Vec::new(), Vec::new());
        for grp in g.groups {
            let base = positions.len() as u32;
            positions.extend(grp.positions);
            indices.extend(grp.indices.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
        }
        let mesh = TriangleMesh::new(positions, None, None, indices, BvhSplit::Sah).unwrap();
        let hits = floats(&hits_path);
        assert_eq!(hits.len(), rays.len());
        let mut n_hit = 0;
        for (r, &t) in rays.iter().zip(&hits) {
            let reference = mesh.intersect_reference(&mut r.clone()).map_or(f32::INFINITY, |h| h.1.t);
            let brute = mesh.intersect_brute_force(r).map_or(f32::INFINITY, |h| h.1.t);
            assert_eq!(t.to_bits(), reference.to_bits(), "ray {r:?}");
            assert_eq!(t.to_bits(), brute.to_bits(), "ray {r:?}");
            n_hit += t.is_finite() as usize;
        }
        let frac = j["hit_fraction"].as_f64().unwrap();
        assert!((frac - n_hit as f64 / rays.len() as f64).abs() < 1e-9);
        if kind == "primary" {
            assert!(n_hit > 100, "the camera should see the mesh");
        }
    }
}
