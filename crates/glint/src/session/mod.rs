//! The session: the one API every front end uses. A session opens a scene (a file or a
//! description), applies edits to the description, builds the world once (again only after
//! an edit), and renders passes of samples into a [`Film`], which it can stop, continue,
//! save and restore.
//!
//! ```no_run
//! use glint::formats::ReadOptions;
//! use glint::render::{Film, Silent};
//! use glint::session::{FilmOptions, RenderControl, Session};
//! use std::sync::atomic::AtomicBool;
//!
//! # fn main() -> Result<(), glint::Error> {
//! let mut session = Session::open("scenes/cornell-box.json".as_ref(), &ReadOptions::default())?;
//! session.edit().sampler.spp = 64;
//! let mut film = session.new_film(&FilmOptions::default())?;
//!
//! // Render the first 8 passes (of 1 sample each, the default), then stop.
//! let cancel = AtomicBool::new(false);
//! let control = RenderControl { passes: Some(0..8), ..RenderControl::new(&cancel, &Silent) };
//! session.render(&mut film, &control, &mut |_film| Ok(()))?;
//! println!("{} of {} passes", film.passes_done(), film.pass_count());
//!
//! // Save the film, restore it, and continue to the end: the image is bit-identical to one
//! // rendered in one go. Setting `cancel` from another thread (a Ctrl-C handler) stops the
//! // render after the current pass and keeps what is done.
//! session.save_film("cornell.film".as_ref(), &film, None)?;
//! let (mut session, mut film) = Session::resume("cornell.film".as_ref())?;
//! session.render(&mut film, &RenderControl::new(&cancel, &Silent), &mut |_film| Ok(()))?;
//! glint::io::write_image(&film.image(), "cornell.png".as_ref())?;
//! # Ok(())
//! # }
//! ```

// Crate-visible for `edit::resolve_param_name` (gradient code names parameters too).
pub(crate) mod edit;
mod files;
mod gradient;
mod job;
mod outputs;
mod overrides;

pub use edit::{Param, ParamValue};
pub use files::SceneFile;
pub use job::{RenderJob, JOB_VERSION};
pub use outputs::{check_output, layer_channels, layer_names, output_files, Outputs, NOISY_LAYER};
pub use overrides::{integrator_name, integrator_names, Overrides};

use crate::assemble::{build_cached, BuildOptions, MeshCache, WorldLayout};
use crate::error::{Error, SourceLoc};
use crate::formats::{read, ReadOptions};
use crate::integrators::Integrator;
use crate::materials::SceneDesc;
use crate::preview::{film_spp, FilmSink, RenderProgress};
use crate::render::{
    read_film, render_passes, write_film, Adaptive, Aov, ContentHash, Film, FilmMeta, PassRequest, Progress, Rect,
    RenderSettings, RenderStats, Schedule,
};
use crate::world::World;
use files::with_side_files;
use overrides::OverridableSettings;
use std::collections::BTreeSet;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The samples per pass when none is asked for. The image does not depend on the pass size
/// (the film's sums are exact), so one sample keeps passes short (Ctrl-C, time limits,
/// previews and adaptive sampling act after each pass) at a measured cost under 3%
/// (BENCHMARKS.md).
pub const DEFAULT_PASS_SPP: u32 = 1;

/// What a new film holds.
#[derive(Clone, Debug, Default)]
pub struct FilmOptions {
    /// Samples per pass (default [`DEFAULT_PASS_SPP`]).
    pub pass_spp: Option<u32>,
    /// The pixels to render (default: all).
    pub region: Option<Rect>,
    /// Layers beside the image; the film also keeps those the scene asks for
    /// ([`Session::film_aovs`]).
    pub aovs: Vec<Aov>,
}

/// How far a call to [`Session::render`] goes.
pub struct RenderControl<'a> {
    /// Passes to render (default: every pass the film lacks, from the first it lacks).
    pub passes: Option<Range<u32>>,
    pub adaptive: Option<Adaptive>,
    /// Set (by a signal handler, say) to stop; the pass under way is dropped.
    pub cancel: &'a AtomicBool,
    /// No pass starts after this.
    pub time_limit: Option<Duration>,
    pub progress: &'a dyn Progress,
    /// Live views fed after each pass (the browser preview, tev); one asking to stop stops
    /// the render as `cancel` does.
    pub sinks: &'a [&'a dyn FilmSink],
}

