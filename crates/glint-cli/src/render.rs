//! `glint render` and `glint resume`: open the scene through a session, apply the command
//! line's overrides as edits of its description, check every output before any sample is
//! taken, render passes into a film (with time limit, checkpoints, previews and Ctrl-C),
//! and write the image, its layers and the film.

use crate::commands::{CliError, RenderArgs, ResumeArgs, RunArgs};
use crate::progress::ProgressBar;
use crate::signals;
use glint::denoise::{with_guides, Denoiser};
use glint::preview::{film_spp, FilmSink, PreviewServer, TevSink};
use glint::render::{Adaptive, Film};
use glint::session::{
    check_output, layer_names, output_files, FilmOptions, Outputs, RenderControl, RenderReport, Session,
};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use std::time::{Duration, Instant};

pub fn render_cmd(a: RenderArgs) -> Result<(), CliError> {
    // Without -o the image goes next to the scene, named after it (the summary says where).
    let output = a.output.clone().unwrap_or_else(|| a.scene.scene.with_extension("png"));
    glint::io::image_io::ImageFormat::from_path(&output)?;
    if a.adaptive && a.passes.is_some() {
        return Err("--adaptive cannot be combined with --passes (its decisions need every earlier pass)".into());
    }
    if a.adaptive && !(a.adaptive_threshold > 0.0 && a.adaptive_threshold.is_finite()) {
        return Err(format!("--adaptive-threshold {} must be positive", a.adaptive_threshold).into());
    }
    if a.pass_spp == Some(0) {
        return Err("--pass-spp must be at least 1".into());
    }
    check_run_args(&a.run)?;
    // Found before anything is rendered: a missing denoiser is one line, and no output.
    let denoiser = if a.denoise { Some(Denoiser::load(None)?) } else { None };
    set_threads(a.threads, a.quiet)?;
    let start = Instant::now();
    let mut session = a.scene.open()?;
    session.set_overrides(&a.overrides())?;
    let aovs = session.film_aovs(&with_guides(&a.aov, a.denoise));
    let desc = session.description();
    if let Some(c) = &a.crop {
        if c.x1 > desc.film.width || c.y1 > desc.film.height {
            return Err(format!("--crop {c} is outside the {}x{} image", desc.film.width, desc.film.height).into());
        }
    }
    for out in output_files(&output, &layer_names(&aovs, a.denoise)) {
        check_output(&out, desc)?;
    }
    for f in a.run.checkpoint.iter().chain(&a.run.film_out) {
        check_output(f, desc)?;
    }
    if !a.quiet {
        for w in &desc.warnings {
            eprintln!("glint: warning: {w}");
        }
    }
    let film = session.new_film(&FilmOptions { pass_spp: a.pass_spp, region: a.crop, aovs })?;
    if let Some(p) = &a.passes {
        if p.end > film.pass_count() {
            return Err(format!("--passes {}..{}: the render has {} passes", p.start, p.end, film.pass_count()).into());
        }
    }
    let adaptive =
        a.adaptive.then_some(Adaptive { threshold: a.adaptive_threshold, min_passes: a.adaptive_min_passes });
    let job =
        Job { scene_name: a.scene.scene.display().to_string(), output, run: a.run.clone(), quiet: a.quiet, denoiser };
    run(session, film, a.passes.clone(), adaptive, start, &job)
}

pub fn resume_cmd(a: ResumeArgs) -> Result<(), CliError> {
    check_run_args(&a.run)?;
    set_threads(a.threads, a.quiet)?;
    let start = Instant::now();
    let resumed = Session::resume_job(&a.from)?;
    let (mut session, mut film) = (resumed.session, resumed.film);
    let output = match (a.output, resumed.job.output) {
        (Some(o), _) => o,
        (None, Some(o)) => o,
        (None, None) => return Err(format!("{}: the checkpoint names no output; give -o", a.from.display()).into()),
    };
    glint::io::image_io::ImageFormat::from_path(&output)?;
    if let Some(spp) = a.spp {
        if spp == 0 || spp > glint::describe::limits::MAX_SPP {
            return Err(format!("--spp {spp} is out of range (1 to {})", glint::describe::limits::MAX_SPP).into());
        }
        film.set_spp(spp).map_err(|e| CliError::from(format!("--spp {spp}: {e}")))?;
        session.edit().sampler.spp = spp;
    }
    for out in output_files(&output, &layer_names(film.aovs(), false)) {
        check_output(&out, session.description())?;
    }
    // A resumed render goes on checkpointing into the file it came from.
    let mut run_args = a.run.clone();
    if run_args.checkpoint.is_none() {
        run_args.checkpoint = Some(a.from.clone());
    }
    let adaptive = session.adaptive();
    let name = session.description().source.as_ref().map_or("scene".to_string(), |p| p.display().to_string());
    let job = Job { scene_name: name, output, run: run_args, quiet: a.quiet, denoiser: None };
    run(session, film, None, adaptive, start, &job)
}

