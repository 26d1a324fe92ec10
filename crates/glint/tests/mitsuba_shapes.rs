//! Mitsuba's cylinder, shapegroup/instance, orthographic sensor, crop windows and projected
//! lights: what the reader makes of them, and the built world's geometry.

mod common;

use common::scratch::ScratchDir;
use glint::assemble::{build, BuildOptions};
use glint::camera::{CropWindow, Projection};
use glint::describe::{Geometry, LightKind, TextureDesc};
use glint::formats::mitsuba::read_str;
use glint::lights::Light;
use glint::materials::SceneDesc;
use glint::math::{rgb, vec3, Ray, Rgb, Vec3};
use std::path::Path;

fn scratch(name: &str) -> ScratchDir {
    ScratchDir::new(&format!("mitsuba-shapes-{name}"))
}

fn read(dir: &Path, body: &str) -> Result<SceneDesc, String> {
    let text = format!(
        r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film></sensor>
  {body}
</scene>"#
    );
    read_str(&text, &dir.join("scene.xml"), &[]).map_err(|e| e.to_string())
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn instances_share_the_group_meshes_and_compose_transforms() {
    let dir = scratch("instances");
    std::fs::write(dir.join("tri.obj"), TRIANGLE).unwrap();
    let desc = read(
        &dir,
        r#"<shape type="shapegroup" id="g">
             <shape type="obj"><string name="filename" value="tri.obj"/>
               <transform name="to_world"><translate x="1"/></transform></shape>
             <shape type="sphere"><float name="radius" value="0.5"/></shape>
           </shape>
           <shape type="instance"><ref id="g"/></shape>
           <shape type="instance"><ref id="g"/>
             <transform name="to_world"><scale value="2"/><translate z="5"/></transform></shape>"#,
    )
    .unwrap();
    // The group itself draws nothing; each instance draws both shapes.
    assert_eq!(desc.shapes.len(), 4);
    assert_eq!(desc.meshes.len(), 1, "the mesh file is described once");
    assert!(matches!(desc.shapes[0].geometry, Geometry::Instance { mesh: 0 }));
    assert!(matches!(desc.shapes[2].geometry, Geometry::Instance { mesh: 0 }));
    // The second instance: the mesh's own translate, then the instance's scale and translate.
    let m = desc.shapes[2].to_world;
    assert_eq!([m[0][3], m[1][3], m[2][3]], [2.0, 0.0, 5.0]);
    assert_eq!(m[0][0], 2.0);
    let world = build(&desc, &BuildOptions::default()).unwrap();
    assert_eq!(world.meshes().len(), 1, "one BVH for the mesh, placed twice");
    // A ray down onto the second instance's triangle (x in [2, 4], at z = 5).
    let hit = world.intersect(&Ray::new(vec3(2.5, 0.5, 10.0), vec3(0.0, 0.0, -1.0))).unwrap();
    assert!((hit.t - 5.0).abs() < 1e-4, "{}", hit.t);
    // And the second sphere (radius 1 at z = 5) from the side.
    let hit = world.intersect(&Ray::new(vec3(-5.0, 0.0, 5.0), Vec3::X)).unwrap();
    assert!((hit.t - 4.0).abs() < 1e-4, "{}", hit.t);
}

#[test]
fn every_unsupported_instancing_feature_is_reported_in_one_run() {
    let dir = scratch("instance-errors");
    let err = read(
        &dir,
        r#"<shape type="shapegroup" id="g">
             <shape type="sphere"><emitter type="area"/></shape>
             <shape type="shapegroup" id="inner"/>
           </shape>
           <shape type="instance"><ref id="g"/><transform name="to_world"><scale x="-1"/></transform></shape>
           <shape type="instance"/>
           <shape type="instance"><ref id="g"/><bsdf type="diffuse"/></shape>
           <shape type="shapegroup"/>"#,
    )
    .unwrap_err();
    for needle in [
        "cannot emit light",
        "cannot hold another shapegroup",
        "mirrors",
        "exactly one <ref id>",
        "an instance takes no <bsdf>",
        "a shapegroup needs an id",
    ] {
        assert!(err.contains(needle), "missing '{needle}' in:\n{err}");
    }
    assert!(err.lines().all(|l| l.contains("scene.xml:")), "{err}");
}

#[test]
fn cylinder_is_read_with_mitsubas_defaults_and_hit_in_the_world() {
    let dir = scratch("cylinder");
    let desc = read(
        &dir,
        r#"<shape type="cylinder"><float name="radius" value="0.5"/>
             <point name="p1" x="0" y="0" z="2"/></shape>"#,
    )
    .unwrap();
    let Geometry::Cylinder { p0, p1, radius } = desc.shapes[0].geometry else { panic!() };
    assert_eq!((p0, p1, radius), (Vec3::ZERO, vec3(0.0, 0.0, 2.0), 0.5));
    let world = build(&desc, &BuildOptions::default()).unwrap();
    let ray = Ray::new(vec3(3.0, 0.0, 1.5), vec3(-1.0, 0.0, 0.0));
    let hit = world.intersect(&ray).unwrap();
    assert!((hit.t - 2.5).abs() < 1e-5);
    let si = world.interaction(&ray, &hit);
    assert!((si.ng - Vec3::X).length() < 1e-5);
    assert!((si.uv[0] - 0.0).abs() < 1e-5 && (si.uv[1] - 0.75).abs() < 1e-5);
    assert!(world.occluded(&Ray::segment(vec3(3.0, 0.0, 1.5), vec3(-1.0, 0.0, 0.0), 10.0)));
    // Above the open tube: nothing.
    assert!(world.intersect(&Ray::new(vec3(3.0, 0.0, 2.5), vec3(-1.0, 0.0, 0.0))).is_none());
    // A zero radius is a one-line error.
    let err = read(&dir, r#"<shape type="cylinder"><float name="radius" value="0"/></shape>"#)
        .and_then(|d| build(&d, &BuildOptions::default()).map(|_| ()).map_err(|e| e.to_string()))
        .unwrap_err();
    assert!(err.contains("radius") && err.contains("scene.xml:") && !err.contains('\n'), "{err}");
}

#[test]
fn an_emitting_cylinder_is_an_area_light_of_its_area() {
    let dir = scratch("cylinder-light");
    let desc = read(
        &dir,
        r#"<shape type="cylinder"><float name="radius" value="0.5"/><point name="p1" x="0" y="0" z="2"/>
             <emitter type="area"><rgb name="radiance" value="2, 3, 4"/></emitter></shape>"#,
    )
    .unwrap();
    let world = build(&desc, &BuildOptions::default()).unwrap();
    assert_eq!(world.lights().len(), 1);
    assert!(matches!(world.lights()[0], Light::Cylinder { inward: false, .. }));
    let area = 2.0 * std::f32::consts::PI * 0.5 * 2.0;
    assert!((world.lights()[0].area() - area).abs() < 1e-4 * area, "{}", world.lights()[0].area());
    // Seen from outside, light samples come from the side facing the point (outward normals).
    let p = vec3(3.0, 0.0, 1.0);
    for u in [[0.1, 0.3], [0.4, 0.6], [0.8, 0.9]] {
        if let Some(ls) = world.lights()[0].sample_li(p, u) {
            assert!(ls.pdf > 0.0 && ls.wi.x < 0.0 && ls.radiance == rgb(2.0, 3.0, 4.0), "{ls:?}");
        }
    }
}

#[test]
fn textured_area_emitters_are_read() {
    let dir = scratch("textured-emitters");
    let desc = read(
        &dir,
        r#"<texture type="checkerboard" id="tiles"><rgb name="color0" value="0.9"/><rgb name="color1" value="0.1"/></texture>
           <shape type="rectangle"><emitter type="area">
             <texture type="bitmap" name="radiance"><string name="filename" value="glow.png"/></texture></emitter></shape>
           <shape type="sphere"><emitter type="area"><ref name="radiance" id="tiles"/></emitter></shape>
           <shape type="cylinder"><emitter type="area"><texture type="checkerboard" name="radiance"/></emitter></shape>"#,
    )
    .unwrap();
    let radiance = |i: usize| desc.shapes[i].emission.as_ref().unwrap().radiance.clone();
    assert!(matches!(radiance(0), TextureDesc::Bitmap { ref file, .. } if file.ends_with("glow.png")));
    assert!(matches!(radiance(1), TextureDesc::Checkerboard { color0, .. } if color0 == Rgb::splat(0.9)));
    assert!(matches!(radiance(2), TextureDesc::Checkerboard { .. }));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);

    // What glint does not read is one line naming the file and line.
    let one_line = |body: &str, wanted: &str| {
        let err = read(&dir, body)
            .and_then(|d| build(&d, &BuildOptions::default()).map(|_| ()).map_err(|e| e.to_string()))
            .unwrap_err();
        assert!(err.contains(wanted) && err.contains("scene.xml:") && !err.contains('\n'), "{err}");
    };
    one_line(
        r#"<shape type="rectangle"><emitter type="area">
             <texture type="noise" name="radiance"/></emitter></shape>"#,
        "texture plugin 'noise'",
    );
    one_line(
        r#"<shape type="rectangle"><emitter type="area">
             <texture type="bitmap" name="radiance"/></emitter></shape>"#,
        "filename",
    );
    one_line(
        r#"<shape type="rectangle"><emitter type="area">
             <texture type="bitmap" name="radiance"><string name="filename" value="missing.png"/></texture></emitter></shape>"#,
        "missing.png",
    );
    // A mesh attribute the shape does not have (a sphere has none).
    one_line(
        r#"<shape type="sphere"><emitter type="area">
             <texture type="mesh_attribute" name="radiance"><string name="name" value="vertex_color"/></texture>
           </emitter></shape>"#,
        "vertex_color",
    );
}

#[test]
fn orthographic_sensor_and_crop_window_are_read() {
    let dir = scratch("ortho");
    let text = r#"<scene version="3.0.0">
      <sensor type="orthographic"><float name="near_clip" value="0.5"/><float name="far_clip" value="20"/>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="8"/>
          <integer name="crop_offset_x" value="4"/><integer name="crop_width" value="6"/>
          <integer name="crop_offset_y" value="2"/></film></sensor>
      <shape type="sphere"/>
    </scene>"#;
    let desc = read_str(text, &dir.join("scene.xml"), &[]).unwrap();
    assert_eq!(desc.camera.projection, Projection::Orthographic);
    assert_eq!(desc.film.crop, Some(CropWindow { offset_x: 4, offset_y: 2, width: 6, height: 6 }));
    let world = build(&desc, &BuildOptions::default()).unwrap();
    assert_eq!((world.camera().width, world.camera().height), (6, 6));
    // A window past the film's edge is an error naming the film's line.
    let bad = text.replace(r#"name="crop_width" value="6""#, r#"name="crop_width" value="13""#);
    let err = read_str(&bad, &dir.join("scene.xml"), &[]).unwrap_err().to_string();
    assert!(err.contains("crop window") && err.contains("scene.xml:3:"), "{err}");
}

#[test]
fn projector_and_textured_spot_are_read() {
    let dir = scratch("projector");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/mitsuba/assets/texture.png"),
        dir.join("t.png"),
    )
    .unwrap();
    let desc = read(
        &dir,
        r#"<emitter type="projector"><float name="fov" value="30"/><float name="scale" value="2"/>
             <rgb name="irradiance" value="1, 2, 3"/></emitter>
           <emitter type="spot"><texture type="bitmap" name="texture"><string name="filename" value="t.png"/></texture></emitter>
           <shape type="sphere"/>"#,
    )
    .unwrap();
    assert!(matches!(desc.lights[0].light, LightKind::Projector { scale: 2.0, fov_degrees: 30.0, .. }));
    assert!(matches!(desc.lights[1].light, LightKind::TexturedSpot { cutoff_degrees: 20.0, .. }));
    build(&desc, &BuildOptions::default()).unwrap();
    // A constant spot texture is rejected, as by Mitsuba.
    let err = read(&dir, r#"<emitter type="spot"><rgb name="texture" value="0.5"/></emitter>"#).unwrap_err();
    assert!(err.contains("spatially varying"), "{err}");
}

#[test]
fn the_json_format_describes_the_same_features() {
    let dir = scratch("json");
    let text = r#"{
      "camera": { "position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40,
                  "projection": "orthographic", "ortho_half_width": 2 },
      "film": { "width": 16, "height": 8, "crop": [2, 1, 8, 4] },
      "shapes": [ { "type": "cylinder", "p0": [0, 0, -1], "p1": [0, 0, 1], "radius": 0.5 } ],
      "lights": [
        { "type": "projector", "position": [0, 0, 5], "target": [0, 0, 0], "fov": 30, "irradiance": [1, 1, 1] },
        { "type": "spot", "position": [0, 0, 5], "target": [0, 0, 0], "intensity": 3,
          "texture": { "checkerboard": [[1, 0, 0], [0, 1, 0]] } }
      ]
    }"#;
    let desc = glint::formats::json::read(&dir.join("scene.json"), text).unwrap();
    assert_eq!(desc.camera.projection, Projection::Orthographic);
    assert_eq!(desc.film.crop, Some(CropWindow { offset_x: 2, offset_y: 1, width: 8, height: 4 }));
    assert!(matches!(desc.shapes[0].geometry, Geometry::Cylinder { radius: 0.5, .. }));
    assert!(matches!(desc.lights[0].light, LightKind::Projector { fov_degrees: 30.0, .. }));
    assert!(matches!(desc.lights[1].light, LightKind::TexturedSpot { .. }));
    let world = build(&desc, &BuildOptions::default()).unwrap();
    // The view is 4 units wide: a ray from the crop's left edge starts 2 - 2 * 2 * 2/16 from the axis.
    let r = world.camera().generate_ray(0.0, 2.0, [0.5; 2]);
    assert!((r.origin.x.abs() - 1.5).abs() < 1e-4, "{:?}", r.origin);
}

/// A sphere's signed distance (radius 0.3 around the cube's centre) on 9^3 vertices, as a
/// Mitsuba `.vol` file whose bounding box (which Mitsuba ignores) is not the unit cube.
fn sphere_vol(path: &Path) {
    let n = 9;
    let mut b = b"VOL\x03".to_vec();
    for v in [1i32, n, n, n, 1] {
        b.extend(v.to_le_bytes());
    }
    for v in [-5.0f32, -5.0, -5.0, 7.0, 7.0, 7.0] {
        b.extend(v.to_le_bytes());
    }
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = vec3(x as f32, y as f32, z as f32) / (n - 1) as f32 - Vec3::splat(0.5);
                b.extend((p.length() - 0.3).to_le_bytes());
            }
        }
    }
    std::fs::write(path, b).unwrap();
}

