//! Mitsuba reader features where parsing is the point (what the scene becomes, not how it
//! renders): the search path, scene-level samplers, spectra, serialized meshes, and the
//! report of every unsupported feature at once.

mod common;

use common::load::load;
use common::scratch::ScratchDir;
use glint::describe::{Geometry, LightKind, TextureDesc};
use glint::formats::{Define, ReadOptions};
use glint::materials::{ConductorDesc, DiffuseDesc};
use glint::materials::{MaterialModel, SceneDesc};
use std::path::{Path, PathBuf};

/// A fresh folder for one test's files, removed when the test ends.
fn scratch(name: &str) -> ScratchDir {
    ScratchDir::new(&format!("mitsuba-features-{name}"))
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn read(path: &Path) -> Result<SceneDesc, String> {
    glint::formats::read(path, &ReadOptions { defines: Vec::<Define>::new(), camera: None }).map_err(|e| e.to_string())
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
        MaterialModel::Diffuse(DiffuseDesc { reflectance: TextureDesc::Bitmap { file, .. } }) => {
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
        format!(
            r#"<sampler type="independent" {id}><integer name="sample_count" value="{n}"/><integer name="seed" value="3"/></sampler>"#
        )
    };
    let d = read(&scene("ref.xml", &sampler("id=\"s\"", 7), &format!("<ref id=\"s\"/>{FILM}"))).unwrap();
    assert_eq!((d.sampler.spp, d.sampler.seed), (7, 3));
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let d =
        read(&scene("named.xml", &sampler("id=\"s\"", 5), &format!("<ref name=\"sampler\" id=\"s\"/>{FILM}"))).unwrap();
    assert_eq!(d.sampler.spp, 5);
    // A scene-level film, referred to.
    let film = FILM.replace("<film ", "<film id=\"f\" ");
    let d = read(&scene("film.xml", &film, "<ref id=\"f\"/>")).unwrap();
    assert_eq!((d.film.width, d.film.height), (8, 6));
    // Unreferenced: ignored with a warning naming file and line.
    let d = read(&scene("unused.xml", &sampler("", 7), FILM)).unwrap();
    assert_eq!(d.sampler.spp, 16);
    assert!(
        d.warnings.len() == 1 && d.warnings[0].contains("unused.xml:2:") && d.warnings[0].contains("ignored"),
        "{:?}",
        d.warnings
    );
    // Two samplers for one sensor: an error, as in Mitsuba.
    let e = read(&scene("two.xml", &sampler("id=\"s\"", 7), &format!("<ref id=\"s\"/>\n{}{FILM}", sampler("", 9))))
        .unwrap_err();
    assert!(e.contains("two.xml:5:") && e.contains("only one <sampler>"), "{e}");
}

/// The uniform radiance shape `i` emits.
fn emitted(d: &glint::materials::SceneDesc, i: usize) -> glint::math::Rgb {
    match &d.shapes[i].emission.as_ref().expect("the shape emits").radiance {
        glint::describe::TextureDesc::Constant { color } => *color,
        t => panic!("shape {i} emits a texture: {t:?}"),
    }
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
        MaterialModel::Diffuse(DiffuseDesc { reflectance: TextureDesc::Constant { color } }) => *color,
        other => panic!("{other:?}"),
    };
    close(diffuse(0), [0.776368, 0.779809, 0.776029], 1e-5);
    close(emitted(&d, 0), [20.7108, 10.8546, 2.77115], 1e-5);
    match &d.materials[1].model {
        MaterialModel::Conductor(ConductorDesc { eta, k, .. }) => {
            close(*eta, [0.27, 0.27, 0.27], 0.0);
            // Unbounded: through D65, clamped at 0 only (mi.spectrum_list_to_srgb(..., False, True)).
            close(*k, [3.3887, 2.34904, 1.87516], 1e-5);
        }
        other => panic!("{other:?}"),
    }
    close(emitted(&d, 1), [2.0 * 1.20479, 2.0 * 0.948291, 2.0 * 0.908916], 1e-5);
    close(diffuse(2), [0.3, 0.3, 0.3], 0.0);
    close(emitted(&d, 2), [2.0, 2.0, 2.0], 0.0);
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

/// A tiny writer of Mitsuba's `.serialized` format (versions 3 and 4), for the tests.
mod serialized_writer {
    use std::io::Write;

    pub struct Mesh {
        pub name: &'static str,
        pub positions: Vec<[f64; 3]>,
        pub normals: Option<Vec<[f64; 3]>>,
        pub uvs: Option<Vec<[f64; 2]>>,
        pub colors: bool,
        pub double: bool,
        pub indices: Vec<[u32; 3]>,
    }

    /// The compressed body of one mesh (what follows its 4-byte header).
    pub fn body(m: &Mesh, version: u16, vertex_count: u64, triangle_count: u64) -> Vec<u8> {
        let mut raw = Vec::new();
        let flags = m.normals.is_some() as u32
            | (m.uvs.is_some() as u32) << 1
            | (m.colors as u32) << 3
            | if m.double { 0x2000 } else { 0x1000 };
        raw.extend(flags.to_le_bytes());
        if version == 4 {
            raw.extend(m.name.as_bytes());
            raw.push(0);
        }
        raw.extend(vertex_count.to_le_bytes());
        raw.extend(triangle_count.to_le_bytes());
        let mut put = |v: f64| {
            if m.double {
                raw.extend(v.to_le_bytes())
            } else {
                raw.extend((v as f32).to_le_bytes())
            }
        };
        m.positions.iter().flatten().for_each(|&v| put(v));
        m.normals.iter().flatten().flatten().for_each(|&v| put(v));
        m.uvs.iter().flatten().flatten().for_each(|&v| put(v));
        if m.colors {
            m.positions.iter().flatten().for_each(|_| put(0.25));
        }
        for t in &m.indices {
            t.iter().for_each(|i| raw.extend(i.to_le_bytes()));
        }
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&raw).unwrap();
        z.finish().unwrap()
    }

    /// A whole file: each mesh after its header, then the dictionary of offsets and the count.
    pub fn file(meshes: &[Mesh], version: u16) -> Vec<u8> {
        let mut out = Vec::new();
        let mut offsets = Vec::new();
        for m in meshes {
            offsets.push(out.len() as u64);
            out.extend(0x041Cu16.to_le_bytes());
            out.extend(version.to_le_bytes());
            out.extend(body(m, version, m.positions.len() as u64, m.indices.len() as u64));
        }
        for o in offsets {
            if version == 4 {
                out.extend(o.to_le_bytes());
            } else {
                out.extend((o as u32).to_le_bytes());
            }
        }
        out.extend((meshes.len() as u32).to_le_bytes());
        out
    }

    pub fn quad(name: &'static str, double: bool) -> Mesh {
        Mesh {
            name,
            positions: vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]],
            normals: Some(vec![[0.0, 0.0, 1.0]; 4]),
            uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
            colors: false,
            double,
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    pub fn triangle(name: &'static str) -> Mesh {
        Mesh {
            name,
            positions: vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]],
            normals: None,
            uvs: None,
            colors: true,
            double: false,
            indices: vec![[0, 1, 2]],
        }
    }
}

