//! `principled` and `blendbsdf` as the readers take them: bad parameters are one-line errors
//! naming the file and line, and the JSON format describes the same models as the Mitsuba
//! reader does.

mod common;

use common::load::load;
use common::scratch::ScratchDir;
use glint::describe::TextureDesc;
use glint::materials::MaterialModel;
use std::path::{Path, PathBuf};

/// A folder for one test's files: tests run in parallel, so each needs its own.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new(&format!("principled-blend-{test}"))
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;

fn scene_with(bsdf: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"sphere\">\n{bsdf}\n</shape>\n</scene>\n")
}

fn error_of(dir: &Path, name: &str, text: &str) -> String {
    let p = write(dir, name, text);
    match load(&p, &[], None) {
        Ok(_) => panic!("{name} loaded but should not"),
        Err(e) => {
            assert!(!e.contains('\n'), "not one line: {e}");
            e
        }
    }
}

#[test]
fn a_blend_needs_two_bsdfs_and_a_weight() {
    let dir = scratch("blend-arity");
    let one = scene_with(
        "<bsdf type=\"blendbsdf\">\n<float name=\"weight\" value=\"0.5\"/>\n<bsdf type=\"diffuse\"/>\n</bsdf>",
    );
    let e = error_of(&dir, "one.xml", &one);
    assert!(e.contains("one.xml:5:") && e.contains("two nested BSDFs, found 1"), "{e}");
    let three = scene_with(
        "<bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.5\"/>\n<bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/>\n<bsdf type=\"conductor\"/></bsdf>",
    );
    let e = error_of(&dir, "three.xml", &three);
    assert!(e.contains("three.xml:7:") && e.contains("more than two"), "{e}");
    let no_weight = scene_with("<bsdf type=\"blendbsdf\">\n<bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/></bsdf>");
    let e = error_of(&dir, "noweight.xml", &no_weight);
    assert!(e.contains("noweight.xml:5:") && e.contains("'weight'"), "{e}");
}

#[test]
fn principled_rejects_eta_with_specular_and_values_out_of_range() {
    let dir = scratch("principled-ranges");
    let both = scene_with(
        "<bsdf type=\"principled\">\n<float name=\"eta\" value=\"1.5\"/><float name=\"specular\" value=\"0.5\"/></bsdf>",
    );
    assert!(error_of(&dir, "both.xml", &both).contains("either 'eta' or 'specular'"));
    let aniso = scene_with("<bsdf type=\"principled\">\n<float name=\"anisotropic\" value=\"2\"/></bsdf>");
    let e = error_of(&dir, "aniso.xml", &aniso);
    assert!(e.contains("aniso.xml:5:") && e.contains("anisotropic") && e.contains("[0, 1]"), "{e}");
    let nan = scene_with("<bsdf type=\"principled\">\n<float name=\"roughness\" value=\"nan\"/></bsdf>");
    error_of(&dir, "nan.xml", &nan);
    // An unsupported feature inside a blend is reported, with the blend's other errors.
    let nested = scene_with(
        "<bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.5\"/>\n<bsdf type=\"velvet\"/><bsdf type=\"diffuse\"/></bsdf>",
    );
    assert!(error_of(&dir, "nested.xml", &nested).contains("nested.xml:6:"));
}

fn mitsuba_model(dir: &Path, bsdf: &str) -> MaterialModel {
    let p = write(dir, "model.xml", &scene_with(bsdf));
    let desc = glint::formats::mitsuba::read(&p, &[]).unwrap();
    desc.materials[0].model.clone()
}

fn json_model(material: &str) -> MaterialModel {
    let text = format!(
        r#"{{"camera": {{"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40}},
            "film": {{"width": 8, "height": 8}},
            "materials": {{"m": {material}}},
            "shapes": [{{"type": "sphere", "material": "m"}}]}}"#
    );
    let desc = glint::formats::json::read(Path::new("scene.json"), &text).unwrap();
    desc.materials[0].model.clone()
}

#[test]
fn json_and_mitsuba_describe_the_same_principled_material() {
    let dir = scratch("same-principled");
    let m = mitsuba_model(
        &dir,
        r#"<bsdf type="principled"><rgb name="base_color" value="0.2, 0.4, 0.6"/>
           <float name="metallic" value="0.3"/><float name="specular" value="0.7"/>
           <float name="clearcoat" value="0.5"/></bsdf>"#,
    );
    let j = json_model(
        r#"{"type": "principled", "base_color": [0.2, 0.4, 0.6], "metallic": 0.3, "specular": 0.7, "clearcoat": 0.5}"#,
    );
    assert_eq!(m, j);
}

#[test]
fn json_and_mitsuba_describe_the_same_blend() {
    let dir = scratch("same-blend");
    let m = mitsuba_model(
        &dir,
        r#"<bsdf type="blendbsdf"><float name="weight" value="0.25"/>
           <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf></bsdf>
           <bsdf type="principled"/></bsdf>"#,
    );
    let j = json_model(
        r#"{"type": "blend", "weight": 0.25, "materials": [
              {"type": "diffuse", "reflectance": 0.3},
              {"type": "principled", "two_sided": false}]}"#,
    );
    assert_eq!(m, j);
    let MaterialModel::Blend(b) = m else { panic!("not a blend") };
    assert!(b.first.two_sided && !b.second.two_sided);
    assert_eq!(b.weight, TextureDesc::constant(glint::math::Rgb::splat(0.25)));
}
