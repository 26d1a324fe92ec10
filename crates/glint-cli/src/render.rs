//! `glint render` and `glint resume`: open the scene through a session, apply the command
//! line's overrides as edits of its description, check every output before any sample is
//! taken, render passes into a film (with time limit, checkpoints, previews and Ctrl-C),
//! and write the image, its layers and the film.

use crate::commands::{CliError, RenderArgs, ResumeArgs, RunArgs};
use crate::progress::ProgressBar;
use crate::signals;
use glint::denoise::{with_guides, Denoiser};
use glint::render::{Adaptive, Film};
use glint::session::{
    check_output, layer_names, output_files, FilmOptions, Outputs, RenderControl, RenderReport, Session,
};
use std::io::IsTerminal;
use std::path::PathBuf;

use std::time::{Duration, Instant};

pub fn render_cmd(a: RenderArgs) -> Result<(), CliError> {
    glint::io::image_io::ImageFormat::from_path(&a.output)?;
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
    for out in output_files(&a.output, &layer_names(&aovs, a.denoise)) {
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
    let job = Job {
        scene_name: a.scene.scene.display().to_string(),
        output: a.output.clone(),
        run: a.run.clone(),
        quiet: a.quiet,
        denoiser,
    };
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

/// The samples per pixel the film holds (over its region, for the passes it has).
fn film_spp(film: &Film) -> u32 {
    let mut passes: Vec<u32> = film.blocks().iter().flat_map(|b| b.passes.clone()).collect();
    passes.sort_unstable();
    passes.dedup();
    passes.iter().map(|&p| film.pass_samples(p).len() as u32).sum()
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

    let requested = passes.clone().unwrap_or(film.passes_done()..film.pass_count());
    let show_bar = !job.quiet && std::io::stderr().is_terminal();
    let bar = ProgressBar::new(film.region().area() * requested.len() as u64, show_bar);
    let control = RenderControl {
        passes,
        adaptive,
        cancel: &signals::CANCEL,
        time_limit: job.run.time_limit.map(Duration::from_secs_f64),
        progress: &bar,
    };
    // What a checkpoint records is fixed for the whole render: work it out once.
    session.set_adaptive(adaptive);
    session.set_schedule(job.run.schedule);
    let meta = session.film_meta(&film, Some(&job.output))?;
    let (mut last_checkpoint, mut last_preview) = (Instant::now(), Instant::now());
    let target = film.spp();
    let report = session.render(&mut film, &control, &mut |film: &Film| {
        bar.set_spp(film_spp(film), target);
        if let Some(ck) = &job.run.checkpoint {
            if last_checkpoint.elapsed().as_secs_f64() >= job.run.checkpoint_every {
                glint::render::write_film(ck, film, &meta)?;
                last_checkpoint = Instant::now();
            }
        }
        if let Some(every) = job.run.write_every {
            if last_preview.elapsed().as_secs_f64() >= every {
                Outputs::of_film(film).write(&job.output)?;
                last_preview = Instant::now();
            }
        }
        Ok(())
    })?;
    bar.finish();
    finish(&film, &meta, &report, load_s, job)
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
    let interrupted = signals::received().filter(|_| report.cancelled);
    let outputs = match &job.denoiser {
        None => Outputs::of_film(film),
        Some(denoiser) => Outputs::of_film(film).denoised(denoiser)?,
    };
    outputs.write(&job.output)?;
    for f in job.run.checkpoint.iter().chain(&job.run.film_out) {
        glint::render::write_film(f, film, meta)?;
    }
    let spp = film_spp(film);
    let written = {
        let mut w = vec![job.output.display().to_string()];
        w.extend(job.run.checkpoint.iter().chain(&job.run.film_out).map(|p| p.display().to_string()));
        w.join(", ")
    };
    if let Some(sig) = interrupted {
        if !job.quiet {
            eprintln!("glint: interrupted at {spp} of {} spp: wrote {written}", film.spp());
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
