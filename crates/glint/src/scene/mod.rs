//! Scenes: descriptions as parsed from files (native JSON, Mitsuba XML), the builder that
//! turns any description into a render-ready [`Scene`], and that scene.

mod builder;
pub mod json;
pub mod mitsuba;
mod world;

pub use builder::{Emission, LoadedGroup, SceneBuilder};
pub use world::{Hit, Instance, LightSelection, Scene, ShapeRef, SurfaceInteraction};

use crate::accel::BvhSplit;
use crate::integrators::Integrator;
use crate::render::RenderSettings;
use std::path::Path;

/// Options that the command line can impose on a scene while loading it.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    pub bvh_split: BvhSplit,
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// `-D name=value` overrides of Mitsuba `<default>` values.
    pub defines: Vec<(String, String)>,
}

/// A scene ready to render, with the integrator and sampling settings its file asked for.
pub struct LoadedScene {
    pub scene: Scene,
    pub integrator: Integrator,
    pub settings: RenderSettings,
    /// Things the loader accepted but could not honour exactly (printed by the CLI).
    pub warnings: Vec<String>,
}

/// Loads a scene file, choosing the format by extension (`.json`; `.xml` for Mitsuba 3).
pub fn load(path: &Path, opts: &LoadOptions) -> Result<LoadedScene, String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ext == "obj" || ext == "ply" {
        return load_mesh_as_scene(path, opts);
    }
    if ext == "xml" {
        return mitsuba::load(path, opts);
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    match ext.as_str() {
        "json" => json::load(path, &text, opts),
        "xml" => mitsuba::load(path, opts),
        _ => Err(format!("{}: unknown scene format (expected .json, .xml, .obj or .ply)", path.display())),
    }
}

/// A bare mesh file as a scene: the mesh in grey, lit by a grey sky and a sun, and a camera that
/// frames it from the front (for `glint info mesh.obj` and quick previews).
fn load_mesh_as_scene(path: &Path, opts: &LoadOptions) -> Result<LoadedScene, String> {
    use crate::camera::{Camera, FovAxis};
    use crate::materials::{Material, MaterialKind, Texture};
    use crate::math::{Rgb, Transform, Vec3};
    let mut b = SceneBuilder::new(opts.bvh_split);
    let m = b.add_material(Material::new(
        "grey",
        MaterialKind::Diffuse { reflectance: Texture::Constant(Rgb::splat(0.6)) },
        true,
    ));
    let groups = b.load_mesh_file(path, false)?;
    for g in &groups {
        b.add_mesh_instance(&g.mesh, &Transform::IDENTITY, false, m, None, false)?;
    }
    b.add_constant_environment(Rgb::splat(0.4));
    b.add_directional(Vec3 { x: 1.0, y: -2.0, z: -1.5 }, Rgb::splat(2.5));
    let bounds = groups.iter().fold(crate::math::Aabb::EMPTY, |a, g| a.union(g.mesh.bounds()));
    let centre = bounds.center();
    let radius = bounds.extent().length() * 0.5;
    let eye = centre + Vec3 { x: 0.0, y: 0.0, z: radius * 2.8 };
    let to_world = Transform::look_at(eye, centre, Vec3::Y).ok_or_else(|| format!("{}: empty mesh", path.display()))?;
    let (w, h) = (opts.width.unwrap_or(512), opts.height.unwrap_or(512));
    json::check_resolution(w, h)?;
    let camera = Camera::new(to_world, w, h, 45.0, FovAxis::Y);
    let scene = b.finish(camera, LightSelection::Power)?;
    Ok(LoadedScene {
        scene,
        integrator: Integrator::Path(crate::integrators::PathSettings::default()),
        settings: RenderSettings::default(),
        warnings: Vec::new(),
    })
}
