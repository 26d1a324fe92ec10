//! The scene hash a checkpoint records covers every file the image depends on, an OBJ's
//! material files included: a checkpoint of a scene whose `.mtl` changed must be refused.

mod common;

use common::scratch::ScratchDir;
use glint::formats::ReadOptions;
use glint::session::Session;
use std::path::Path;

fn hash_of(obj: &Path) -> u64 {
    Session::open(obj, &ReadOptions::default()).unwrap().scene_hash().unwrap()
}

#[test]
fn editing_or_removing_an_obj_material_file_changes_the_scene_hash() {
    let dir = ScratchDir::new("scene-hash");
    let obj = dir.join("tri.obj");
    let mtl = dir.join("tri.mtl");
    std::fs::write(&obj, "mtllib tri.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(&mtl, "newmtl red\nKd 0.8 0.1 0.1\n").unwrap();
    let first = hash_of(&obj);
    assert_eq!(hash_of(&obj), first, "the hash is not deterministic");

    std::fs::write(&mtl, "newmtl red\nKd 0.1 0.8 0.1\n").unwrap();
    let edited = hash_of(&obj);
    assert_ne!(edited, first, "an edited .mtl left the scene hash unchanged");

    std::fs::remove_file(&mtl).unwrap();
    let removed = hash_of(&obj);
    assert_ne!(removed, edited, "a removed .mtl left the scene hash unchanged");
}
