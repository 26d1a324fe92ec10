//! A glTF file placed from a JSON scene as a group of shapes (`{"type": "gltf", "file": ...,
//! "transform": [...]}`) beside the JSON's own materials, shapes and environment; and the
//! files a glTF scene depends on (its `.bin` and images) in the checkpoint's scene hash and
//! in what a render farm ships.

mod common;

use common::scratch::ScratchDir;
use glint::describe::{Geometry, LightKind, MaterialRef};
use glint::formats::ReadOptions;
use glint::render::Silent;
use glint::session::{FilmOptions, RenderControl, Session};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// A unit triangle in `tri.bin`, textured from `tex.png`, material "paint", with a point
/// light one unit above the origin: `tri.gltf` in `dir`.
fn write_gltf(dir: &Path) -> PathBuf {
    let mut bin: Vec<u8> =
        [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend([0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0].iter().flat_map(|x| x.to_le_bytes()));
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb([200, 120, 40]));
    img.save(dir.join("tex.png")).unwrap();
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 683.0, "name": "bulb"}]}},
        "buffers": [{"byteLength": bin.len(), "uri": "tri.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
        ],
        "images": [{"uri": "tex.png"}],
        "textures": [{"source": 0}],
        "materials": [{"name": "paint", "doubleSided": true,
                       "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "nodes": [{"mesh": 0}, {"translation": [0.0, 1.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "scenes": [{"nodes": [0, 1]}]
    });
    let path = dir.join("tri.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

fn write_json(dir: &Path, gltf_shape: serde_json::Value) -> PathBuf {
    let scene = json!({
        "camera": {"position": [10.3, 0.3, 4.0], "look_at": [10.3, 0.3, 0.0], "fov": 30},
        "film": {"width": 24, "height": 24},
        "sampler": {"spp": 4},
        "materials": {"red": {"type": "diffuse", "reflectance": [0.8, 0.1, 0.1]}},
        "shapes": [
            {"type": "sphere", "center": [0, 0, -50], "radius": 1, "material": "red"},
            gltf_shape
        ],
        "lights": [{"type": "constant", "radiance": [0.5, 0.5, 0.5]}]
    });
    let path = dir.join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    path
}

fn open(path: &Path) -> Result<Session, glint::error::Error> {
    Session::open(path, &ReadOptions::default())
}

#[test]
fn a_gltf_file_placed_from_json_moves_with_its_transform_beside_the_json_entities() {
    let dir = ScratchDir::new("gltf-compose");
    write_gltf(&dir);
    let scene = write_json(&dir, json!({"type": "gltf", "file": "tri.gltf", "transform": [{"translate": [10, 0, 0]}]}));
    let mut session = open(&scene).unwrap();
    let d = session.description().clone();

    // The JSON's sphere, then the glTF's triangle; the JSON's material first, then glTF's.
    assert_eq!(d.shapes.len(), 2);
    assert!(matches!(d.shapes[0].geometry, Geometry::Sphere { .. }));
    assert!(matches!(d.shapes[1].geometry, Geometry::Instance { .. }));
    assert_eq!(d.shapes[0].material, MaterialRef::Index(d.material_index("red").unwrap()));
    assert_eq!(d.shapes[1].material, MaterialRef::Index(d.material_index("paint").unwrap()));
    assert_eq!(d.shapes[1].to_world[0][3], 10.0, "the triangle was not moved by the JSON transform");
    // The glTF's light moved with it (683 cd is 1 W/sr); the JSON's constant light kept.
    let points: Vec<_> = d
        .lights
        .iter()
        .filter_map(|l| match &l.light {
            LightKind::Point { position, intensity } => Some((*position, *intensity)),
            _ => None,
        })
        .collect();
    assert_eq!(points.len(), 1);
    assert_eq!(points[0].0.to_array(), [10.0, 1.0, 0.0]);
    assert!((points[0].1.r - 1.0).abs() < 1e-6);
    assert!(d.lights.iter().any(|l| matches!(l.light, LightKind::Constant { .. })));
    // The JSON's camera is kept: a placed glTF chooses none and warns of none.
    assert_eq!(d.camera.fov_degrees, 30.0);
    assert!(d.warnings.iter().all(|w| !w.contains("camera")), "{:?}", d.warnings);

    // Built, the triangle lies at x 10 to 11; the render of it is finite and lit.
    let world = session.world().unwrap();
    let b = world.bounds();
    assert!(b.max.x >= 11.0 - 1e-4 && b.min.x <= -1.0 + 1e-4, "bounds {b:?}");
    let mut film = session.new_film(&FilmOptions::default()).unwrap();
    let cancel = AtomicBool::new(false);
    session.render(&mut film, &RenderControl::new(&cancel, &Silent), &mut |_| Ok(())).unwrap();
    let img = film.image();
    let centre = img.pixels[12 * img.width + 12];
    assert!(centre.is_finite() && centre.max_component() > 0.0, "{centre:?}");
}

#[test]
fn a_placed_gltf_takes_only_file_and_transform_and_names_what_it_refused() {
    let dir = ScratchDir::new("gltf-compose-errors");
    write_gltf(&dir);
    let scene = write_json(&dir, json!({"type": "gltf", "file": "tri.gltf", "material": "red"}));
    let e = open(&scene).err().expect("a gltf shape with a material must be refused").to_string();
    assert!(e.contains("scene.json") && e.contains("'material' does not apply"), "{e}");

    let scene = write_json(&dir, json!({"type": "gltf"}));
    let e = open(&scene).err().unwrap().to_string();
    assert!(e.contains("needs 'file'"), "{e}");

    // An error inside the glTF file names that file and the JSON path within it.
    std::fs::write(dir.join("bad.gltf"), r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": [4]}]}"#).unwrap();
    let scene = write_json(&dir, json!({"type": "gltf", "file": "bad.gltf"}));
    let e = open(&scene).err().unwrap().to_string();
    assert!(e.contains("bad.gltf") && e.contains("scenes[0].nodes[0]"), "{e}");
}

#[test]
fn the_scene_hash_and_the_shipped_files_cover_a_gltf_files_buffers_and_images() {
    let dir = ScratchDir::new("gltf-hash");
    let gltf = write_gltf(&dir);
    let composed = write_json(&dir, json!({"type": "gltf", "file": "tri.gltf"}));
    for scene in [&gltf, &composed] {
        let hash = |p: &Path| open(p).unwrap().scene_hash().unwrap();
        let first = hash(scene);
        assert_eq!(hash(scene), first, "the hash is not deterministic");
        let shipped: Vec<PathBuf> = open(scene).unwrap().build_files().unwrap().into_iter().map(|f| f.path).collect();
        for side in ["tri.gltf", "tri.bin", "tex.png"] {
            assert!(shipped.contains(&dir.join(side)), "{side} is not shipped: {shipped:?}");
        }

        let bin = std::fs::read(dir.join("tri.bin")).unwrap();
        let mut edited = bin.clone();
        edited[4] ^= 0x01;
        std::fs::write(dir.join("tri.bin"), &edited).unwrap();
        let after_bin = hash(scene);
        assert_ne!(after_bin, first, "an edited .bin left the scene hash of {} unchanged", scene.display());
        std::fs::write(dir.join("tri.bin"), &bin).unwrap();

        let png = std::fs::read(dir.join("tex.png")).unwrap();
        image::RgbImage::from_pixel(2, 2, image::Rgb([10, 20, 30])).save(dir.join("tex.png")).unwrap();
        assert_ne!(hash(scene), first, "an edited image left the scene hash of {} unchanged", scene.display());
        std::fs::write(dir.join("tex.png"), &png).unwrap();
        assert_eq!(hash(scene), first);
    }
}