/// What a render writes and says, apart from the scene.
struct Job {
    scene_name: String,
    output: PathBuf,
    run: RunArgs,
    quiet: bool,
    denoiser: Option<Denoiser>,
}

fn check_run_args(r: &RunArgs) -> Result<(), CliError> {
    for (name, v) in [
        ("--time-limit", r.time_limit),
        ("--write-every", r.write_every),
        ("--checkpoint-every", Some(r.checkpoint_every)),
    ] {
        if let Some(v) = v {
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!("{name} {v} must be a positive number of seconds").into());
            }
        }
    }
    for p in r.checkpoint.iter().chain(&r.film_out) {
        if glint::io::image_io::ImageFormat::from_path(p).is_ok() {
            return Err(format!("{}: a film file should not have an image extension", p.display()).into());
        }
    }
    Ok(())
}

fn run(
    mut session: Session,
    mut film: Film,
    passes: Option<std::ops::Range<u32>>,
    adaptive: Option<Adaptive>,
    start: Instant,
    job: &Job,
) -> Result<(), CliError> {
    let world = session.world()?;
    let load_s = start.elapsed().as_secs_f64();
    if !job.quiet && world.lights().is_empty() {
        eprintln!("glint: warning: {}: the scene has no lights: the image will be black", job.scene_name);
    }
    for t in output_files(&job.output, &layer_names(film.aovs(), job.denoiser.is_some())) {
        signals::register_temp(&glint::io::layers::temp_path(&t));
    }
    for f in job.run.checkpoint.iter().chain(&job.run.film_out) {
        signals::register_temp(&glint::io::layers::temp_path(f));
    }
    signals::install();
    // The page's title and tev's image name: the scene file's name.
    let title = Path::new(&job.scene_name).file_name().map_or(job.scene_name.clone(), |n| n.to_string_lossy().into());
    let preview = match &job.run.preview {
        Some(addr) => Some(PreviewServer::start((!addr.is_empty()).then_some(addr.as_str()), &title)?),
        None => None,
    };
    if let Some(p) = &preview {
        eprintln!("glint: preview at {}", p.url());
    }
    let tev = job.run.tev.as_deref().map(|addr| TevSink::connect(addr, &title)).transpose()?;
    let mut sinks: Vec<&dyn FilmSink> = Vec::new();
    sinks.extend(preview.as_ref().map(|p| p as &dyn FilmSink));
    sinks.extend(tev.as_ref().map(|t| t as &dyn FilmSink));

    let requested = passes.clone().unwrap_or(film.passes_done()..film.pass_count());
    let show_bar = !job.quiet && std::io::stderr().is_terminal();
    let bar = ProgressBar::new(film.region().area() * requested.len() as u64, show_bar);
    let control = RenderControl {
        passes,
        adaptive,
        cancel: &signals::CANCEL,
        time_limit: job.run.time_limit.map(Duration::from_secs_f64),
        progress: &bar,
        sinks: &sinks,
    };
    // What a checkpoint records is fixed for the whole render: work it out once.
    session.set_adaptive(adaptive);
    session.set_schedule(job.run.schedule);
    let meta = session.film_meta(&film, Some(&job.output))?;
    let mut checkpoints = job.run.checkpoint.as_ref().map(|ck| PeriodicWrite::new(ck, job.run.checkpoint_every));
    let mut previews = job.run.write_every.map(|every| PeriodicWrite::new(&job.output, every));
    let target = film.spp();
    let report = session.render(&mut film, &control, &mut |film: &Film| {
        bar.set_spp(film_spp(film), target);
        if let (Some(ck), Some(w)) = (&job.run.checkpoint, &mut checkpoints) {
            w.attempt(&bar, job.quiet, || glint::render::write_film(ck, film, &meta));
        }
        if let Some(w) = &mut previews {
            w.attempt(&bar, job.quiet, || Outputs::of_film(film).write(&job.output));
        }
        Ok(())
    })?;
    bar.finish();
    if let (Some(p), false) = (&preview, job.quiet) {
        let (frames, spent) = p.cost();
        let share = 100.0 * spent.as_secs_f64() / report.stats.seconds.max(1e-9);
        eprintln!(
            "glint: preview: {frames} frames, {:.3} s copying and encoding ({share:.2}% of the render)",
            spent.as_secs_f64()
        );
    }
    if let Some(e) = tev.as_ref().and_then(|t| t.error()) {
        eprintln!("glint: warning: {e}");
    }
    finish(&film, &meta, &report, load_s, job)
}

/// A write repeated during the render (a checkpoint, the image so far). One that fails (a
/// full disk, a folder removed) must not end hours of rendering: it is reported once per
/// distinct error, the file on disk stays as it was (writes are atomic), the render goes on
/// and the write is tried again at the next interval.
struct PeriodicWrite {
    file: PathBuf,
    every: f64,
    last: Instant,
    failing: Option<String>,
}

