//! Scene files loaded through the session, as the front ends load them.

use glint::formats::{Define, ReadOptions};
use glint::integrators::Integrator;
use glint::render::RenderSettings;
use glint::session::Session;
use glint::world::World;
use std::path::Path;
use std::sync::Arc;

pub struct Loaded {
    pub world: Arc<World>,
    pub integrator: Integrator,
    pub settings: RenderSettings,
}

/// Reads and builds a scene with `-D` style overrides and, optionally, a new resolution.
pub fn load(path: &Path, defines: &[(&str, &str)], size: Option<(u32, u32)>) -> Result<Loaded, String> {
    let defines = defines.iter().map(|(n, v)| Define { name: n.to_string(), value: v.to_string() }).collect();
    let mut s = Session::open(path, &ReadOptions { defines, camera: None }).map_err(|e| e.to_string())?;
    if let Some((w, h)) = size {
        s.edit().film.width = w;
        s.edit().film.height = h;
    }
    let world = s.world().map_err(|e| e.to_string())?;
    Ok(Loaded { world, integrator: s.integrator(), settings: s.render_settings() })
}