impl<'a> RenderControl<'a> {
    pub fn new(cancel: &'a AtomicBool, progress: &'a dyn Progress) -> RenderControl<'a> {
        RenderControl { passes: None, adaptive: None, cancel, time_limit: None, progress, sinks: &[] }
    }
}

/// Why a render stopped, and what it did.
#[derive(Clone, Debug, Default)]
pub struct RenderReport {
    pub passes: Range<u32>,
    pub cancelled: bool,
    /// Stopped by a live view's Stop button (then `cancelled` too).
    pub stopped_by_viewer: bool,
    pub timed_out: bool,
    pub stats: RenderStats,
}

pub struct Session {
    desc: SceneDesc,
    build_options: BuildOptions,
    world: Option<Arc<World>>,
    /// Meshes (with their BVHs) of earlier builds, so a build after an edit builds only
    /// what changed.
    cache: MeshCache,
    /// Where the description's entities are in the built world (for in-place edits).
    layout: Option<WorldLayout>,
    /// Shapes whose transform was edited: traced through it rather than baked.
    instanced: BTreeSet<usize>,
    /// Adaptive settings of the film being rendered (stored in its checkpoints).
    adaptive: Option<Adaptive>,
    /// How paths are scheduled (speed only: the image is the same bits).
    schedule: Schedule,
    /// The scene's own values of what overrides change, while overrides apply.
    own_settings: Option<OverridableSettings>,
}

impl Session {
    /// Reads a scene file of any format glint knows.
    pub fn open(path: &Path, read_options: &ReadOptions) -> Result<Session, Error> {
        Ok(Session::from_description(read(path, read_options)?))
    }

    pub fn from_description(desc: SceneDesc) -> Session {
        Session {
            desc,
            build_options: BuildOptions::default(),
            world: None,
            cache: MeshCache::default(),
            layout: None,
            instanced: BTreeSet::new(),
            adaptive: None,
            schedule: Schedule::default(),
            own_settings: None,
        }
    }

    /// Applies a front end's overrides to the description for the renders that follow. Each
    /// call starts from the scene's own settings, so what an earlier call overrode and this
    /// one does not is the scene's again; overrides that cannot apply change nothing. The
    /// world is built again only when its camera or light selection changes.
    pub fn set_overrides(&mut self, overrides: &Overrides) -> Result<(), Error> {
        let own = self.own_settings.clone().unwrap_or_else(|| OverridableSettings::of(&self.desc));
        let wanted = overrides.applied_to(&own)?;
        if wanted.world_differs(&OverridableSettings::of(&self.desc)) {
            self.world = None;
        }
        wanted.store(&mut self.desc);
        self.own_settings = Some(own);
        Ok(())
    }

    /// How the render schedules paths: one at a time or many in flight. The image is the
    /// same bits either way.
    pub fn set_schedule(&mut self, schedule: Schedule) {
        self.schedule = schedule;
    }

    pub fn description(&self) -> &SceneDesc {
        &self.desc
    }

    /// The description, to edit; the world is built again on next use (from the cached
    /// meshes where they are unchanged). The edited description, overrides included, is
    /// the scene's own from then on.
    pub fn edit(&mut self) -> &mut SceneDesc {
        self.world = None;
        self.own_settings = None;
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
        let built = build_cached(&self.desc, &self.build_options, &mut self.cache, &self.instanced)?;
        let w = Arc::new(built.world);
        self.world = Some(w.clone());
        self.layout = Some(built.layout);
        Ok(w)
    }

    /// The integrator the description asks for.
    pub fn integrator(&self) -> Integrator {
        self.desc.integrator.clone()
    }

    /// Sampling settings from the description (film filter, sampler, spp, seed).
    pub fn render_settings(&self) -> RenderSettings {
        RenderSettings {
            spp: self.desc.sampler.spp,
            seed: self.desc.sampler.seed,
            filter: self.desc.film.filter,
            sampler: self.desc.sampler.kind,
            schedule: self.schedule,
            ..RenderSettings::default()
        }
    }

