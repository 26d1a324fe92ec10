//! Bad input gets one clear line naming the file (and line, where there is one), a non-zero
//! exit, no panic, and no output file.

use std::path::{Path, PathBuf};
use std::process::Command;

struct Fixture {
    dir: PathBuf,
}

impl Fixture {
    fn new(name: &str) -> Fixture {
        let dir = std::env::temp_dir().join(format!("glint-bad-input-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Fixture { dir }
    }
    fn write(&self, name: &str, content: &[u8]) -> PathBuf {
        let p = self.dir.join(name);
        std::fs::write(&p, content).unwrap();
        p
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Runs `glint args...`, expects failure, returns stderr.
fn fails(args: &[&str], out: &Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_glint")).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success(), "expected failure for {args:?}, stderr: {stderr}");
    assert!(!stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"), "panic for {args:?}: {stderr}");
    assert!(!out.exists(), "an output file was written for {args:?}");
    // No half-written temporary files either.
    if let Some(dir) = out.parent().filter(|d| d.is_dir()) {
        for e in std::fs::read_dir(dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            assert!(!name.ends_with(".tmp"), "temporary file {name} left behind");
        }
    }
    stderr
}

fn scene_json(shape: &str, extra_material: &str, film: &str) -> String {
    format!(
        r#"{{
  "camera": {{ "position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40 }},
  "film": {film},
  "materials": {{ "white": {{ "type": "diffuse", "reflectance": 0.5 }} {extra_material} }},
  "shapes": [
    {shape}
  ],
  "lights": [ {{ "type": "point", "position": [0, 3, 3], "intensity": 10 }} ]
}}
"#
    )
}

const FILM: &str = r#"{ "width": 8, "height": 8 }"#;

fn render_args<'a>(scene: &'a str, out: &'a str) -> Vec<&'a str> {
    vec!["render", scene, "-o", out, "--spp", "1", "--quiet"]
}

#[test]
fn missing_scene_file() {
    let f = Fixture::new("missing");
    let out = f.dir.join("o.png");
    let e = fails(&render_args("no-such-scene.json", out.to_str().unwrap()), &out);
    assert!(e.contains("no-such-scene.json"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
}

#[test]
fn malformed_json_names_line() {
    let f = Fixture::new("malformed");
    let s = f.write("s.json", b"{\n  \"camera\": {\n    \"position\": [0, 0, 5,\n  }\n}\n");
    let out = f.dir.join("o.png");
    let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
    assert!(e.contains("s.json:4:"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
}

#[test]
fn unknown_field_names_line() {
    let f = Fixture::new("field");
    let s =
        f.write("s.json", scene_json(r#"{ "type": "sphere", "radus": 1, "material": "white" }"#, "", FILM).as_bytes());
    let out = f.dir.join("o.png");
    let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
    assert!(e.contains("s.json:") && e.contains("radus"), "{e}");
}

#[test]
fn unknown_material_names_file_and_line() {
    let f = Fixture::new("material");
    let s = f.write("s.json", scene_json(r#"{ "type": "sphere", "material": "chrome" }"#, "", FILM).as_bytes());
    let out = f.dir.join("o.png");
    let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
    assert!(e.contains("s.json:6:") && e.contains("chrome"), "{e}");
}

#[test]
fn truncated_and_out_of_range_obj() {
    let f = Fixture::new("obj");
    f.write("trunc.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
    f.write("range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    f.write("nan.obj", b"v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
    for (file, line) in [("trunc.obj", 4), ("range.obj", 4), ("nan.obj", 2)] {
        let shape = format!(r#"{{ "type": "obj", "file": "{file}", "material": "white" }}"#);
        let s = f.write("s.json", scene_json(&shape, "", FILM).as_bytes());
        let out = f.dir.join("o.png");
        let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
        assert!(e.contains(&format!("{file}:{line}:")), "{file}: {e}");
        assert_eq!(e.trim().lines().count(), 1, "{e}");
    }
}

#[test]
fn truncated_and_out_of_range_ply() {
    let f = Fixture::new("ply");
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let mut body = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        body.extend_from_slice(&v.to_le_bytes());
    }
    let mut good = header.as_bytes().to_vec();
    good.extend_from_slice(&body);
    good.push(3);
    let mut range = good.clone();
    for i in [0i32, 1, 5] {
        range.extend_from_slice(&i.to_le_bytes());
    }
    let truncated = good[..good.len() - 20].to_vec();
    f.write("range.ply", &range);
    f.write("trunc.ply", &truncated);
    for (file, needle) in [("range.ply", "vertex 5"), ("trunc.ply", "truncated")] {
        let shape = format!(r#"{{ "type": "ply", "file": "{file}", "material": "white" }}"#);
        let s = f.write("s.json", scene_json(&shape, "", FILM).as_bytes());
        let out = f.dir.join("o.png");
        let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
        assert!(e.contains(file) && e.contains(needle), "{file}: {e}");
    }
}

#[test]
fn missing_mesh_file() {
    let f = Fixture::new("nomesh");
    let s = f.write(
        "s.json",
        scene_json(r#"{ "type": "obj", "file": "gone.obj", "material": "white" }"#, "", FILM).as_bytes(),
    );
    let out = f.dir.join("o.png");
    let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
    assert!(e.contains("gone.obj"), "{e}");
}

#[test]
fn zero_and_absurd_resolutions() {
    let f = Fixture::new("res");
    let sphere = r#"{ "type": "sphere", "material": "white" }"#;
    for film in [r#"{ "width": 0, "height": 8 }"#, r#"{ "width": 1000000, "height": 1000000 }"#] {
        let s = f.write("s.json", scene_json(sphere, "", film).as_bytes());
        let out = f.dir.join("o.png");
        let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
        assert!(e.contains("s.json") && e.contains("resolution"), "{e}");
    }
    let s = f.write("ok.json", scene_json(sphere, "", FILM).as_bytes());
    let out = f.dir.join("o.png");
    let e = fails(&["render", s.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", "0"], &out);
    assert!(e.contains("resolution"), "{e}");
}

#[test]
fn degenerate_transforms_are_refused_in_one_line() {
    let f = Fixture::new("scale");
    for scale in ["1e-40", "1e38", "[1, 1e-25, 1]"] {
        let shape = format!(r#"{{ "type": "cube", "material": "white", "transform": [ {{ "scale": {scale} }} ] }}"#);
        let s = f.write("s.json", scene_json(&shape, "", FILM).as_bytes());
        let out = f.dir.join("o.png");
        let e = fails(&render_args(s.to_str().unwrap(), out.to_str().unwrap()), &out);
        assert!(e.contains("s.json:") && e.contains("degenerate") && e.trim().lines().count() == 1, "{scale}: {e}");
    }
    // Large and small scales within range render.
    for scale in ["1e-6", "1e6"] {
        let shape = format!(r#"{{ "type": "cube", "material": "white", "transform": [ {{ "scale": {scale} }} ] }}"#);
        let s = f.write("ok.json", scene_json(&shape, "", FILM).as_bytes());
        let out = f.dir.join("ok.png");
        let o = Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(render_args(s.to_str().unwrap(), out.to_str().unwrap()))
            .output()
            .unwrap();
        assert!(o.status.success(), "{scale}: {}", String::from_utf8_lossy(&o.stderr));
    }
}

#[test]
fn bad_flags_and_outputs() {
    let f = Fixture::new("flags");
    let s = f.write("s.json", scene_json(r#"{ "type": "sphere", "material": "white" }"#, "", FILM).as_bytes());
    let s = s.to_str().unwrap();
    let out = f.dir.join("o.png");
    let o = out.to_str().unwrap();
    fails(&["render", s, "-o", o, "--spp", "many"], &out);
    fails(&["render", s, "-o", o, "--bvh", "octree"], &out);
    fails(&["render", s, "-o", o, "--spp", "0"], &out);
    fails(&["render", s, "-o", o, "--threads", "0"], &out);
    let bmp = f.dir.join("o.bmp");
    let e = fails(&["render", s, "-o", bmp.to_str().unwrap()], &bmp);
    assert!(e.contains("o.bmp"), "{e}");
    let nodir = f.dir.join("missing-folder").join("o.png");
    let e = fails(&["render", s, "-o", nodir.to_str().unwrap(), "--quiet"], &nodir);
    assert!(e.contains("missing-folder"), "{e}");
}

#[test]
fn good_scene_renders_and_writes_the_file() {
    let f = Fixture::new("good");
    let s = f.write("s.json", scene_json(r#"{ "type": "sphere", "material": "white" }"#, "", FILM).as_bytes());
    for ext in ["png", "exr", "pfm"] {
        let out = f.dir.join(format!("o.{ext}"));
        let o = Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(["render", s.to_str().unwrap(), "-o", out.to_str().unwrap(), "--spp", "2"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(out.exists());
        // One summary line with time and ray rate, nothing else.
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(stderr.contains("Mrays/s") && stderr.contains("discarded"), "{stderr}");
    }
    // --quiet prints nothing.
    let out = f.dir.join("q.png");
    let o = Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(["render", s.to_str().unwrap(), "-o", out.to_str().unwrap(), "--spp", "1", "--quiet"])
        .output()
        .unwrap();
    assert!(o.status.success() && o.stderr.is_empty() && o.stdout.is_empty());
}

#[test]
fn without_an_output_the_image_goes_next_to_the_scene_and_help_names_every_format() {
    let f = Fixture::new("default-out");
    let s = f.write("box.json", scene_json(r#"{ "type": "sphere", "material": "white" }"#, "", FILM).as_bytes());
    let o =
        Command::new(env!("CARGO_BIN_EXE_glint")).args(["render", s.to_str().unwrap(), "--spp", "1"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let written = f.dir.join("box.png");
    assert!(written.exists(), "{stderr}");
    assert!(stderr.contains(&format!("-> {}", written.display())), "the summary says where: {stderr}");
    let help = Command::new(env!("CARGO_BIN_EXE_glint")).args(["render", "--help"]).output().unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    for format in [".json", ".xml", ".obj", ".ply", "Mitsuba"] {
        assert!(help.contains(format), "render --help names {format}: {help}");
    }
}

/// A Mitsuba scene with several unsupported features: one line each, every one with file and
/// line, then a non-zero exit.
#[test]
fn mitsuba_scene_reports_every_unsupported_feature() {
    let f = Fixture::new("mitsuba-many");
    let scene = f.write(
        "many.xml",
        b"<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<shape type=\"linearcurve\"/>\n<shape type=\"sphere\"><bsdf type=\"velvet\"/></shape>\n<emitter type=\"sunsky\"/>\n</scene>\n",
    );
    let out = f.dir.join("out.png");
    let err = fails(&render_args(scene.to_str().unwrap(), out.to_str().unwrap()), &out);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 3, "{err}");
    for (line, (n, what)) in lines.iter().zip([(3, "linearcurve"), (4, "velvet"), (5, "sunsky")]) {
        assert!(
            line.starts_with("glint: error: ") && line.contains(&format!("many.xml:{n}:")) && line.contains(what),
            "{err}"
        );
    }
}
