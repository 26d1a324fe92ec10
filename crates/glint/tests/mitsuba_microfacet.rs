//! The Mitsuba reader's microfacet and plastic parameters: anisotropic and textured
//! roughness where Mitsuba takes them, the errors where Mitsuba rejects them, `nonlinear`,
//! `pplastic` and `polarizer`; and the JSON format's equivalents.

use glint::bsdf::MicrofacetKind;
use glint::describe::{Roughness, ScalarTexture, TextureDesc};
use glint::formats::mitsuba::read_str;
use glint::materials::{ConductorDesc, DielectricDesc, PPlasticDesc, PlasticDesc};
use glint::materials::{MaterialModel, SceneDesc};
use glint::math::Rgb;
use std::path::Path;

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;

fn scene(bsdf: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"sphere\">\n{bsdf}\n</shape>\n</scene>\n")
}

fn model(bsdf: &str) -> MaterialModel {
    let d: SceneDesc = read_str(&scene(bsdf), Path::new("m.xml"), &[]).unwrap_or_else(|e| panic!("{e}"));
    d.materials[0].model.clone()
}

fn error(bsdf: &str) -> String {
    let e = read_str(&scene(bsdf), Path::new("m.xml"), &[]).expect_err("should be rejected").to_string();
    assert!(!e.contains('\n') && e.contains("m.xml:5:"), "one line naming the file and line: {e}");
    e
}

fn roughness_of(m: &MaterialModel) -> Roughness {
    match m {
        MaterialModel::Conductor(ConductorDesc { roughness: Some(r), .. })
        | MaterialModel::Dielectric(DielectricDesc { roughness: Some(r), .. })
        | MaterialModel::Plastic(PlasticDesc { roughness: Some(r), .. })
        | MaterialModel::PPlastic(PPlasticDesc { roughness: r, .. }) => r.clone(),
        other => panic!("no roughness in {other:?}"),
    }
}

#[test]
fn anisotropic_roughness_is_read_per_axis() {
    let m = model(
        r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/>
           <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/></bsdf>"#,
    );
    let r = roughness_of(&m);
    assert_eq!(r.distribution, MicrofacetKind::Ggx);
    assert_eq!(r.alpha, ScalarTexture::Value(0.05));
    assert_eq!(r.alpha_v, Some(ScalarTexture::Value(0.3)));
}

#[test]
fn textured_roughness_is_a_texture() {
    let m = model(
        r#"<bsdf type="roughdielectric"><texture name="alpha" type="checkerboard">
             <float name="color0" value="0.0"/><float name="color1" value="0.4"/></texture></bsdf>"#,
    );
    let r = roughness_of(&m);
    assert_eq!(r.distribution, MicrofacetKind::Beckmann, "Mitsuba's default");
    match r.alpha {
        ScalarTexture::Texture(TextureDesc::Checkerboard { color0, color1, .. }) => {
            assert_eq!((color0, color1), (Rgb::splat(0.0), Rgb::splat(0.4)));
        }
        other => panic!("{other:?}"),
    }
    assert!(m.textures().len() == 1, "the roughness texture is one of the material's textures");
}

#[test]
fn roughness_combinations_mitsuba_rejects_are_errors() {
    let e = error(r#"<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/></bsdf>"#);
    assert!(e.contains("both 'alpha_u' and 'alpha_v'"), "{e}");
    let e = error(
        r#"<bsdf type="roughconductor"><float name="alpha" value="0.1"/>
           <float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.2"/></bsdf>"#,
    );
    assert!(e.contains("either 'alpha' or"), "{e}");
    let e = error(
        r#"<bsdf type="roughplastic"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.2"/></bsdf>"#,
    );
    assert!(e.contains("anisotropic"), "{e}");
    let e = error(r#"<bsdf type="roughplastic"><texture name="alpha" type="checkerboard"/></bsdf>"#);
    assert!(e.contains("must be a <float>"), "{e}");
}

#[test]
fn nonlinear_pplastic_and_polarizer() {
    match model(r#"<bsdf type="roughplastic"><boolean name="nonlinear" value="true"/></bsdf>"#) {
        MaterialModel::Plastic(PlasticDesc { nonlinear: true, roughness: Some(_), .. }) => {}
        other => panic!("{other:?}"),
    }
    match model(r#"<bsdf type="plastic"/>"#) {
        MaterialModel::Plastic(PlasticDesc { nonlinear: false, roughness: None, .. }) => {}
        other => panic!("{other:?}"),
    }
    match model(r#"<bsdf type="pplastic"><rgb name="diffuse_reflectance" value="0.05, 0.03, 0.1"/></bsdf>"#) {
        MaterialModel::PPlastic(PPlasticDesc { eta, roughness, specular, .. }) => {
            assert!((eta - 1.49 / 1.000277).abs() < 1e-6, "polypropylene in air: {eta}");
            assert_eq!(roughness, Roughness::isotropic(MicrofacetKind::Beckmann, 0.1));
            assert_eq!(specular, Rgb::WHITE);
        }
        other => panic!("{other:?}"),
    }
    match model(r#"<bsdf type="polarizer"><spectrum name="theta" value="90"/></bsdf>"#) {
        MaterialModel::Dielectric(DielectricDesc { eta, reflect, transmit, roughness: None, thin: true }) => {
            assert_eq!((eta, reflect, transmit), (1.0, Rgb::BLACK, Rgb::splat(0.5)));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn json_takes_textured_and_anisotropic_alpha_and_a_plain_number() {
    let text = r#"{
      "camera": { "position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40 },
      "film": { "width": 8, "height": 8 },
      "materials": {
        "old": { "type": "conductor", "metal": "Au", "alpha": 0.2 },
        "brushed": { "type": "conductor", "metal": "a-C", "alpha": 0.05, "alpha_v": { "checkerboard": [0.1, 0.3] }, "distribution": "beckmann" },
        "paint": { "type": "plastic", "diffuse": [0.5, 0.2, 0.1], "alpha": 0.1, "nonlinear": true },
        "pp": { "type": "pplastic", "diffuse": 0.2 }
      },
      "shapes": [ { "type": "sphere", "material": "old" } ]
    }"#;
    let d = glint::formats::json::read(Path::new("s.json"), text).unwrap_or_else(|e| panic!("{e}"));
    let by_name = |n: &str| d.materials[d.material_index(n).unwrap()].model.clone();
    assert_eq!(roughness_of(&by_name("old")), Roughness::isotropic(MicrofacetKind::Ggx, 0.2));
    let r = roughness_of(&by_name("brushed"));
    assert_eq!(r.alpha, ScalarTexture::Value(0.05));
    assert!(matches!(r.alpha_v, Some(ScalarTexture::Texture(TextureDesc::Checkerboard { .. }))), "{r:?}");
    assert!(matches!(by_name("paint"), MaterialModel::Plastic(PlasticDesc { nonlinear: true, .. })));
    assert!(matches!(by_name("pp"), MaterialModel::PPlastic(_)));
    // The description round-trips through serde with the new fields.
    let back: SceneDesc = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_eq!(back, d);
}
