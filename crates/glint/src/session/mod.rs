//! The session: the one API every front end uses. A session opens a scene (a file or a
//! description), applies edits to the description, builds the world once (again only after
//! an edit), and renders it.

use crate::build::{build, BuildOptions};
use crate::describe::SceneDesc;
use crate::error::Error;
use crate::formats::{read, ReadOptions};
use crate::integrators::Integrator;
use crate::render::RenderSettings;
use crate::world::World;
use std::path::Path;
use std::sync::Arc;

pub struct Session {
    desc: SceneDesc,
    build_options: BuildOptions,
    world: Option<Arc<World>>,
}

impl Session {
    /// Reads a scene file of any format glint knows.
    pub fn open(path: &Path, read_options: &ReadOptions) -> Result<Session, Error> {
        Ok(Session::from_description(read(path, read_options)?))
    }

    pub fn from_description(desc: SceneDesc) -> Session {
        Session { desc, build_options: BuildOptions::default(), world: None }
    }

    pub fn description(&self) -> &SceneDesc {
        &self.desc
    }

    /// The description, to edit; the world is built again on next use.
    pub fn edit(&mut self) -> &mut SceneDesc {
        self.world = None;
        &mut self.desc
    }

    pub fn build_options(&self) -> BuildOptions {
        self.build_options
    }

    pub fn set_build_options(&mut self, opts: BuildOptions) {
        if opts != self.build_options {
            self.world = None;
        }
        self.build_options = opts;
    }

    /// The render-ready world, built on first use.
    pub fn world(&mut self) -> Result<Arc<World>, Error> {
        if let Some(w) = &self.world {
            return Ok(w.clone());
        }
        let w = Arc::new(build(&self.desc, &self.build_options)?);
        self.world = Some(w.clone());
        Ok(w)
    }

    /// The integrator the description asks for.
    pub fn integrator(&self) -> Integrator {
        Integrator::from(&self.desc.integrator)
    }

    /// Sampling settings from the description (film filter, sampler, spp, seed).
    pub fn render_settings(&self) -> RenderSettings {
        RenderSettings {
            spp: self.desc.sampler.spp,
            seed: self.desc.sampler.seed,
            filter: self.desc.film.filter,
            sampler: self.desc.sampler.kind,
            ..RenderSettings::default()
        }
    }
}