#[test]
fn serialized_meshes_are_read_by_index() {
    use glint::io::serialized::parse_serialized;
    use serialized_writer::{file, quad, triangle};
    for version in [3u16, 4] {
        let data = file(&[quad("plane", false), triangle("tri"), quad("plane64", true)], version);
        let m = parse_serialized(&data, 0).unwrap();
        assert_eq!((m.positions.len(), m.indices.len()), (4, 2));
        assert_eq!(m.uvs.as_ref().unwrap()[2], [1.0, 1.0]);
        assert_eq!(m.normals.as_ref().unwrap()[0].z, 1.0);
        assert_eq!(m.name, if version == 4 { "plane" } else { "" });
        let t = parse_serialized(&data, 1).unwrap();
        assert_eq!(t.indices, vec![[0, 1, 2]]);
        assert!(t.normals.is_none() && t.uvs.is_none());
        assert_eq!(t.positions[2].y, 3.0);
        let d = parse_serialized(&data, 2).unwrap();
        assert_eq!(d.positions[1].x, 1.0);
        let e = parse_serialized(&data, 3).unwrap_err();
        assert!(e.contains("out of range") && e.contains("3 meshes"), "{e}");
    }
    // Through the scene reader and the builder: shape_index, to_world, face_normals.
    let dir = scratch("serialized");
    std::fs::write(dir.join("m.serialized"), file(&[quad("plane", false), triangle("tri")], 4)).unwrap();
    let p = dir.join("s.xml");
    write(
        &p,
        &format!(
            r#"<scene version="3.0.0">{SENSOR}
<shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_index" value="1"/>
  <transform name="to_world"><translate z="-5"/></transform></shape>
<shape type="serialized"><string name="filename" value="m.serialized"/><boolean name="face_normals" value="true"/></shape>
</scene>"#
        ),
    );
    let d = read(&p).unwrap();
    assert!(matches!(d.shapes[0].geometry, Geometry::MeshFile { shape_index: 1, face_normals: false, .. }));
    assert!(matches!(d.shapes[1].geometry, Geometry::MeshFile { shape_index: 0, face_normals: true, .. }));
    let s = load(&p, &[], None).unwrap();
    assert_eq!(s.world.triangle_count(), 3);
}

