//! glTF's `TANGENT` is the frame of the normal map where a primitive has it: the tangent's
//! xyz (interpolated, orthonormalised against the shading normal) is the map's +X and
//! sign(w) normal x tangent its +Y; without it the frame comes from the texture coordinates
//! (dp/du). Each scene is a normal-mapped white Lambertian quad (a constant 1 x 1 normal
//! map) lit by a directional light only, one bounce: every pixel is the same deterministic
//! number, so two scenes whose mapped normals agree render the same to float rounding, and
//! scenes whose normals differ render clearly different numbers.

mod common;

use common::load::load;
use common::scratch::ScratchDir;
use glint::render::{render, Silent};
use serde_json::json;

struct Quad {
    /// Texture coordinates of the corners (-1,-1), (1,-1), (1,1), (-1,1).
    uvs: [[f32; 2]; 4],
    /// One tangent (xyz, w) for every vertex, or none.
    tangent: Option<[f32; 4]>,
    /// The normal map's one texel.
    texel: [u8; 3],
    /// Placed mirrored in x.
    mirror: bool,
    /// The direction the light travels.
    light: [f32; 3],
}

/// u along +x, v along -y (glTF's v runs down the image): dp/du = +x.
const UV_X: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
/// u along +y, v along +x: dp/du = +y.
const UV_Y: [[f32; 2]; 4] = [[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];

/// The image mean (every pixel is the same) of `q` rendered in its own folder.
fn radiance(name: &str, q: &Quad) -> f64 {
    let dir = ScratchDir::new(&format!("gltf-tangents-{name}"));
    let positions: [[f32; 3]; 4] = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend([[0.0f32, 0.0, 1.0]; 4].iter().flatten().flat_map(|x| x.to_le_bytes()));
    bin.extend(q.uvs.iter().flatten().flat_map(|x| x.to_le_bytes()));
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    let tangent_at = bin.len();
    if let Some(t) = q.tangent {
        bin.extend([t; 4].iter().flatten().flat_map(|x| x.to_le_bytes()));
    }
    std::fs::write(dir.join("quad.bin"), &bin).unwrap();
    image::RgbImage::from_pixel(1, 1, image::Rgb(q.texel)).save(dir.join("normal.png")).unwrap();
    let mut attributes = json!({"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2});
    let mut views = vec![
        json!({"buffer": 0, "byteLength": 48}),
        json!({"buffer": 0, "byteOffset": 48, "byteLength": 48}),
        json!({"buffer": 0, "byteOffset": 96, "byteLength": 32}),
        json!({"buffer": 0, "byteOffset": 128, "byteLength": 12}),
    ];
    let mut accessors = vec![
        json!({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}),
        json!({"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}),
        json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}),
        json!({"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}),
    ];
    if q.tangent.is_some() {
        views.push(json!({"buffer": 0, "byteOffset": tangent_at, "byteLength": 64}));
        accessors.push(json!({"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC4"}));
        attributes["TANGENT"] = json!(4);
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_specular"],
        "buffers": [{"byteLength": bin.len(), "uri": "quad.bin"}],
        "bufferViews": views,
        "accessors": accessors,
        "images": [{"uri": "normal.png"}],
        "textures": [{"source": 0}],
        "materials": [{
            "pbrMetallicRoughness": {"metallicFactor": 0.0},
            "normalTexture": {"index": 0},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}
        }],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}]
    });
    std::fs::write(dir.join("quad.gltf"), doc.to_string()).unwrap();
    let transform = if q.mirror { json!([{"scale": [-1, 1, 1]}]) } else { json!([]) };
    let scene = json!({
        "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 10},
        "film": {"width": 8, "height": 8},
        "sampler": {"spp": 1},
        "integrator": {"type": "path", "max_depth": 2},
        "shapes": [{"type": "gltf", "file": "quad.gltf", "transform": transform}],
        "lights": [{"type": "directional", "direction": q.light, "irradiance": 1}]
    });
    let path = dir.join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let s = load(&path, &[], None).unwrap();
    let img = render(&s.world, &s.integrator, &s.settings, &Silent).image;
    let m = img.channel_means()[0];
    // Every pixel sees the same flat quad under a delta light: the same number, to the
    // rounding of the interpolated normal and tangent at different points.
    for p in &img.pixels {
        assert!((p.r as f64 - m).abs() <= 1e-5 * m.max(1e-3), "{name}: pixels differ ({} vs {m})", p.r);
    }
    assert!(m > 0.0, "{name}: black");
    m
}

fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(b.abs())
}

