//! Layers a scene file asks for (Mitsuba's `aov` integrator, the JSON film's `aovs`): read
//! into the film description, and kept by every film a session makes, after the layers its
//! caller asks for.

mod common;

use common::scratch::ScratchDir;
use glint::describe::Aov;
use glint::formats::ReadOptions;
use glint::render::Rect;
use glint::session::{FilmOptions, Session};
use std::path::Path;

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film></sensor>"#;

fn open(dir: &Path, name: &str, text: &str) -> Result<Session, String> {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    Session::open(&path, &ReadOptions::default()).map_err(|e| e.to_string())
}

fn aov_scene(aovs: &str) -> String {
    format!(
        "<scene version=\"3.0.0\">\n{SENSOR}\n<integrator type=\"aov\"><string name=\"aovs\" value=\"{aovs}\"/>\
         <integrator type=\"path\"/></integrator>\n</scene>\n"
    )
}

#[test]
fn mitsuba_aov_types_become_the_films_layers() {
    let dir = ScratchDir::new("scene-aovs-mitsuba");
    let s = open(&dir, "a.xml", &aov_scene("dd.y:depth, nn:sh_normal, pos:position, a:albedo, d2:depth")).unwrap();
    assert_eq!(s.description().film.aovs, [Aov::Depth, Aov::Normal, Aov::Position, Aov::Albedo]);
    assert!(s.description().warnings.is_empty(), "{:?}", s.description().warnings);

    // A type glint has no layer for is named in one warning; the others are kept.
    let s = open(&dir, "b.xml", &aov_scene("uv:uv,dd:depth,p:prim_index")).unwrap();
    assert_eq!(s.description().film.aovs, [Aov::Depth]);
    let w = &s.description().warnings;
    assert!(w.len() == 1 && w[0].starts_with(&format!("{}:4:", dir.join("b.xml").display())), "{w:?}");
    assert!(w[0].contains("uv:uv") && w[0].contains("p:prim_index"), "{w:?}");

    // An entry that is not name:type is an error naming the file and line.
    let e = open(&dir, "c.xml", &aov_scene("depth")).err().expect("an error");
    assert!(e.contains("c.xml:4:") && e.contains("not name:type") && !e.contains('\n'), "{e}");
}

#[test]
fn json_films_name_their_layers() {
    let dir = ScratchDir::new("scene-aovs-json");
    let scene = |film: &str| {
        format!(
            r#"{{"camera": {{"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40}},
  "film": {film}, "sampler": {{"spp": 1}}, "materials": {{}}}}"#
        )
    };
    let s = open(&dir, "a.json", &scene(r#"{"width": 8, "height": 6, "aovs": ["position", "albedo"]}"#)).unwrap();
    assert_eq!(s.description().film.aovs, [Aov::Position, Aov::Albedo]);
    let e = open(&dir, "b.json", &scene(r#"{"width": 8, "height": 6, "aovs": ["normals"]}"#)).err().expect("an error");
    assert!(e.contains("b.json") && e.contains("normals"), "{e}");
}

#[test]
fn films_keep_the_requested_layers_then_the_scenes() {
    let dir = ScratchDir::new("scene-aovs-film");
    let s = open(&dir, "a.xml", &aov_scene("dd:depth,nn:sh_normal")).unwrap();
    let film = |requested: &[Aov]| {
        let opts = FilmOptions { pass_spp: None, region: Some(Rect::full(8, 6)), aovs: requested.to_vec() };
        s.new_film(&opts).unwrap().aovs().to_vec()
    };
    assert_eq!(film(&[]), [Aov::Depth, Aov::Normal]);
    assert_eq!(film(&[Aov::Albedo, Aov::Normal]), [Aov::Albedo, Aov::Normal, Aov::Depth]);
    assert_eq!(s.film_aovs(&[Aov::Spp]), [Aov::Spp, Aov::Depth, Aov::Normal]);
}
