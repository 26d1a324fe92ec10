//! Subcommands: `render`, `info`, `bench`, `rays`.

use clap::{Args, Parser, Subcommand};
use glint::accel::BvhSplit;
use glint::integrators::{Integrator, PathSettings, Strategy, WhittedSettings};
use glint::render::{render, Progress, RenderSettings, Silent};
use glint::sampling::SamplerKind;
use glint::scene::{load, LightSelection, LoadOptions, LoadedScene, ShapeRef};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

#[derive(Parser)]
#[command(name = "glint", version, about = "A physically based CPU renderer")]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (.json, or Mitsuba 3 .xml) to an image (.png, .exr or .pfm).
    Render(RenderArgs),
    /// Print scene statistics: shapes, triangles, lights, BVH quality and memory.
    Info(InfoArgs),
    /// Measure ray throughput (closest hit and occlusion) on a mesh and a ray file.
    Bench(crate::bench::BenchArgs),
    /// Write a benchmark ray set (primary or diffuse rays) for a mesh.
    Rays(crate::rays::RaysArgs),
}

#[derive(Args)]
struct SceneArgs {
    /// Scene file.
    scene: PathBuf,
    /// BVH split strategy: sah (binned surface area heuristic) or median (the paper's).
    #[arg(long, default_value = "sah", value_parser = parse_split)]
    bvh: BvhSplit,
    /// Override a Mitsuba `<default>` value: -D name=value (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    define: Vec<(String, String)>,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image; the extension chooses the format.
    #[arg(short, long, default_value = "out.png")]
    output: PathBuf,
    /// Samples per pixel (default: the scene's).
    #[arg(long)]
    spp: Option<u32>,
    /// Integrator (default: the scene's).
    #[arg(long, value_parser = ["whitted", "path"])]
    integrator: Option<String>,
    /// Longest path (path: segments, -1 unbounded; whitted: recursion depth).
    #[arg(long, allow_hyphen_values = true)]
    max_depth: Option<i64>,
    /// Path tracer estimator: mis, light or bsdf.
    #[arg(long)]
    strategy: Option<Strategy>,
    /// Light selection for next-event estimation: uniform, area or power.
    #[arg(long)]
    light_selection: Option<LightSelection>,
    /// Image width (overrides the scene's film).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (overrides the scene's film).
    #[arg(long)]
    height: Option<u32>,
    /// Sampler: sobol (Owen-scrambled, the default) or independent.
    #[arg(long)]
    sampler: Option<SamplerKind>,
    /// Random seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args)]
struct InfoArgs {
    #[command(flatten)]
    scene: SceneArgs,
}

fn parse_split(s: &str) -> Result<BvhSplit, String> {
    s.parse()
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    let (k, v) = s.split_once('=').ok_or_else(|| format!("'{s}' is not NAME=VALUE"))?;
    Ok((k.to_string(), v.to_string()))
}

pub fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Render(a) => render_cmd(a),
        Command::Info(a) => info_cmd(a),
        Command::Bench(a) => crate::bench::bench_cmd(a),
        Command::Rays(a) => crate::rays::rays_cmd(a),
    }
}

fn load_scene(a: &SceneArgs, width: Option<u32>, height: Option<u32>) -> Result<(LoadedScene, f64), String> {
    let opts = LoadOptions { bvh_split: a.bvh, width, height, defines: a.define.clone() };
    let start = Instant::now();
    let loaded = load(&a.scene, &opts)?;
    Ok((loaded, start.elapsed().as_secs_f64()))
}

