//! Mitsuba reader features where parsing is the point (what the scene becomes, not how it
//! renders): the search path, scene-level samplers, spectra, serialized meshes, and the
//! report of every unsupported feature at once.

mod common;

use common::load::load;
use glint::describe::{Geometry, LightKind, MaterialModel, SceneDesc, TextureDesc};
use glint::formats::{Define, ReadOptions};
use std::path::{Path, PathBuf};

/// A fresh folder for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("glint-mitsuba-features-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn read(path: &Path) -> Result<SceneDesc, String> {
    glint::formats::read(path, &ReadOptions { defines: Vec::<Define>::new() }).map_err(|e| e.to_string())
}

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn path_folders_serve_meshes_textures_envmaps_and_includes() {
    let dir = scratch("path");
    write(&dir.join("common/meshes/tri.obj"), TRIANGLE);
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/mitsuba/assets/texture.png"),
        dir.join("common/textures/t.png").tap_parent(),
    )
    .unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/mitsuba/assets/sky.exr"),
        dir.join("common/textures/sky.exr"),
    )
    .unwrap();
    // As in Mitsuba's documentation scenes: the scene in docs/scenes/, a <path> to
    // ../../common, and an included file in docs/scenes/include/ with a <path> of its own.
    write(
        &dir.join("docs/scenes/include/part.xml"),
        r#"<scene version="3.0.0">
    <path value="../../common"/>
    <shape type="obj"><string name="filename" value="meshes/tri.obj"/>
        <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="textures/t.png"/></texture></bsdf>
    </shape>
</scene>"#,
    );
    let scene = dir.join("docs/scenes/scene.xml");
    write(
        &scene,
        &format!(
            r#"<scene version="3.0.0">
    <path value="../../common"/>
    {SENSOR}
    <emitter type="envmap"><string name="filename" value="textures/sky.exr"/></emitter>
    <include filename="include/part.xml"/>
</scene>"#
        ),
    );
    let desc = read(&scene).unwrap();
    let same = |a: &Path, b: &Path| assert_eq!(a.canonicalize().unwrap(), b.canonicalize().unwrap());
    match &desc.shapes[0].geometry {
        Geometry::MeshFile { file, .. } => same(file, &dir.join("common/meshes/tri.obj")),
        other => panic!("{other:?}"),
    }
    match &desc.lights[0].light {
        LightKind::EnvMap { file, .. } => same(file, &dir.join("common/textures/sky.exr")),
        other => panic!("{other:?}"),
    }
    match &desc.materials[0].model {
        MaterialModel::Diffuse { reflectance: TextureDesc::Bitmap { file, .. } } => {
            same(file, &dir.join("common/textures/t.png"))
        }
        other => panic!("{other:?}"),
    }
    // And the whole scene builds (the files are really read).
    load(&scene, &[], None).unwrap();
}

trait TapParent {
    fn tap_parent(self) -> Self;
}

impl TapParent for PathBuf {
    /// Creates the path's folder, and gives the path back.
    fn tap_parent(self) -> Self {
        std::fs::create_dir_all(self.parent().unwrap()).unwrap();
        self
    }
}