/// Oblique light from +x (and a little +y) above; a texel tilting the normal along the
/// map's +X. Every normal below stays lit (its cosine with the light is positive).
const LIGHT: [f32; 3] = [-0.7, -0.1, -0.707];
const TILT_X: [u8; 3] = [230, 128, 240];

#[test]
fn file_tangents_set_the_normal_maps_frame() {
    let base = Quad { uvs: UV_X, tangent: None, texel: TILT_X, mirror: false, light: LIGHT };
    // Tangents along +y on a quad whose uvs give dp/du = +x: the file's frame is used...
    let file_y = radiance("file-y", &Quad { tangent: Some([0.0, 1.0, 0.0, 1.0]), ..base });
    // ...as a quad whose own dp/du is +y renders, and unlike the uvs' frame.
    let uv_y = radiance("uv-y", &Quad { uvs: UV_Y, ..base });
    let uv_x = radiance("uv-x", &base);
    assert!(same(file_y, uv_y), "file tangents +y: {file_y}, uv frame +y: {uv_y}");
    assert!((file_y - uv_x).abs() > 0.05 * uv_x, "the file's tangents changed nothing: {file_y} vs {uv_x}");
    // Tangents that agree with the uvs change nothing (and are not normalised in the file).
    let file_x = radiance("file-x", &Quad { tangent: Some([2.0, 0.0, 0.0, 1.0]), ..base });
    assert!(same(file_x, uv_x), "file tangents +x: {file_x}, uv frame +x: {uv_x}");
    // A tangent with a component along the normal is made orthogonal to it.
    let tilted = radiance("file-tilted", &Quad { tangent: Some([0.0, 1.0, 0.7, 1.0]), ..base });
    assert!(same(tilted, uv_y), "tangent (0, 1, 0.7): {tilted}, uv frame +y: {uv_y}");
}

#[test]
fn the_tangents_w_is_the_bitangents_sign() {
    // A texel tilting along the map's +Y. With tangent +y and w = -1 the bitangent is
    // -(z x y) = +x: the same normal as the uv frame (+x) tilted along its +X.
    let tilt_y = [128, 230, 240];
    let base = Quad { uvs: UV_X, tangent: Some([0.0, 1.0, 0.0, -1.0]), texel: tilt_y, mirror: false, light: LIGHT };
    let flipped = radiance("w-negative", &base);
    let along_x = radiance("w-reference", &Quad { tangent: None, texel: TILT_X, ..base });
    assert!(same(flipped, along_x), "w = -1: {flipped}, reference: {along_x}");
    let unflipped = radiance("w-positive", &Quad { tangent: Some([0.0, 1.0, 0.0, 1.0]), ..base });
    assert!((flipped - unflipped).abs() > 0.05 * unflipped, "w changed nothing: {flipped} vs {unflipped}");
}

#[test]
fn a_mirroring_placement_mirrors_the_tangent_frame() {
    // Mirrored in x with the light mirrored too, a quad renders as it does unmirrored: its
    // bitangent (here +-x, from the file's tangent +y) moves with the surface.
    let tilt_xy = [200, 200, 240];
    let base = Quad { uvs: UV_X, tangent: Some([0.0, 1.0, 0.0, 1.0]), texel: tilt_xy, mirror: false, light: LIGHT };
    let plain = radiance("mirror-plain", &base);
    let mirrored = radiance("mirror-mirrored", &Quad { mirror: true, light: [-LIGHT[0], LIGHT[1], LIGHT[2]], ..base });
    assert!(same(plain, mirrored), "plain {plain}, mirrored {mirrored}");
    // And differently from the unmirrored quad under the mirrored light (the check can fail).
    let other = radiance("mirror-other", &Quad { light: [-LIGHT[0], LIGHT[1], LIGHT[2]], ..base });
    assert!((plain - other).abs() > 0.05 * plain, "the light's mirror changed nothing: {plain} vs {other}");
}
