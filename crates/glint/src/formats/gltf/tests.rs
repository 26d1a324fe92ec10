//! The reader on small glTF documents made here (buffers as `data:` URIs): accessor types,
//! `normalized`, strides, sparse accessors, strips and fans, TRS and matrices, instancing,
//! and errors that name the JSON path.

use super::describe;
use crate::describe::Geometry;
use crate::io::gltf::{assemble_triangles, read_accessor, GltfFile, PrimitiveMode};
use crate::materials::SceneDesc;
use serde_json::{json, Value};
use std::path::Path;

fn base64(data: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A document with one buffer holding `bin`, and the given extra top-level fields.
fn doc(bin: &[u8], fields: Value) -> Value {
    let mut d = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(bin))}],
    });
    for (k, v) in fields.as_object().unwrap() {
        d[k] = v.clone();
    }
    d
}

fn open(d: &Value) -> Result<GltfFile, String> {
    GltfFile::from_bytes(Path::new("t.gltf"), d.to_string().as_bytes(), false)
}

fn scene(d: &Value) -> Result<SceneDesc, String> {
    describe(&open(d)?, Path::new("t.gltf"), None)
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A triangle (positions at byte 0) drawn by one node with `node` fields.
fn triangle_doc(node: Value, extra: Value) -> Value {
    let bin = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let mut fields = json!({
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [node],
        "scenes": [{"nodes": [0]}],
    });
    for (k, v) in extra.as_object().unwrap() {
        fields[k] = v.clone();
    }
    doc(&bin, fields)
}

#[test]
fn every_component_type_reads_with_and_without_normalized() {
    // i8 -128, u8 255, i16 -32768, u16 65535, u32 7 (padded to 4-byte alignment), f32 0.25.
    let mut bin = vec![0x80u8, 0, 0, 0, 255, 0, 0, 0];
    bin.extend((-32768i16).to_le_bytes());
    bin.extend([0, 0]);
    bin.extend(65535u16.to_le_bytes());
    bin.extend([0, 0]);
    bin.extend(7u32.to_le_bytes());
    bin.extend(0.25f32.to_le_bytes());
    let acc = |offset: usize, ct: u32, normalized: bool| json!({"bufferView": 0, "byteOffset": offset, "componentType": ct, "count": 1, "type": "SCALAR", "normalized": normalized});
    let d = doc(
        &bin,
        json!({
            "bufferViews": [{"buffer": 0, "byteLength": bin.len()}],
            "accessors": [acc(0, 5120, true), acc(4, 5121, true), acc(8, 5122, true), acc(12, 5123, true), acc(16, 5125, false), acc(20, 5126, false), acc(0, 5120, false), acc(4, 5121, false)],
        }),
    );
    let f = open(&d).unwrap();
    let v: Vec<f32> = (0..8).map(|i| read_accessor(&f, i, "x").unwrap().values[0]).collect();
    // The specification clamps the most negative signed value to -1.
    assert_eq!(v, [-1.0, 1.0, -1.0, 1.0, 7.0, 0.25, -128.0, 255.0]);
}

#[test]
fn strided_and_sparse_accessors() {
    // Interleaved VEC2 of f32 with a 12-byte stride (4 bytes of padding each).
    let bin = f32s(&[1.0, 2.0, 99.0, 3.0, 4.0, 99.0, 5.0, 6.0, 99.0]);
    let mut all = bin.clone();
    // Sparse: indices (u16) 0 and 2, values (f32 VEC2).
    let idx_at = all.len();
    all.extend([0u8, 0, 2, 0]);
    let val_at = all.len();
    all.extend(f32s(&[10.0, 20.0, 50.0, 60.0]));
    let d = doc(
        &all,
        json!({
            "bufferViews": [
                {"buffer": 0, "byteLength": 36, "byteStride": 12},
                {"buffer": 0, "byteOffset": idx_at, "byteLength": 4},
                {"buffer": 0, "byteOffset": val_at, "byteLength": 16},
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC2"},
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC2",
                 "sparse": {"count": 2, "indices": {"bufferView": 1, "componentType": 5123}, "values": {"bufferView": 2}}},
                {"componentType": 5126, "count": 3, "type": "VEC2",
                 "sparse": {"count": 2, "indices": {"bufferView": 1, "componentType": 5123}, "values": {"bufferView": 2}}},
            ],
        }),
    );
    let f = open(&d).unwrap();
    assert_eq!(read_accessor(&f, 0, "x").unwrap().values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    assert_eq!(read_accessor(&f, 1, "x").unwrap().values, [10.0, 20.0, 3.0, 4.0, 50.0, 60.0]);
    // Without a bufferView the base is zeros.
    assert_eq!(read_accessor(&f, 2, "x").unwrap().values, [10.0, 20.0, 0.0, 0.0, 50.0, 60.0]);
}

#[test]
fn strips_and_fans_follow_the_specification() {
    let v = [0, 1, 2, 3, 4];
    assert_eq!(assemble_triangles(&v, PrimitiveMode::Strip), [[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
    assert_eq!(assemble_triangles(&v, PrimitiveMode::Fan), [[1, 2, 0], [2, 3, 0], [3, 4, 0]]);
    assert_eq!(assemble_triangles(&v, PrimitiveMode::Triangles), [[0, 1, 2]]);
    assert!(assemble_triangles(&v, PrimitiveMode::PointsOrLines).is_empty());
}

#[test]
fn trs_equals_the_matrix_it_stands_for_and_hierarchies_compose() {
    // A quarter turn about z, scale 2, then a move by (1, 2, 3).
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let trs = json!({"mesh": 0, "translation": [1, 2, 3], "rotation": [0, 0, h, h], "scale": [2, 2, 2]});
    // The same as a column-major matrix.
    let m = json!({"mesh": 0, "matrix": [0, 2, 0, 0, -2, 0, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1]});
    let a = scene(&triangle_doc(trs, json!({}))).unwrap();
    let b = scene(&triangle_doc(m, json!({}))).unwrap();
    for (ra, rb) in a.shapes[0].to_world.iter().zip(&b.shapes[0].to_world) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-12, "{:?} vs {:?}", a.shapes[0].to_world, b.shapes[0].to_world);
        }
    }
    // A parent's translation applies to its child's.
    let d = triangle_doc(
        json!({"translation": [10, 0, 0], "children": [1]}),
        json!({"nodes": [{"translation": [10, 0, 0], "children": [1]}, {"mesh": 0, "translation": [0, 5, 0]}]}),
    );
    let s = scene(&d).unwrap();
    assert_eq!((s.shapes[0].to_world[0][3], s.shapes[0].to_world[1][3]), (10.0, 5.0));
}

#[test]
fn a_shared_mesh_is_one_mesh_placed_twice() {
    let d = triangle_doc(
        json!({}),
        json!({"nodes": [{"mesh": 0}, {"mesh": 0, "translation": [3, 0, 0]}], "scenes": [{"nodes": [0, 1]}]}),
    );
    let s = scene(&d).unwrap();
    assert_eq!(s.meshes.len(), 1);
    assert_eq!(s.shapes.len(), 2);
    assert!(s.shapes.iter().all(|sh| matches!(sh.geometry, Geometry::Instance { mesh: 0 })));
}

#[test]
fn a_mirroring_placement_uses_the_primitive_with_its_winding_reversed() {
    // Mirrored in x (negative determinant): glTF keeps the front where the mirrored normal
    // points, so that placement reads the primitive with its triangles reversed; the
    // unmirrored one and a rotation (positive determinant) share the primitive as it is.
    let d = triangle_doc(
        json!({}),
        json!({"nodes": [{"mesh": 0}, {"mesh": 0, "scale": [-1, 1, 1]}, {"mesh": 0, "rotation": [0, 0, 1, 0]}],
               "scenes": [{"nodes": [0, 1, 2]}]}),
    );
    let s = scene(&d).unwrap();
    assert_eq!(s.meshes.len(), 2);
    let mesh = |i: usize| match s.shapes[i].geometry {
        Geometry::Instance { mesh } => &s.meshes[mesh],
        _ => panic!("shape {i} is not an instance"),
    };
    assert!(!mesh(0).reverse_winding && mesh(1).reverse_winding && !mesh(2).reverse_winding);
    assert_eq!(mesh(0).shape_index, mesh(1).shape_index);
}

/// A triangle with one material whose `extensions` are `ext`.
fn material_doc(ext: Value) -> Value {
    triangle_doc(
        json!({}),
        json!({"materials": [{"name": "glass", "extensions": ext}],
               "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
               "nodes": [{"mesh": 0}]}),
    )
}

#[test]
fn an_attenuating_volume_is_an_absorbing_medium_inside_its_surface() {
    use crate::describe::{IntegratorDesc, VolumeDesc};
    let volume = |v: Value| {
        material_doc(json!({"KHR_materials_transmission": {"transmissionFactor": 0.5}, "KHR_materials_volume": v}))
    };
    let s =
        scene(&volume(json!({"thicknessFactor": 1, "attenuationColor": [0.5, 1.0, 0.0], "attenuationDistance": 4})))
            .unwrap();
    assert_eq!(s.media.len(), 1);
    let m = &s.media[0];
    // sigma_a = -ln(colour) / distance; colour 0 absorbs at the largest extinction allowed.
    assert!((m.sigma_t.r - std::f32::consts::LN_2 / 4.0).abs() < 1e-7, "{:?}", m.sigma_t);
    assert_eq!(m.sigma_t.g, 0.0);
    assert_eq!(m.sigma_t.b, crate::describe::limits::MAX_EXTINCTION);
    assert_eq!(m.albedo, VolumeDesc::Constant(crate::math::Rgb::BLACK));
    assert_eq!((s.shapes[0].media.interior, s.shapes[0].media.exterior), (Some(0), None));
    assert!(matches!(s.integrator, IntegratorDesc::Volpath(_)), "{:?}", s.integrator);
    // No medium (and the path tracer) for a thin wall, no attenuation, or no transmission.
    for d in [
        volume(json!({"thicknessFactor": 0, "attenuationColor": [0.5, 0.5, 0.5], "attenuationDistance": 4})),
        volume(json!({"thicknessFactor": 1, "attenuationColor": [0.5, 0.5, 0.5]})),
        volume(json!({"thicknessFactor": 1, "attenuationColor": [1, 1, 1], "attenuationDistance": 4})),
        material_doc(json!({"KHR_materials_volume":
            {"thicknessFactor": 1, "attenuationColor": [0.5, 0.5, 0.5], "attenuationDistance": 4}})),
    ] {
        let s = scene(&d).unwrap();
        assert!(s.media.is_empty() && s.shapes[0].media.interior.is_none());
        assert!(matches!(s.integrator, IntegratorDesc::Path(_)));
    }
}

#[test]
fn extension_textures_are_read_with_their_colour_spaces_and_errors_name_them() {
    use crate::describe::TextureDesc;
    use crate::materials::MaterialModel;
    let t = |i: usize| json!({"index": i});
    let with_textures = |ext: Value| {
        let mut d = material_doc(ext);
        d["images"] = json!([{"uri": "a.png"}, {"uri": "b.png"}]);
        d["textures"] = json!([{"source": 0}, {"source": 1}]);
        d
    };
    let s = scene(&with_textures(json!({
        "KHR_materials_specular": {"specularTexture": t(0), "specularColorTexture": t(1)},
        "KHR_materials_transmission": {"transmissionTexture": t(0)},
        "KHR_materials_clearcoat": {"clearcoatTexture": t(1), "clearcoatRoughnessTexture": t(0)},
        "KHR_materials_sheen": {"sheenColorTexture": t(0), "sheenRoughnessTexture": t(1)},
        "KHR_materials_volume": {"thicknessTexture": {"index": 1, "texCoord": 1}}
    })))
    .unwrap();
    let MaterialModel::Gltf(g) = &s.materials[0].model else { panic!("not a glTF material") };
    let read = |t: &Option<TextureDesc>| match t {
        Some(TextureDesc::Gltf(t)) => (t.image, t.srgb, t.texcoord),
        other => panic!("{other:?}"),
    };
    // (image, sRGB, texture coordinate set): colours are sRGB, the rest linear.
    assert_eq!(read(&g.specular_texture), (0, false, 0));
    assert_eq!(read(&g.specular_color_texture), (1, true, 0));
    assert_eq!(read(&g.transmission_texture), (0, false, 0));
    assert_eq!(read(&g.clearcoat_texture), (1, false, 0));
    assert_eq!(read(&g.clearcoat_roughness_texture), (0, false, 0));
    assert_eq!(read(&g.sheen_color_texture), (0, true, 0));
    assert_eq!(read(&g.sheen_roughness_texture), (1, false, 0));
    assert_eq!(read(&g.thickness_texture), (1, false, 1));
    assert_eq!(g.textures().len(), 8);
    let e = scene(&with_textures(json!({"KHR_materials_sheen": {"sheenColorTexture": t(7)}}))).unwrap_err();
    assert!(e.starts_with("materials[0].extensions.KHR_materials_sheen.sheenColorTexture.index: "), "{e}");
}

#[test]
fn errors_name_the_json_path() {
    // POSITION's accessor claims 4 vertices; the buffer holds 3.
    let mut d = triangle_doc(json!({"mesh": 0}), json!({}));
    d["bufferViews"][0]["byteLength"] = json!(36);
    d["accessors"][0]["count"] = json!(4);
    let e = scene(&d).unwrap_err();
    assert!(
        e.starts_with("meshes[0].primitives[0].attributes.POSITION: accessor 0 reads past the end of buffer 0"),
        "{e}"
    );
    // A bufferView past its buffer.
    let mut d = triangle_doc(json!({"mesh": 0}), json!({}));
    d["bufferViews"][0]["byteLength"] = json!(1u64 << 31);
    let e = scene(&d).unwrap_err();
    assert!(e.contains("bufferView 0 reads past the end of buffer 0"), "{e}");
    // An index past the vertices.
    let mut d = triangle_doc(json!({"mesh": 0}), json!({}));
    d["meshes"][0]["primitives"][0]["indices"] = json!(0);
    d["accessors"][0]["componentType"] = json!(5126);
    let e = scene(&d).unwrap_err();
    assert!(e.starts_with("meshes[0].primitives[0].indices: accessor 0 is not a scalar"), "{e}");
    // A node that is its own child.
    let d = triangle_doc(json!({"mesh": 0, "children": [0]}), json!({}));
    let e = scene(&d).unwrap_err();
    assert!(e.starts_with("nodes[0].children[0]: node 0 appears twice"), "{e}");
    // A missing mesh.
    let e = scene(&triangle_doc(json!({"mesh": 4}), json!({}))).unwrap_err();
    assert!(e.starts_with("nodes[0].mesh: meshes[4] does not exist"), "{e}");
}

#[test]
fn sizes_are_bounded_before_allocation() {
    // Billions of elements with no bufferView, and with one too short for them.
    let mut d = triangle_doc(json!({"mesh": 0}), json!({}));
    d["accessors"][0] = json!({"componentType": 5126, "count": 4_000_000_000u64, "type": "VEC3"});
    assert!(scene(&d).unwrap_err().contains("has no bufferView and 4000000000 elements"));
    let mut d = triangle_doc(json!({"mesh": 0}), json!({}));
    d["accessors"][0]["count"] = json!(4_000_000_000u64);
    assert!(scene(&d).unwrap_err().contains("reads past the end of buffer 0"));
    // A buffer whose data is shorter than its byteLength.
    let mut d = triangle_doc(json!({"mesh": 0}), json!({}));
    d["buffers"][0]["byteLength"] = json!(1000);
    assert!(open(&d).unwrap_err().starts_with("buffers[0]: byteLength is 1000 but the data has 36 bytes"));
}

#[test]
fn extensions_required_and_used() {
    let d = triangle_doc(json!({"mesh": 0}), json!({"extensionsRequired": ["KHR_draco_mesh_compression"]}));
    assert_eq!(scene(&d).unwrap_err(), "extensionsRequired: KHR_draco_mesh_compression is not supported by glint");
    let d = triangle_doc(json!({"mesh": 0}), json!({"extensionsUsed": ["VENDOR_thing", "KHR_texture_transform"]}));
    let s = scene(&d).unwrap();
    assert_eq!(s.warnings.iter().filter(|w| w.contains("VENDOR_thing")).count(), 1);
    assert!(!s.warnings.iter().any(|w| w.contains("KHR_texture_transform")));
}

#[test]
fn gpu_instancing_places_one_shape_per_instance() {
    let mut bin = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    bin.extend(f32s(&[5.0, 0.0, 0.0, 0.0, 7.0, 0.0]));
    let d = doc(
        &bin,
        json!({
            "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                          {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1}}}}],
            "scenes": [{"nodes": [0]}],
        }),
    );
    let s = scene(&d).unwrap();
    assert_eq!(s.shapes.len(), 2);
    assert_eq!((s.shapes[0].to_world[0][3], s.shapes[1].to_world[1][3]), (5.0, 7.0));
}

#[test]
fn lights_convert_photometric_units_at_683_lumens_per_watt() {
    let lights = json!({"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 683.0, "color": [1.0, 0.5, 0.0]},
        {"type": "directional", "intensity": 6830.0},
    ]}});
    let d = triangle_doc(
        json!({}),
        json!({"extensions": lights, "nodes": [
            {"mesh": 0},
            {"translation": [0, 2, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"rotation": [-std::f64::consts::FRAC_1_SQRT_2, 0, 0, std::f64::consts::FRAC_1_SQRT_2], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        ], "scenes": [{"nodes": [0, 1, 2]}]}),
    );
    let s = scene(&d).unwrap();
    match &s.lights[0].light {
        crate::describe::LightKind::Point { position, intensity } => {
            assert_eq!(position.y, 2.0);
            assert!((intensity.r - 1.0).abs() < 1e-6 && (intensity.g - 0.5).abs() < 1e-6 && intensity.b == 0.0);
        }
        other => panic!("{other:?}"),
    }
    match &s.lights[1].light {
        crate::describe::LightKind::Directional { direction, irradiance } => {
            // -z turned a quarter about -x points down.
            assert!((direction.y + 1.0).abs() < 1e-6, "{direction:?}");
            assert!((irradiance.r - 10.0).abs() < 1e-5);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_first_camera_of_the_walk_or_the_one_picked() {
    let cams = json!([
        {"type": "perspective", "name": "wide", "perspective": {"yfov": 1.0, "aspectRatio": 2.0}},
        {"type": "orthographic", "name": "plan", "orthographic": {"xmag": 2.0, "ymag": 1.0}},
    ]);
    let d = triangle_doc(
        json!({}),
        json!({"cameras": cams, "nodes": [{"mesh": 0}, {"camera": 1, "name": "top"}, {"camera": 0}], "scenes": [{"nodes": [0, 1, 2]}]}),
    );
    let f = open(&d).unwrap();
    let first = describe(&f, Path::new("t.gltf"), None).unwrap();
    assert_eq!(first.camera.projection, crate::describe::Projection::Orthographic);
    assert_eq!((first.film.width, first.film.height), (960, 480));
    for pick in ["0", "wide"] {
        let s = describe(&f, Path::new("t.gltf"), Some(pick)).unwrap();
        assert_eq!(s.camera.projection, crate::describe::Projection::Perspective);
        assert!((s.camera.fov_degrees - 1f32.to_degrees()).abs() < 1e-4);
    }
    assert_eq!(
        describe(&f, Path::new("t.gltf"), Some("top")).unwrap().camera.projection,
        crate::describe::Projection::Orthographic
    );
    let e = describe(&f, Path::new("t.gltf"), Some("nope")).unwrap_err();
    assert!(e.starts_with("--camera nope: no camera"), "{e}");
}