fn render_cmd(a: RenderArgs) -> Result<(), String> {
    // Check the output name before spending time on the render.
    glint::io::image_io::ImageFormat::from_path(&a.output)?;
    if let Some(t) = a.threads {
        if t == 0 {
            return Err("--threads must be at least 1".into());
        }
        rayon::ThreadPoolBuilder::new().num_threads(t).build_global().map_err(|e| e.to_string())?;
    }
    if let (Some(w), Some(h)) = (a.width.or(Some(1)), a.height.or(Some(1))) {
        glint::scene::json::check_resolution(w, h)?;
    }
    let (mut loaded, load_s) = load_scene(&a.scene, a.width, a.height)?;
    if !a.quiet {
        for w in &loaded.warnings {
            eprintln!("glint: warning: {w}");
        }
    }
    if let Some(sel) = a.light_selection {
        loaded.scene.set_light_selection(sel);
    }
    let integrator = choose_integrator(&a, loaded.integrator)?;
    let settings = RenderSettings {
        spp: a.spp.unwrap_or(loaded.settings.spp),
        seed: a.seed.unwrap_or(loaded.settings.seed),
        sampler: a.sampler.unwrap_or(loaded.settings.sampler),
        ..loaded.settings
    };
    if settings.spp == 0 {
        return Err("--spp must be at least 1".into());
    }
    let scene = &loaded.scene;
    let pixels = scene.camera.width as u64 * scene.camera.height as u64;
    let show_bar = !a.quiet && std::io::stderr().is_terminal();
    let bar = ProgressBar::new(pixels, show_bar);
    let out = render(scene, &integrator, &settings, if show_bar { &bar } else { &Silent });
    bar.finish();
    glint::io::write_image(&out.image, &a.output)?;
    if !a.quiet {
        let s = &out.stats;
        eprintln!(
            "glint: {} {}x{} @ {} spp ({}) in {:.3} s (load {:.3} s): {:.1} M rays ({:.2} Mrays/s), {} discarded samples -> {}",
            a.scene.scene.display(),
            scene.camera.width,
            scene.camera.height,
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

fn choose_integrator(a: &RenderArgs, from_scene: Integrator) -> Result<Integrator, String> {
    let mut integ = match a.integrator.as_deref() {
        None => from_scene,
        Some("whitted") => match from_scene {
            Integrator::Whitted(w) => Integrator::Whitted(w),
            _ => Integrator::Whitted(WhittedSettings::default()),
        },
        Some(_) => match from_scene {
            Integrator::Path(p) => Integrator::Path(p),
            _ => Integrator::Path(PathSettings::default()),
        },
    };
    match &mut integ {
        Integrator::Whitted(w) => {
            if let Some(d) = a.max_depth {
                if d < 1 {
                    return Err(format!("--max-depth {d}: the Whitted integrator needs a depth of at least 1"));
                }
                w.max_depth = d as u32;
            }
            if a.strategy.is_some() {
                return Err("--strategy applies to the path integrator only".into());
            }
        }
        Integrator::Path(p) => {
            if let Some(d) = a.max_depth {
                p.max_depth = if d < 0 { None } else { Some(d as u32) };
            }
            if let Some(s) = a.strategy {
                p.strategy = s;
            }
        }
    }
    Ok(integ)
}

fn info_cmd(a: InfoArgs) -> Result<(), String> {
    let (loaded, load_s) = load_scene(&a.scene, None, None)?;
    let s = &loaded.scene;
    let spheres = s.instances.iter().filter(|i| matches!(i.shape, ShapeRef::Sphere(_))).count();
    let mesh_instances = s.instances.len() - spheres;
    let unique_tris: usize = s.meshes.iter().map(|m| m.indices.len()).sum();
    println!("scene            {}", a.scene.scene.display());
    println!("shapes           {} ({} mesh instances, {} spheres)", s.instances.len(), mesh_instances, spheres);
    println!("meshes           {} unique, {} triangles stored", s.meshes.len(), unique_tris);
    println!("triangles        {} (instanced)", s.triangle_count());
    println!("lights           {}", s.lights.len());
    println!("materials        {}", s.materials.len());
    println!("camera           {}x{}", s.camera.width, s.camera.height);
    println!("bvh split        {:?}", s.bvh_split);
    println!("load time        {:.3} s (BVH builds {:.3} s)", load_s, s.bvh_build_seconds);
    let top = s.top.stats();
    println!(
        "top-level BVH    {} nodes, {} leaves, depth {}, leaf size {}..{} (mean {:.2}), SAH cost {:.2}, {} bytes",
        top.nodes, top.leaves, top.max_depth, top.min_leaf, top.max_leaf, top.mean_leaf, top.sah_cost, top.bytes
    );
    let mut total_bytes = top.bytes;
    let mut mesh_bytes = 0;
    for (i, m) in s.meshes.iter().enumerate() {
        let st = m.bvh.stats();
        total_bytes += st.bytes;
        mesh_bytes += m.memory_bytes();
        if i < 20 {
            println!(
                "mesh {:<4}        {} triangles: {} nodes, {} leaves, depth {}, leaf size {}..{} (mean {:.2}), SAH cost {:.2}, {} bytes",
                i, m.indices.len(), st.nodes, st.leaves, st.max_depth, st.min_leaf, st.max_leaf, st.mean_leaf, st.sah_cost, st.bytes
            );
        }
    }
    if s.meshes.len() > 20 {
        println!("...              ({} more meshes)", s.meshes.len() - 20);
    }
    println!("BVH memory       {} bytes ({:.2} MiB)", total_bytes, total_bytes as f64 / 1048576.0);
    println!("mesh memory      {} bytes ({:.2} MiB)", mesh_bytes, mesh_bytes as f64 / 1048576.0);
    Ok(())
}

/// A progress bar on stderr with ETA and Mrays/s.
struct ProgressBar {
    bar: Option<indicatif::ProgressBar>,
    rays: AtomicU64,
    start: Instant,
}

impl ProgressBar {
    fn new(pixels: u64, show: bool) -> ProgressBar {
        let bar = show.then(|| {
            let b = indicatif::ProgressBar::new(pixels);
            b.set_style(
                indicatif::ProgressStyle::with_template("{bar:40} {percent:>3}% ETA {eta:>4} {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        ProgressBar { bar, rays: AtomicU64::new(0), start: Instant::now() }
    }
    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Progress for ProgressBar {
    fn advance(&self, pixels: u64, rays: u64) {
        let total = self.rays.fetch_add(rays, Ordering::Relaxed) + rays;
        if let Some(b) = &self.bar {
            b.inc(pixels);
            let mrays = total as f64 / self.start.elapsed().as_secs_f64().max(1e-9) / 1e6;
            b.set_message(format!("{mrays:.1} Mrays/s"));
        }
    }
}
