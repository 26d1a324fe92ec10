//! The KHR material extensions' textures, read through the whole build: each multiplies its
//! factor by the channel its extension names (`specularTexture` A, `specularColorTexture`
//! RGB sRGB, `transmissionTexture` R, `clearcoatTexture` R, `clearcoatRoughnessTexture` G,
//! `sheenColorTexture` RGB sRGB, `sheenRoughnessTexture` A), as the BSDF at a hit sees it;
//! `thicknessTexture` is read (its reference checked) and changes nothing. Every
//! texture is a 1 x 1 image of its own RGBA, so the expected numbers are exact.

mod common;

use common::scratch::ScratchDir;
use glint::formats::ReadOptions;
use glint::materials::Bsdf;
use glint::session::Session;
use serde_json::json;

/// The specification's sRGB transfer function, decoded.
fn srgb(v: u8) -> f32 {
    let c = v as f64 / 255.0;
    (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
}

fn linear(v: u8) -> f32 {
    v as f32 / 255.0
}

/// One image per texture: distinct values in every channel.
const TEXELS: [(&str, [u8; 4]); 8] = [
    ("specular", [10, 20, 30, 200]),
    ("specular_color", [100, 150, 250, 255]),
    ("transmission", [128, 5, 6, 7]),
    ("clearcoat", [64, 1, 2, 3]),
    ("clearcoat_roughness", [1, 192, 3, 4]),
    ("sheen_color", [30, 60, 90, 255]),
    ("sheen_roughness", [1, 2, 3, 96]),
    ("thickness", [1, 77, 3, 4]),
];

#[test]
fn extension_textures_multiply_their_factors_by_their_channels() {
    let dir = ScratchDir::new("gltf-extension-textures");
    for (name, px) in TEXELS {
        image::RgbaImage::from_pixel(1, 1, image::Rgba(px)).save(dir.join(format!("{name}.png"))).unwrap();
    }
    let bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    let t = |i: usize| json!({"index": i});
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_transmission", "KHR_materials_clearcoat",
                           "KHR_materials_sheen", "KHR_materials_volume"],
        "buffers": [{"byteLength": bin.len(), "uri": "tri.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
        ],
        "images": TEXELS.iter().map(|(n, _)| json!({"uri": format!("{n}.png")})).collect::<Vec<_>>(),
        "textures": (0..TEXELS.len()).map(|i| json!({"source": i})).collect::<Vec<_>>(),
        "materials": [{
            "pbrMetallicRoughness": {"metallicFactor": 0.0},
            "extensions": {
                "KHR_materials_specular": {"specularFactor": 0.5, "specularTexture": t(0),
                                           "specularColorFactor": [1.0, 0.5, 2.0], "specularColorTexture": t(1)},
                "KHR_materials_transmission": {"transmissionFactor": 0.8, "transmissionTexture": t(2)},
                "KHR_materials_clearcoat": {"clearcoatFactor": 0.9, "clearcoatTexture": t(3),
                                            "clearcoatRoughnessFactor": 0.6, "clearcoatRoughnessTexture": t(4)},
                "KHR_materials_sheen": {"sheenColorFactor": [0.5, 1.0, 0.25], "sheenColorTexture": t(5),
                                        "sheenRoughnessFactor": 0.7, "sheenRoughnessTexture": t(6)},
                "KHR_materials_volume": {"thicknessFactor": 0.0, "thicknessTexture": t(7)}
            }
        }],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}]
    });
    let path = dir.join("tri.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();

    let mut s = Session::open(&path, &ReadOptions::default()).unwrap();
    let world = s.world().unwrap();
    let m = world.materials().iter().find(|m| m.name == "material 0").expect("the glTF material");
    let Bsdf::GltfPbr(b) = m.bsdf([0.5, 0.5]) else { panic!("not a glTF BSDF") };
    let close =
        |a: f32, e: f32, what: &str| assert!((a - e).abs() <= 1e-6 * e.abs().max(1.0), "{what}: {a}, expected {e}");
    let px = |i: usize| TEXELS[i].1;
    close(b.specular, 0.5 * linear(px(0)[3]), "specular x specularTexture.a");
    for (k, f) in [1.0, 0.5, 2.0].into_iter().enumerate() {
        close(b.specular_color.channel(k), f * srgb(px(1)[k]), "specularColor x specularColorTexture (sRGB)");
    }
    close(b.transmission, 0.8 * linear(px(2)[0]), "transmission x transmissionTexture.r");
    close(b.clearcoat, 0.9 * linear(px(3)[0]), "clearcoat x clearcoatTexture.r");
    close(b.clearcoat_roughness, 0.6 * linear(px(4)[1]), "clearcoatRoughness x clearcoatRoughnessTexture.g");
    for (k, f) in [0.5, 1.0, 0.25].into_iter().enumerate() {
        close(b.sheen_color.channel(k), f * srgb(px(5)[k]), "sheenColor x sheenColorTexture (sRGB)");
    }
    close(b.sheen_roughness, 0.7 * linear(px(6)[3]), "sheenRoughness x sheenRoughnessTexture.a");
    // The base stays the factors' (no base textures here), and thickness changes nothing.
    close(b.roughness, 1.0, "roughness");
    assert!(b.thin_walled);
}