#[test]
fn sdfgrid_is_placed_on_the_unit_cube_directly_and_through_instances() {
    let dir = scratch("sdfgrid");
    sphere_vol(&dir.join("ball.vol"));
    let desc = read(
        &dir,
        r#"<shape type="sdfgrid"><string name="filename" value="ball.vol"/>
             <transform name="to_world"><scale value="2"/><translate x="-1" y="-1" z="-1"/></transform></shape>
           <shape type="shapegroup" id="g">
             <shape type="sdfgrid"><string name="filename" value="ball.vol"/>
               <string name="normals" value="analytic"/></shape>
           </shape>
           <shape type="instance"><ref id="g"/>
             <transform name="to_world"><translate x="-0.5" y="-0.5" z="-0.5"/><translate x="5"/></transform></shape>"#,
    )
    .unwrap();
    use glint::describe::SdfNormalsDesc;
    assert!(matches!(desc.shapes[0].geometry, Geometry::SdfGrid { normals: SdfNormalsDesc::Smooth, .. }));
    assert!(matches!(desc.shapes[1].geometry, Geometry::SdfGrid { normals: SdfNormalsDesc::Analytic, .. }));
    let world = build(&desc, &BuildOptions::default()).unwrap();
    assert_eq!(world.sdf_grids().len(), 2);
    // The first: a ball of radius 0.6 at the origin (the file's box is ignored). The ray
    // keeps off the grid lines, where the analytic normal jumps between voxels; between
    // them the coarse grid interpolates the distance within an eighth of a cell (0.25).
    let ray = Ray::new(vec3(-5.0, 0.07, 0.03), Vec3::X);
    let hit = world.intersect(&ray).unwrap();
    assert!((hit.t - 4.405).abs() < 0.03, "{}", hit.t);
    let si = world.interaction(&ray, &hit);
    let n = (ray.at(hit.t)).normalize();
    assert!(si.ng.dot(n) > 0.98 && si.frame.n.dot(n) > 0.98, "{:?} {:?} vs {n:?}", si.ng, si.frame.n);
    assert_eq!(si.uv, [0.0, 0.0]);
    // The instance: radius 0.3 at (5, 0, 0), seen from above.
    let ray = Ray::new(vec3(5.0, 0.0, 5.0), -Vec3::Z);
    let hit = world.intersect(&ray).unwrap();
    assert!((hit.t - 4.7).abs() < 0.03, "{}", hit.t);
    assert!(world.occluded(&ray) && world.intersect_brute_force(&ray).unwrap().t == hit.t);
}