impl PeriodicWrite {
    fn new(file: &Path, every: f64) -> PeriodicWrite {
        PeriodicWrite { file: file.to_path_buf(), every, last: Instant::now(), failing: None }
    }

    fn attempt(&mut self, bar: &ProgressBar, quiet: bool, write: impl FnOnce() -> Result<(), String>) {
        if self.last.elapsed().as_secs_f64() < self.every {
            return;
        }
        let result = write();
        self.last = Instant::now();
        match result {
            Ok(()) => {
                if self.failing.take().is_some() && !quiet {
                    bar.println(&format!("glint: {}: written again", self.file.display()));
                }
            }
            Err(e) => {
                if self.failing.as_ref() != Some(&e) && !quiet {
                    bar.println(&format!(
                        "glint: warning: {e}; rendering goes on (the file keeps its last good state), next try in {} s",
                        self.every
                    ));
                }
                self.failing = Some(e);
            }
        }
    }
}
/// Writes what the render produced and says so; a render stopped by a signal writes the
/// image so far (and the checkpoint) and exits with 128 + the signal's number.
fn finish(
    film: &Film,
    meta: &glint::render::FilmMeta,
    report: &RenderReport,
    load_s: f64,
    job: &Job,
) -> Result<(), CliError> {
    // The preview's Stop button ends the render as Ctrl-C does.
    let interrupted =
        signals::received().filter(|_| report.cancelled).or(report.stopped_by_viewer.then_some(signals::SIGINT));
    let outputs = match &job.denoiser {
        None => Outputs::of_film(film),
        Some(denoiser) => Outputs::of_film(film).denoised(denoiser)?,
    };
    let image = outputs.write(&job.output);
    // The film is written even when the image cannot be (a full disk): it holds the work,
    // and `glint resume` writes the image from it later.
    let checkpoint = job.run.checkpoint.as_ref().map(|ck| glint::render::write_film(ck, film, meta));
    if let Some(f) = &job.run.film_out {
        glint::render::write_film(f, film, meta)?;
    }
    let checkpoint_written = matches!(checkpoint, Some(Ok(())));
    match (image, checkpoint) {
        (Err(e), Some(Ok(()))) => {
            let ck = job.run.checkpoint.as_ref().map_or(String::new(), |p| p.display().to_string());
            return Err(format!("{e} (the film is saved: `glint resume {ck} -o OTHER` writes the image)").into());
        }
        (Err(e), _) => return Err(e.into()),
        // The image is whole; the checkpoint on disk is the last one that could be written.
        (Ok(()), Some(Err(e))) if !job.quiet => {
            eprintln!("glint: warning: {e}; the image is written, the checkpoint keeps its last good state")
        }
        _ => {}
    }
    let spp = film_spp(film);
    let written = {
        let mut w = vec![job.output.display().to_string()];
        w.extend(job.run.checkpoint.iter().filter(|_| checkpoint_written).map(|p| p.display().to_string()));
        w.extend(job.run.film_out.iter().map(|p| p.display().to_string()));
        w.join(", ")
    };
    if let Some(sig) = interrupted {
        if !job.quiet {
            let how = if report.stopped_by_viewer { "stopped from the preview" } else { "interrupted" };
            eprintln!("glint: {how} at {spp} of {} spp: wrote {written}", film.spp());
        }
        return Err(CliError { message: String::new(), code: signals::exit_code(sig) });
    }
    if !job.quiet {
        let s = &report.stats;
        let r = film.region();
        let stop = if report.timed_out {
            format!(" (time limit reached at {spp} of {} spp)", film.spp())
        } else {
            String::new()
        };
        eprintln!(
            "glint: {} {}x{} @ {} spp in {:.3} s (load {:.3} s): {:.1} M rays ({:.2} Mrays/s), {} discarded samples{stop} -> {written}",
            job.scene_name,
            r.width(),
            r.height(),
            spp,
            s.seconds,
            load_s,
            (s.rays + s.shadow_rays) as f64 / 1e6,
            s.mrays_per_second(),
            s.discarded_samples,
        );
    }
    Ok(())
}

/// More threads than this many times the cores only cost memory and scheduling.
const THREADS_PER_CORE_LIMIT: usize = 4;

pub fn set_threads(threads: Option<usize>, quiet: bool) -> Result<(), CliError> {
    let Some(t) = threads else { return Ok(()) };
    if t == 0 {
        return Err("--threads must be at least 1".into());
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let limit = cores * THREADS_PER_CORE_LIMIT;
    let t = if t > limit {
        if !quiet {
            eprintln!(
                "glint: warning: --threads {t} is more than {THREADS_PER_CORE_LIMIT}x the {cores} cores; using {limit}"
            );
        }
        limit
    } else {
        t
    };
    rayon::ThreadPoolBuilder::new().num_threads(t).build_global().map_err(|e| CliError::from(e.to_string()))
}
