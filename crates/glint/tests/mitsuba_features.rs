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

const FILM: &str = r#"<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film>"#;

/// A scene-level `<sampler>` (or `<film>`) serves the sensor that refers to it, as in Mitsuba
/// 3.9.1; one that no sensor refers to is ignored there too (glint warns).
#[test]
fn scene_level_sampler_and_film() {
    let dir = scratch("sampler");
    let scene = |name: &str, top: &str, inside: &str| {
        let p = dir.join(name);
        write(
            &p,
            &format!(
                "<scene version=\"3.0.0\">\n{top}\n<sensor type=\"perspective\">\n{inside}\n</sensor>\n<shape type=\"sphere\"/>\n</scene>\n"
            ),
        );
        p
    };
    let sampler = |id: &str, n: u32| {
        format!(r#"<sampler type="independent" {id}><integer name="sample_count" value="{n}"/><integer name="seed" value="3"/></sampler>"#)
    };
    let d = read(&scene("ref.xml", &sampler("id=\"s\"", 7), &format!("<ref id=\"s\"/>{FILM}"))).unwrap();
    assert_eq!((d.sampler.spp, d.sampler.seed), (7, 3));
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let d = read(&scene("named.xml", &sampler("id=\"s\"", 5), &format!("<ref name=\"sampler\" id=\"s\"/>{FILM}"))).unwrap();
    assert_eq!(d.sampler.spp, 5);
    // A scene-level film, referred to.
    let film = FILM.replace("<film ", "<film id=\"f\" ");
    let d = read(&scene("film.xml", &film, "<ref id=\"f\"/>")).unwrap();
    assert_eq!((d.film.width, d.film.height), (8, 6));
    // Unreferenced: ignored with a warning naming file and line.
    let d = read(&scene("unused.xml", &sampler("", 7), FILM)).unwrap();
    assert_eq!(d.sampler.spp, 16);
    assert!(d.warnings.len() == 1 && d.warnings[0].contains("unused.xml:2:") && d.warnings[0].contains("ignored"), "{:?}", d.warnings);
    // Two samplers for one sensor: an error, as in Mitsuba.
    let e = read(&scene("two.xml", &sampler("id=\"s\"", 7), &format!("<ref id=\"s\"/>\n{}{FILM}", sampler("", 9)))).unwrap_err();
    assert!(e.contains("two.xml:5:") && e.contains("only one <sampler>"), "{e}");
}
