#![no_main]
//! glTF 2.0 (`.gltf` JSON or `.glb`) from bytes: the file is parsed (its `data:` buffers
//! decoded, external ones not read: the path names a folder that does not exist), described
//! as a scene (node hierarchy, materials, cameras, lights), and every triangle primitive's
//! attributes, indices and every image are read as the build would read them.
use glint::io::gltf::{decode_image, image_bytes, read_primitive, GltfFile};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-glint-fuzz/in.gltf");
    let Ok(file) = GltfFile::from_bytes(path, data, false) else { return };
    let _ = glint::formats::gltf::describe(&file, path, None);
    let _ = glint::formats::gltf::describe(&file, path, Some("1"));
    for (m, mesh) in file.array("meshes").iter().enumerate().take(64) {
        let prims = mesh.get("primitives").and_then(|p| p.as_array()).map_or(0, Vec::len);
        for p in 0..prims.min(64) {
            let _ = read_primitive(&file, m, p);
        }
    }
    for i in 0..file.array("images").len().min(16) {
        if let Ok(bytes) = image_bytes(&file, i) {
            let _ = decode_image(&bytes, i % 2 == 0, "fuzz");
        }
    }
});
