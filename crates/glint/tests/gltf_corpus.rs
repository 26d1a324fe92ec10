//! Every asset of the shared glTF corpus (`../shared/corpora/gltf/`, see its `index.json`
//! and `SOURCE.md`) loads, draws the triangle count and fills the world-space bounding box
//! that `index.json` gives (computed there by an independent tool), and renders to a finite,
//! not black image in which the scene is seen. Every asset is rendered under a uniform white
//! sky added for the test (glTF's background is black and most assets bring no light), so
//! the background reads exactly 1 and "the scene is seen" means some pixel differs from it.
//! Skipped, with a message, where the corpus is absent.

use glint::describe::{LightDesc, LightKind};
use glint::error::SourceLoc;
use glint::formats::ReadOptions;
use glint::math::Rgb;
use glint::render::Silent;
use glint::session::{FilmOptions, RenderControl, Session};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpora/gltf");
    dir.join("index.json").is_file().then_some(dir)
}

/// (file, triangles, bbox min, bbox max) of every variant in the index.
fn variants(dir: &Path) -> Vec<(PathBuf, u64, [f64; 3], [f64; 3])> {
    let index: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("index.json")).unwrap()).unwrap();
    let mut out = Vec::new();
    for asset in index["assets"].as_array().unwrap() {
        for v in asset["variants"].as_array().unwrap() {
            let f = &v["facts"];
            let xyz = |k: &str| -> [f64; 3] {
                let a = f["bbox"][k].as_array().unwrap();
                [0, 1, 2].map(|i| a[i].as_f64().unwrap())
            };
            out.push((dir.join(v["file"].as_str().unwrap()), f["triangles"].as_u64().unwrap(), xyz("min"), xyz("max")));
        }
    }
    out
}

#[test]
fn every_corpus_asset_loads_with_its_indexed_facts_and_renders() {
    let Some(dir) = corpus() else {
        println!("skipped: the glTF corpus (../shared/corpora/gltf) is absent");
        return;
    };
    let list = variants(&dir);
    assert!(list.len() >= 20, "the index lists {} variants", list.len());
    let mut failures = Vec::new();
    for (file, triangles, min, max) in &list {
        if let Err(e) = check(file, *triangles, *min, *max) {
            failures.push(format!("{}: {e}", file.display()));
        }
    }
    assert!(failures.is_empty(), "{} of {} assets failed:\n{}", failures.len(), list.len(), failures.join("\n"));
}

fn check(file: &Path, triangles: u64, min: [f64; 3], max: [f64; 3]) -> Result<(), String> {
    let mut s = Session::open(file, &ReadOptions::default()).map_err(|e| e.to_string())?;
    let d = s.edit();
    d.film.width = 24;
    d.film.height = 24;
    d.sampler.spp = 2;
    d.lights.push(LightDesc {
        light: LightKind::Constant { radiance: Rgb::splat(1.0) },
        name: None,
        loc: SourceLoc::default(),
    });
    let world = s.world().map_err(|e| e.to_string())?;
    if world.triangle_count() as u64 != triangles {
        return Err(format!("{} triangles, the index says {triangles}", world.triangle_count()));
    }
    // The world's bounds are the instances' boxes (each a transformed mesh box, so at least
    // the exact one); the reader's own exact box is in the summary. Both must hold the
    // index's box; the reader's must match it to f32 precision.
    let b = world.bounds();
    let extent = (0..3).map(|i| max[i] - min[i]).fold(0.0f64, f64::max).max(1e-6);
    let tol = 1e-5 * extent.max(max.iter().chain(&min).fold(0.0f64, |a, v| a.max(v.abs())));
    let (bmin, bmax) = ([b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z]);
    for i in 0..3 {
        if !(bmin[i] as f64 <= min[i] + tol && bmax[i] as f64 >= max[i] - tol) {
            return Err(format!("world bounds {bmin:?}..{bmax:?} do not hold the index's {min:?}..{max:?}"));
        }
    }
    let line = s.description().summary.iter().find(|l| l.starts_with("glTF bounds")).cloned().unwrap_or_default();
    let nums: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter_map(|t| t.parse().ok())
        .collect();
    let want: Vec<f64> = min.iter().chain(&max).copied().collect();
    // The summary prints 4 decimals.
    if nums.len() != 6 || nums.iter().zip(&want).any(|(a, b)| (a - b).abs() > 6e-5 + 1e-6 * b.abs()) {
        return Err(format!("reader's bounds '{line}', the index says {min:?}..{max:?}"));
    }
    let mut film = s.new_film(&FilmOptions::default()).map_err(|e| e.to_string())?;
    let cancel = AtomicBool::new(false);
    s.render(&mut film, &RenderControl::new(&cancel, &Silent), &mut |_| Ok(())).map_err(|e| e.to_string())?;
    let img = film.image();
    if img.pixels.iter().any(|p| !p.to_array().iter().all(|v| v.is_finite())) {
        return Err("the render has a non-finite pixel".into());
    }
    let sum: f64 = img.pixels.iter().map(|p| p.luminance() as f64).sum();
    if !(sum > 0.0) {
        return Err("the render is black".into());
    }
    if img.pixels.iter().all(|p| p.to_array().iter().all(|v| (v - 1.0).abs() < 1e-6)) {
        return Err("the render shows the sky only".into());
    }
    Ok(())
}