    /// An empty film for this scene's resolution and samples per pixel, with the layers
    /// [`Session::film_aovs`] gives for `opts.aovs`.
    pub fn new_film(&self, opts: &FilmOptions) -> Result<Film, Error> {
        let (w, h) = (self.desc.film.width, self.desc.film.height);
        let region = opts.region.unwrap_or(Rect::full(w, h));
        let pass_spp = opts.pass_spp.unwrap_or(DEFAULT_PASS_SPP);
        let aovs = self.film_aovs(&opts.aovs);
        // A film the scene's own numbers cannot make (a NaN filter width, say) is the scene's
        // error, reported at its film.
        Film::with_filter(w, h, region, pass_spp, self.desc.sampler.spp, &aovs, self.desc.film.filter)
            .map_err(|e| Error::at(&self.desc.film.loc, e))
    }

    /// The layers a film of this scene keeps when `requested` are asked for: those, then
    /// the scene's own (its film's `aovs`) that are not among them. Every front end's film
    /// (CLI, Python, a render farm's workers) gets the same list, so their films merge.
    pub fn film_aovs(&self, requested: &[Aov]) -> Vec<Aov> {
        let mut aovs = requested.to_vec();
        for a in &self.desc.film.aovs {
            if !aovs.contains(a) {
                aovs.push(*a);
            }
        }
        aovs
    }

    /// Renders passes into `film` until the requested passes are in, the time is up or
    /// `cancel` is set; `after_pass` runs after each pass (checkpoints and previews).
    pub fn render(
        &mut self,
        film: &mut Film,
        control: &RenderControl,
        after_pass: &mut dyn FnMut(&Film) -> Result<(), Error>,
    ) -> Result<RenderReport, Error> {
        let world = self.world()?;
        let integrator = self.integrator();
        let settings = self.render_settings();
        self.adaptive = control.adaptive;
        let start = Instant::now();
        let first = film.passes_done();
        let passes = control.passes.clone().unwrap_or(first..film.pass_count());
        let mut report = RenderReport { passes: passes.start..passes.start, ..Default::default() };
        for sink in control.sinks {
            sink.started(film);
        }
        for pass in passes.clone() {
            if control.cancel.load(Ordering::Relaxed) {
                report.cancelled = true;
                break;
            }
            if control.sinks.iter().any(|s| s.stop_requested()) {
                report.cancelled = true;
                report.stopped_by_viewer = true;
                break;
            }
            if control.time_limit.is_some_and(|t| start.elapsed() >= t) {
                report.timed_out = true;
                break;
            }
            let job = PassJob { world: &world, integrator: &integrator, settings: &settings, control };
            let cancelled = job.fill_in(film, pass, &mut report.stats)?;
            if cancelled {
                report.cancelled = true;
                break;
            }
            report.passes.end = pass + 1;
            if !control.sinks.is_empty() {
                let progress = render_progress(film, &report, passes.end, start, "rendering");
                for sink in control.sinks {
                    sink.pass_done(film, &progress);
                }
            }
            after_pass(film)?;
        }
        report.stats.seconds = start.elapsed().as_secs_f64();
        if !control.sinks.is_empty() {
            let state = if report.cancelled { "stopped" } else { "done" };
            let progress = render_progress(film, &report, passes.end, start, state);
            for sink in control.sinks {
                sink.finished(film, &progress);
            }
        }
        Ok(report)
    }

    /// A hash of everything the image depends on: the description and the bytes of every
    /// file it reads. A checkpoint of a changed scene is refused by it.
    pub fn scene_hash(&self) -> Result<u64, Error> {
        let mut h = ContentHash::new();
        h.update(serde_json::to_string(&self.desc).expect("a description serialises").as_bytes());
        // A missing side file is hashed as absent (its reader goes on without it).
        for file in with_side_files(&self.desc.files())? {
            match &file.bytes {
                Some(b) => {
                    h.update(&(b.len() as u64).to_le_bytes());
                    h.update(b);
                }
                None => h.update(&u64::MAX.to_le_bytes()),
            }
        }
        Ok(h.finish())
    }

