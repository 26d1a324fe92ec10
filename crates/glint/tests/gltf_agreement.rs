//! glint agrees with Blender's Cycles on the glTF agreement scenes in tests/scenes/gltf/,
//! where glTF's BRDF and Blender's Principled BSDF are the same function (emission;
//! Lambertian surfaces, metallic 0 with `KHR_materials_specular` factor 0; metals, GGX with
//! Schlick's Fresnel against Cycles' single-scattering GGX) and for the punctual lights with
//! their photometric units. Each scene is loaded through the session, as the front ends load
//! it, and rendered at the sample count the references were made for:
//! (a) every channel's image mean is within 1% of Cycles' high-spp reference, and
//! (b) the relative MSE against that reference is at most 1.3 times the relative MSE of
//!     Cycles' own independent-seed renders at the same sample count.
//! Regenerate the references with tests/scenes/gltf/make-references (docs/gltf-brdf.md).

use glint::io::{read_image, Image};
use glint::render::{render, Silent};
mod common;

use common::load::load;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/gltf")
}

/// mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01), as in make-references.
fn rel_mse(x: &Image, reference: &Image) -> f64 {
    let mut s = 0.0f64;
    for (a, b) in x.pixels.iter().zip(&reference.pixels) {
        for k in 0..3 {
            let (a, b) = (a.channel(k) as f64, b.channel(k) as f64);
            s += (a - b) * (a - b) / (b * b + 1e-2);
        }
    }
    s / (3 * x.pixels.len()) as f64
}

fn reference_entry(name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir().join("references/references.json")).unwrap();
    let index: serde_json::Value = serde_json::from_str(&text).unwrap();
    index[name].clone()
}

fn check(name: &str) {
    let entry = reference_entry(name);
    let cycles_rel_mse = entry["cycles_rel_mse"].as_f64().unwrap();
    let spp = entry["test_spp"].as_u64().unwrap() as u32;
    let reference = read_image(&dir().join(format!("references/{name}.exr"))).unwrap();
    let size = (reference.width as u32, reference.height as u32);
    let mut scene = load(&dir().join(format!("{name}.gltf")), &[], Some(size)).unwrap();
    scene.settings.spp = spp;
    let image = render(&scene.world, &scene.integrator, &scene.settings, &Silent).image;
    assert_eq!((image.width, image.height), (reference.width, reference.height));
    let (ours, theirs) = (image.channel_means(), reference.channel_means());
    let err = rel_mse(&image, &reference);
    eprintln!("{name}: means {ours:?} vs Cycles' {theirs:?}; relMSE {err:.3e} vs Cycles' {cycles_rel_mse:.3e}");
    for k in 0..3 {
        let rel = (ours[k] - theirs[k]).abs() / theirs[k].max(1e-6);
        assert!(
            rel < 0.01,
            "{name}: channel {k} mean {} differs from Cycles' {} by {:.2}%",
            ours[k],
            theirs[k],
            rel * 100.0
        );
    }
    assert!(err <= 1.3 * cycles_rel_mse, "{name}: relative MSE {err:.3e} > 1.3 x Cycles' {cycles_rel_mse:.3e}");
}

/// An emissive quad (`emissiveFactor` x `KHR_materials_emissive_strength`) lighting a room
/// of Lambertian walls and a box.
#[test]
fn emission_and_lambertian_surfaces() {
    check("emissive");
}

/// The same room with a rough copper box and a smoother steel panel (GGX, Schlick).
#[test]
fn metals() {
    check("metal");
}

/// `KHR_lights_punctual` point, spot and directional lights in candela and lux.
#[test]
fn punctual_lights() {
    check("punctual");
}
