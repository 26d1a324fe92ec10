//! Scenes: descriptions as parsed from files (native JSON, Mitsuba XML), the builder that
//! turns any description into a render-ready [`Scene`], and that scene.

mod builder;
pub mod json;
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
}

/// Loads a scene file, choosing the format by extension (`.json`; `.xml` for Mitsuba 3).
pub fn load(path: &Path, opts: &LoadOptions) -> Result<LoadedScene, String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    match ext.as_str() {
        "json" => json::load(path, &text, opts),
        _ => Err(format!("{}: unknown scene format (expected .json)", path.display())),
    }
}