    /// The files building the world reads (meshes and their material libraries, textures,
    /// environment maps), each once, with their bytes: not the scene file and its
    /// includes, whose content the description holds. With the description, what a render
    /// farm ships to its workers.
    pub fn build_files(&self) -> Result<Vec<SceneFile>, Error> {
        with_side_files(&self.desc.build_inputs())
    }

    /// The job a film of this session records.
    pub fn job(&self, film: &Film, output: Option<&Path>) -> RenderJob {
        RenderJob {
            version: JOB_VERSION,
            desc: self.desc.clone(),
            bvh_split: self.build_options.bvh_split,
            spp: film.spp(),
            pass_spp: film.pass_spp(),
            aovs: film.aovs().to_vec(),
            adaptive: self.adaptive,
            output: output.map(Path::to_path_buf),
        }
    }

    /// What a checkpoint of `film` records beside its sums.
    pub fn film_meta(&self, film: &Film, output: Option<&Path>) -> Result<FilmMeta, Error> {
        Ok(FilmMeta { scene_hash: self.scene_hash()?, settings: self.job(film, output).to_json() })
    }

    /// Writes the film and what it was rendered with (atomically), for `resume` and `merge`.
    pub fn save_film(&self, path: &Path, film: &Film, output: Option<&Path>) -> Result<(), Error> {
        write_film(path, film, &self.film_meta(film, output)?).map_err(Error::new)
    }

    /// Sets the adaptive settings that checkpoints of the next render record.
    pub fn set_adaptive(&mut self, adaptive: Option<Adaptive>) {
        self.adaptive = adaptive;
    }

    /// Reads a film written by [`Session::save_film`] and reopens its scene, refusing it if
    /// the scene or any file it reads has changed since.
    pub fn resume(path: &Path) -> Result<(Session, Film), Error> {
        let r = Session::resume_job(path)?;
        Ok((r.session, r.film))
    }

    /// [`Session::resume`], also giving the job the film records (its output, say).
    pub fn resume_job(path: &Path) -> Result<Resumed, Error> {
        let (film, job, hash) = read_film_and_job(path)?;
        let mut s = Session::from_description(job.desc.clone());
        s.build_options = BuildOptions { bvh_split: job.bvh_split };
        s.adaptive = job.adaptive;
        if s.scene_hash()? != hash {
            return Err(Error::at(
                &SourceLoc::file(path),
                "the scene or a file it reads has changed since this film was written",
            ));
        }
        Ok(Resumed { session: s, film, job })
    }

    /// Shapes whose transform was edited in place, traced through it rather than baked:
    /// with the description, what a worker needs to build the same world.
    pub fn instanced_shapes(&self) -> Vec<usize> {
        self.instanced.iter().copied().collect()
    }

    /// Traces these shapes through their transforms (as after an in-place edit of each);
    /// the world is built again on next use.
    pub fn set_instanced_shapes(&mut self, shapes: &[usize]) -> Result<(), Error> {
        let n = self.desc.shapes.len();
        if let Some(bad) = shapes.iter().find(|&&i| i >= n) {
            return Err(Error::new(format!("instanced shape {bad}: the scene has {n} shapes")));
        }
        self.instanced = shapes.iter().copied().collect();
        self.world = None;
        Ok(())
    }

    /// The adaptive settings the film was (or is being) rendered with.
    pub fn adaptive(&self) -> Option<Adaptive> {
        self.adaptive
    }
}

/// A session reopened from a film, the film, and the job it records.
pub struct Resumed {
    pub session: Session,
    pub film: Film,
    pub job: RenderJob,
}

/// A film, its job and its scene hash, with errors that name the file.
pub fn read_film_and_job(path: &Path) -> Result<(Film, RenderJob, u64), Error> {
    let loc = SourceLoc::file(path);
    let (film, meta) = read_film(path).map_err(|e| Error::at(&loc, e))?;
    let job = RenderJob::from_json(&meta.settings).map_err(|e| e.or_at(&loc))?;
    if job.spp != film.spp() || job.pass_spp != film.pass_spp() || job.aovs != film.aovs() {
        return Err(Error::at(&loc, "the film's settings do not match its contents"));
    }
    Ok((film, job, meta.scene_hash))
}