/// Every size read from the file is bounded before allocation and the data checked really
/// there: truncated files, lying counts, bad offsets and indices are one-line errors.
#[test]
fn serialized_robustness() {
    use glint::io::serialized::parse_serialized;
    use serialized_writer::{body, file, quad, triangle};
    let data = file(&[quad("plane", false), triangle("tri")], 4);
    // Every truncation, of either mesh: an error, never a panic.
    for n in 0..data.len() {
        for index in [0, 1] {
            if let Ok(m) = parse_serialized(&data[..n], index) {
                // Only cuts inside the dictionary can leave mesh 0 readable.
                assert_eq!((index, m.indices.len()), (0, 2), "prefix {n}");
            }
        }
    }
    let e = parse_serialized(&data[..30], 0).unwrap_err();
    assert!(e.contains("mesh 0"), "{e}");
    // Huge counts with almost no data: refused before any allocation.
    let q = quad("q", false);
    for (v, f) in [(u32::MAX as u64, u32::MAX as u64), (1 << 40, 2), (4, 1 << 33), (50_000_000, 1)] {
        let mut d = vec![0x1C, 0x04, 4, 0];
        d.extend(body(&q, 4, v, f));
        let e = parse_serialized(&d, 0).unwrap_err();
        assert!(e.contains("vertices") && (e.contains("more than") || e.contains("truncated")), "{v} {f}: {e}");
    }
    // A count that fits the deflate bound but is not there: truncated, not a huge buffer.
    let mut d = vec![0x1C, 0x04, 4, 0];
    d.extend(body(&q, 4, 1000, 1));
    let e = parse_serialized(&d, 0).unwrap_err();
    assert!(e.contains("truncated"), "{e}");
    // A dictionary claiming four billion meshes, and one whose offset points past the file.
    let mut d = data.clone();
    let n = d.len();
    d[n - 4..].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = parse_serialized(&d, 7).unwrap_err();
    assert!(e.contains("dictionary"), "{e}");
    let mut d = data.clone();
    d[n - 12..n - 4].copy_from_slice(&u64::MAX.to_le_bytes());
    let e = parse_serialized(&d, 1).unwrap_err();
    assert!(e.contains("past the end"), "{e}");
    // A triangle naming a vertex that does not exist; a wrong magic; version 5.
    let mut bad = triangle("t");
    bad.indices = vec![[0, 1, 3]];
    let e = parse_serialized(&file(&[bad], 4), 0).unwrap_err();
    assert!(e.contains("triangle 0 uses vertex 3"), "{e}");
    let e = parse_serialized(b"\x00\x00\x04\x00rest", 0).unwrap_err();
    assert!(e.contains("format identifier"), "{e}");
    let e = parse_serialized(b"\x1c\x04\x05\x00rest", 0).unwrap_err();
    assert!(e.contains("version 5"), "{e}");
    // Garbage after a valid header: a decompression error.
    let e = parse_serialized(b"\x1c\x04\x04\x00not zlib at all", 0).unwrap_err();
    assert!(e.contains("mesh 0"), "{e}");
}

/// A scene with several unsupported features reports every one, a line each with file and
/// line, then fails; unsupported media features among them (not ignored parameters).
#[test]
fn every_unsupported_feature_is_reported() {
    let dir = scratch("many");
    let p = dir.join("many.xml");
    write(
        &p,
        &format!(
            r#"<scene version="3.0.0">
{SENSOR}
<shape type="linearcurve"/>
<shape type="sphere">
  <bsdf type="velvet"/>
  <medium type="heterogeneous" name="interior"><phase type="rayleigh"/></medium>
</shape>
<emitter type="sunsky"/>
<phase type="hg" id="p"/>
<shape type="sphere"><medium type="homogeneous" name="inside"/></shape>
<shape type="hair"><bsdf type="velvet"/></shape>
<bsdf type="blendbsdf" id="b"/>
<shape type="sphere"><ref id="b"/></shape>
<shape type="sphere"><ref id="b"/></shape>
</scene>"#
        ),
    );
    let e = read(&p).unwrap_err();
    let lines: Vec<&str> = e.lines().collect();
    let expect = [
        (4, "linearcurve"),
        (6, "velvet"),
        (7, "rayleigh"),
        (9, "sunsky"),
        (10, "phase"),
        (11, "'interior' or 'exterior'"),
        (12, "velvet"),
        (12, "hair"),
        (13, "blendbsdf"),
    ];
    assert_eq!(lines.len(), expect.len(), "{e}");
    for ((line, what), got) in expect.iter().zip(&lines) {
        assert!(
            got.contains(&format!("many.xml:{line}:")) && got.contains(what),
            "expected line {line} ({what}): {got}\n{e}"
        );
    }
}

/// A named area emitter at scene level, given to a shape by `<ref id>` (as in Mitsuba's
/// Cornell box scenes); unreferenced it emits nothing, as in Mitsuba.
#[test]
fn area_emitter_by_reference() {
    let dir = scratch("area-ref");
    let p = dir.join("s.xml");
    write(
        &p,
        &format!(
            r#"<scene version="3.0.0">{SENSOR}
<shape type="sphere"><ref id="glow"/></shape>
<emitter type="area" id="glow"><rgb name="radiance" value="2, 3, 4"/></emitter>
</scene>"#
        ),
    );
    let d = read(&p).unwrap();
    assert_eq!(emitted(&d, 0), glint::math::Rgb { r: 2.0, g: 3.0, b: 4.0 });
    assert!(d.lights.is_empty());
}
