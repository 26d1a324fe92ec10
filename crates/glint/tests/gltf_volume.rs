//! `KHR_materials_volume`'s attenuation: light crossing a distance x inside a volume keeps
//! attenuationColor^(x / attenuationDistance) per channel (Beer-Lambert, sigma_a =
//! -ln(colour) / distance), as a homogeneous absorbing medium inside the glTF surface,
//! rendered by the volumetric path tracer (which a glTF scene gets when it has such a
//! volume). A thin-walled surface (thickness 0) absorbs nothing.
//!
//! The scene: a cube of side 2 (a glTF mesh, fully transmissive, roughness 0, ior 1.5) in
//! front of an emitting wall of radiance 1, seen straight on through a 1-degree field of
//! view. Seen face on, each face reflects F = 0.04 (Schlick's f0 at ior 1.5) and passes the
//! rest without bending it, so light crossing the 2 units of volume once (T =
//! attenuationColor^(2 / distance)), three times, ... reaches the camera:
//! (1 - F)^2 T / (1 - F^2 T^2) per channel.

mod common;

use common::load::load;
use common::scenes::render_with;
use common::scratch::ScratchDir;
use common::stats::{image_estimate, z_critical, FALSE_ALARM};
use glint::describe::IntegratorDesc;
use glint::formats::ReadOptions;
use glint::integrators::Integrator;
use glint::session::Session;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

const COLOR: [f64; 3] = [0.5, 0.25, 0.8];
const DISTANCE: f64 = 2.0;

/// A cube [-1, 1]^3 with outward counter-clockwise faces: 24 positions, 36 indices.
fn cube_bin() -> Vec<u8> {
    let mut pos: Vec<[f32; 3]> = Vec::new();
    let mut idx: Vec<u16> = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = pos.len() as u16;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut p = [0.0f32; 3];
                p[axis] = sign;
                p[u] = a;
                p[v] = b;
                pos.push(p);
            }
            // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
            if sign > 0.0 {
                idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            } else {
                idx.extend([base, base + 2, base + 1, base, base + 3, base + 2]);
            }
        }
    }
    let mut bin: Vec<u8> = pos.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
    bin
}

/// `cube.gltf` in `dir`, with `volume` as its `KHR_materials_volume` object.
fn write_cube(dir: &Path, volume: Value, ior: f64) {
    let bin = cube_bin();
    std::fs::write(dir.join("cube.bin"), &bin).unwrap();
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"],
        "buffers": [{"byteLength": bin.len(), "uri": "cube.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 288}, {"buffer": 0, "byteOffset": 288, "byteLength": 72}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 24, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}
        ],
        "materials": [{
            "name": "tinted glass",
            "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.0},
            "extensions": {
                "KHR_materials_transmission": {"transmissionFactor": 1.0},
                "KHR_materials_ior": {"ior": ior},
                "KHR_materials_volume": volume
            }
        }],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}]
    });
    std::fs::write(dir.join("cube.gltf"), doc.to_string()).unwrap();
}

/// A JSON scene placing the cube before an emitting wall; `integrator` as given (none: the
/// scene's default).
fn write_scene(dir: &Path, integrator: Option<Value>) -> PathBuf {
    let mut scene = json!({
        "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "fov": 1},
        "film": {"width": 8, "height": 8},
        "materials": {"black": {"type": "diffuse", "reflectance": 0}},
        "shapes": [
            {"type": "gltf", "file": "cube.gltf"},
            {"type": "rectangle", "material": "black", "emission": 1,
             "transform": [{"scale": 20}, {"translate": [0, 0, -3]}]}
        ]
    });
    if let Some(i) = integrator {
        scene["integrator"] = i;
    }
    let path = dir.join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    path
}

fn attenuating() -> Value {
    json!({"thicknessFactor": 2.0, "attenuationColor": COLOR, "attenuationDistance": DISTANCE})
}

#[test]
fn light_through_a_volume_keeps_the_attenuation_colour_to_the_power_of_distance() {
    let dir = ScratchDir::new("gltf-volume-beer");
    write_cube(&dir, attenuating(), 1.5);
    let scene = load(&write_scene(&dir, None), &[], None).unwrap();
    // No integrator in the JSON: the glTF volume made it the volumetric path tracer.
    assert!(matches!(scene.integrator, Integrator::Volpath(_)), "{:?}", scene.integrator);
    let out = render_with(&scene.world, &scene.integrator, 256, 5);
    let k = z_critical(FALSE_ALARM, 3);
    let f = 0.04;
    for (c, &color) in COLOR.iter().enumerate() {
        // The slant of the 1-degree view adds at most 4e-5 to the length and 1e-21 to F.
        let t = color.powf(2.0 / DISTANCE);
        let exact = (1.0 - f) * (1.0 - f) * t / (1.0 - f * f * t * t);
        let e = image_estimate(&out, c);
        println!("channel {c}: {:.5} +- {:.5} (exact {exact:.5})", e.mean, e.se);
        assert!(e.se > 0.0 && e.se < 0.02 * exact, "channel {c}: standard error {}", e.se);
        assert!((e.mean - exact).abs() <= k * e.se, "channel {c}: {:.5} +- {:.5}, exact {exact:.5}", e.mean, e.se);
    }
}

#[test]
fn a_thin_wall_absorbs_nothing() {
    // Thickness 0: the attenuation has no volume to act in; each wall passes everything
    // (transmission 1, nothing reflected face on), so the wall behind shows at 1. (Light
    // sampling through the walls' nearly specular lobe adds rare large samples: the mean is
    // tested, within its standard error.)
    let dir = ScratchDir::new("gltf-volume-thin");
    // ior 1: nothing reflected face on.
    write_cube(&dir, json!({"thicknessFactor": 0.0, "attenuationColor": COLOR, "attenuationDistance": DISTANCE}), 1.0);
    let scene = load(&write_scene(&dir, None), &[], None).unwrap();
    assert!(matches!(scene.integrator, Integrator::Path(_)), "{:?}", scene.integrator);
    let out = render_with(&scene.world, &scene.integrator, 64, 5);
    let k = z_critical(FALSE_ALARM, 3);
    for c in 0..3 {
        let e = image_estimate(&out, c);
        println!("thin wall, channel {c}: {:.5} +- {:.5}", e.mean, e.se);
        assert!(e.se < 0.01, "channel {c}: standard error {}", e.se);
        assert!((e.mean - 1.0).abs() <= k * e.se.max(1e-6), "channel {c}: {:.5} +- {:.5}, not 1", e.mean, e.se);
    }
}

#[test]
fn an_integrator_without_media_is_warned_of_the_volume_it_ignores() {
    let dir = ScratchDir::new("gltf-volume-warning");
    write_cube(&dir, attenuating(), 1.5);
    let path = write_scene(&dir, Some(json!({"type": "path"})));
    let s = Session::open(&path, &ReadOptions::default()).unwrap();
    let d = s.description();
    assert!(matches!(d.integrator, IntegratorDesc::Path(_)));
    assert!(d.warnings.iter().any(|w| w.contains("KHR_materials_volume") && w.contains("volpath")), "{:?}", d.warnings);
    // Asked for, volpath takes it without a word.
    let path = write_scene(&dir, Some(json!({"type": "volpath"})));
    let s = Session::open(&path, &ReadOptions::default()).unwrap();
    assert!(s.description().warnings.iter().all(|w| !w.contains("KHR_materials_volume")));
}
