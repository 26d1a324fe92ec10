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

fn close(a: glint::math::Rgb, b: [f32; 3], tol: f32) {
    for (x, y) in [a.r, a.g, a.b].into_iter().zip(b) {
        assert!((x - y).abs() <= tol * y.abs().max(1e-3), "{a:?} vs {b:?}");
    }
}

/// Spectra become the RGB that Mitsuba 3.9.1's scalar_rgb variant makes of them (values
/// printed there): reflectances through D65 and clamped to [0, 1], emitters without D65, a
/// constant emitted spectrum not grey but `xyz_to_srgb(1, 1, 1)` times its value.
#[test]
fn spectra_convert_as_in_mitsubas_rgb_variants() {
    let dir = scratch("spectra");
    let p = dir.join("s.xml");
    write(
        &p,
        &format!(
            r#"<scene version="3.0.0">{SENSOR}
<shape type="sphere">
  <bsdf type="diffuse"><spectrum name="reflectance" value="400:0.78, 500:0.78, 600:0.78, 700:0.78"/></bsdf>
  <emitter type="area"><spectrum name="radiance" value="400:0, 500:8, 600:15.6, 700:18.4"/></emitter>
</shape>
<shape type="sphere"><bsdf type="conductor"><spectrum name="eta" value="0.27"/><spectrum name="k" value="300:1.92, 400:1.95, 500:1.95, 600:2.97, 700:3.8, 800:5.12"/></bsdf>
  <emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape>
<shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" value="0.3"/></bsdf>
  <emitter type="area"><float name="radiance" value="2"/></emitter></shape>
<emitter type="constant"><spectrum name="radiance" type="blackbody"><float name="temperature" value="2700"/></spectrum></emitter>
<emitter type="point"><spectrum name="intensity" value="400:1, 700:1"/></emitter>
</scene>"#
        ),
    );
    let d = read(&p).unwrap();
    let diffuse = |i: usize| match &d.materials[i].model {
        MaterialModel::Diffuse { reflectance: TextureDesc::Constant { color } } => *color,
        other => panic!("{other:?}"),
    };
    close(diffuse(0), [0.776368, 0.779809, 0.776029], 1e-5);
    close(d.shapes[0].emission.unwrap().radiance, [20.7108, 10.8546, 2.77115], 1e-5);
    match &d.materials[1].model {
        MaterialModel::Conductor { eta, k, .. } => {
            close(*eta, [0.27, 0.27, 0.27], 0.0);
            // Unbounded: through D65, clamped at 0 only (mi.spectrum_list_to_srgb(..., False, True)).
            close(*k, [3.3887, 2.34904, 1.87516], 1e-5);
        }
        other => panic!("{other:?}"),
    }
    close(d.shapes[1].emission.unwrap().radiance, [2.0 * 1.20479, 2.0 * 0.948291, 2.0 * 0.908916], 1e-5);
    close(diffuse(2), [0.3, 0.3, 0.3], 0.0);
    close(d.shapes[2].emission.unwrap().radiance, [2.0, 2.0, 2.0], 0.0);
    match &d.lights[0].light {
        LightKind::Constant { radiance } => close(*radiance, [314.3371, 130.67393, 31.319273], 5e-3),
        other => panic!("{other:?}"),
    }
    match &d.lights[1].light {
        LightKind::Point { intensity, .. } => assert!(intensity.r > 0.0 && intensity.b > 0.0, "{intensity:?}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn malformed_spectra_are_errors_with_file_and_line() {
    let dir = scratch("bad-spectra");
    for (i, (value, expect)) in [
        ("value=\"500:0.5\"", "at least two"),
        ("value=\"600:0.5, 500:0.5\"", "must increase"),
        ("value=\"500:0.5, 600\"", "wavelength:value pair"),
        ("value=\"500:x, 600:1\"", "wavelength:value pair"),
        ("value=\"500:nan, 600:1\"", "finite"),
        ("value=\"abc\"", "not a number"),
        ("filename=\"gold.spd\"", "not supported"),
        ("type=\"regular\"", "'regular' is not supported"),
        ("type=\"blackbody\"", "temperature"),
    ]
    .into_iter()
    .enumerate()
    {
        let p = dir.join(format!("bad{i}.xml"));
        write(
            &p,
            &format!(
                "<scene version=\"3.0.0\">{SENSOR}\n<shape type=\"sphere\"><bsdf type=\"diffuse\">\n<spectrum name=\"reflectance\" {value}/>\n</bsdf></shape></scene>"
            ),
        );
        let e = read(&p).unwrap_err();
        assert!(e.contains(&format!("bad{i}.xml:4:")) && e.contains(expect), "{value}: {e}");
    }
}
