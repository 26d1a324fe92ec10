//! `glint render`: opens the scene through a session, applies the command line's overrides
//! as edits of its description, checks the output before any sample is taken, renders and
//! writes the image.

use crate::commands::{CliError, RenderArgs};
use crate::progress::ProgressBar;
use glint::describe::{IntegratorDesc, PathSettings, SceneDesc, WhittedSettings};
use glint::render::{render, Silent};
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

pub fn render_cmd(a: RenderArgs) -> Result<(), CliError> {
    glint::io::image_io::ImageFormat::from_path(&a.output)?;
    set_threads(a.threads, a.quiet)?;
    let start = Instant::now();
    let mut session = a.scene.open()?;
    apply_overrides(session.edit(), &a)?;
    check_output(&a.output, session.description())?;
    if !a.quiet {
        for w in &session.description().warnings {
            eprintln!("glint: warning: {w}");
        }
    }
    let world = session.world()?;
    let load_s = start.elapsed().as_secs_f64();
    if !a.quiet && world.lights().is_empty() {
        eprintln!("glint: warning: {}: the scene has no lights: the image will be black", a.scene.scene.display());
    }
    let settings = session.render_settings();
    let integrator = session.integrator();
    let camera = world.camera();
    let show_bar = !a.quiet && std::io::stderr().is_terminal();
    let bar = ProgressBar::new(camera.width as u64 * camera.height as u64, show_bar);
    let out = render(&world, &integrator, &settings, if show_bar { &bar } else { &Silent });
    bar.finish();
    glint::io::write_image(&out.image, &a.output)?;
    if !a.quiet {
        let s = &out.stats;
        eprintln!(
            "glint: {} {}x{} @ {} spp ({}) in {:.3} s (load {:.3} s): {:.1} M rays ({:.2} Mrays/s), {} discarded samples -> {}",
            a.scene.scene.display(),
            camera.width,
            camera.height,
            settings.spp,
            integrator.name(),
            s.seconds,
            load_s,
            (s.rays + s.shadow_rays) as f64 / 1e6,
            s.mrays_per_second(),
            s.discarded_samples,
            a.output.display()
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

/// The command line's overrides, as edits of the description.
fn apply_overrides(d: &mut SceneDesc, a: &RenderArgs) -> Result<(), CliError> {
    if a.width.is_some() || a.height.is_some() {
        let (w, h) = (a.width.unwrap_or(d.film.width), a.height.unwrap_or(d.film.height));
        glint::describe::limits::check_resolution(w, h)
            .map_err(|e| CliError::from(format!("--width/--height: {e}")))?;
        d.film.width = w;
        d.film.height = h;
    }
    if let Some(spp) = a.spp {
        if spp == 0 || spp > glint::describe::limits::MAX_SPP {
            return Err(format!("--spp {spp} is out of range (1 to {})", glint::describe::limits::MAX_SPP).into());
        }
        d.sampler.spp = spp;
    }
    if let Some(seed) = a.seed {
        d.sampler.seed = seed;
    }
    if let Some(s) = a.sampler {
        d.sampler.kind = s;
    }
    if let Some(sel) = a.light_selection {
        d.light_selection = sel;
    }
    match a.integrator.as_deref() {
        Some("whitted") if !matches!(d.integrator, IntegratorDesc::Whitted(_)) => {
            d.integrator = IntegratorDesc::Whitted(WhittedSettings::default())
        }
        Some("path") if !matches!(d.integrator, IntegratorDesc::Path(_)) => {
            d.integrator = IntegratorDesc::Path(PathSettings::default())
        }
        _ => {}
    }
    match &mut d.integrator {
        IntegratorDesc::Whitted(w) => {
            if let Some(depth) = a.max_depth {
                let max = glint::describe::limits::MAX_WHITTED_DEPTH as i64;
                if !(1..=max).contains(&depth) {
                    return Err(
                        format!("--max-depth {depth}: the Whitted integrator needs a depth from 1 to {max}").into()
                    );
                }
                w.max_depth = depth as u32;
            }
            if a.strategy.is_some() {
                return Err("--strategy applies to the path integrator only".into());
            }
        }
        IntegratorDesc::Path(p) => {
            if let Some(depth) = a.max_depth {
                if depth >= u32::MAX as i64 {
                    return Err(format!(
                        "--max-depth {depth} is out of range (-1 for unbounded, or 0 to {})",
                        u32::MAX - 1
                    )
                    .into());
                }
                p.max_depth = if depth < 0 { None } else { Some(depth as u32) };
            }
            if let Some(s) = a.strategy {
                p.strategy = s;
            }
        }
    }
    Ok(())
}

/// Before any sample is taken: the output's folder exists and is writable, and the output
/// is not one of the scene's own files.
pub fn check_output(out: &Path, desc: &SceneDesc) -> Result<(), CliError> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(format!("{}: the output folder {} does not exist", out.display(), dir.display()).into());
    }
    let probe = dir.join(format!(".glint-write-test-{}", std::process::id()));
    match std::fs::File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) => return Err(format!("{}: cannot write to the folder {}: {e}", out.display(), dir.display()).into()),
    }
    let same = |p: &Path| match (std::fs::canonicalize(p), std::fs::canonicalize(&dir)) {
        (Ok(input), Ok(d)) => out.file_name().is_some_and(|n| d.join(n) == input),
        _ => false,
    };
    let mut inputs = desc.files();
    if let Some(src) = &desc.source {
        inputs.push(src.clone());
    }
    if let Some(p) = inputs.iter().find(|p| same(p)) {
        return Err(
            format!("{}: the output would overwrite the scene's input file {}", out.display(), p.display()).into()
        );
    }
    Ok(())
}