/// Adds films of one render (disjoint passes or regions) into one; refuses films of another
/// scene, other settings, or overlapping work. Returns the sum and its job.
pub fn merge_films(paths: &[PathBuf]) -> Result<(Film, RenderJob, u64), Error> {
    let Some(first) = paths.first() else { return Err(Error::new("no films to merge")) };
    let (mut film, job, hash) = read_film_and_job(first)?;
    for p in &paths[1..] {
        let (other, other_job, other_hash) = read_film_and_job(p)?;
        let loc = SourceLoc::file(p);
        if other_hash != hash {
            return Err(Error::at(&loc, format!("a film of another scene than {}", first.display())));
        }
        if !job.same_render(&other_job) {
            return Err(Error::at(&loc, format!("rendered with other settings than {}", first.display())));
        }
        film.merge(&other).map_err(|e| Error::at(&loc, e))?;
    }
    Ok((film, job, hash))
}

/// How far a render call has come, for live views: `last` is the pass it ends before.
fn render_progress(
    film: &Film,
    report: &RenderReport,
    last: u32,
    start: Instant,
    state: &'static str,
) -> RenderProgress {
    let elapsed = start.elapsed().as_secs_f64();
    let done = report.passes.len() as f64;
    let left = last.saturating_sub(report.passes.end) as f64;
    let s = &report.stats;
    RenderProgress {
        spp: film_spp(film),
        target_spp: film.spp(),
        passes_done: film.passes_done(),
        pass_count: film.pass_count(),
        elapsed,
        eta: (done > 0.0).then(|| elapsed / done * left),
        mrays_per_second: (s.rays + s.shadow_rays) as f64 / elapsed.max(1e-9) / 1e6,
        state,
    }
}

/// What rendering one pass of a session needs.
struct PassJob<'a> {
    world: &'a World,
    integrator: &'a Integrator,
    settings: &'a RenderSettings,
    control: &'a RenderControl<'a>,
}

impl PassJob<'_> {
    /// Renders what pass `pass` lacks: usually the whole region; nothing if the film holds
    /// the pass; only the missing rectangles for a film merged from scattered blocks (a
    /// render farm's checkpoint), each rendered into a film of its own and merged. Returns
    /// whether it was cancelled (a cancelled pass adds nothing, or, when filled in, only
    /// the rectangles finished).
    fn fill_in(&self, film: &mut Film, pass: u32, stats: &mut RenderStats) -> Result<bool, Error> {
        let missing = film.missing(pass);
        let request = PassRequest { passes: pass..pass + 1, adaptive: self.control.adaptive };
        let (cancel, progress) = (self.control.cancel, self.control.progress);
        if missing == [film.region()] {
            let outcome = render_passes(self.world, self.integrator, self.settings, film, &request, cancel, progress)
                .map_err(Error::new)?;
            add_stats(stats, &outcome.stats);
            return Ok(outcome.cancelled);
        }
        if self.control.adaptive.is_some() && !missing.is_empty() {
            return Err(Error::new(format!(
                "pass {pass} is in the film for part of the image only; adaptive sampling cannot fill it in"
            )));
        }
        for region in missing {
            let mut part = Film::with_filter(
                film.width(),
                film.height(),
                region,
                film.pass_spp(),
                film.spp(),
                film.aovs(),
                film.filter(),
            )
            .map_err(Error::new)?;
            let outcome =
                render_passes(self.world, self.integrator, self.settings, &mut part, &request, cancel, progress)
                    .map_err(Error::new)?;
            add_stats(stats, &outcome.stats);
            if outcome.cancelled {
                return Ok(true);
            }
            film.merge(&part).map_err(Error::new)?;
        }
        Ok(false)
    }
}

fn add_stats(total: &mut RenderStats, s: &RenderStats) {
    total.camera_rays += s.camera_rays;
    total.rays += s.rays;
    total.shadow_rays += s.shadow_rays;
    total.discarded_samples += s.discarded_samples;
}
