//! The command line's arguments and its dispatch to the subcommands.

use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand};
use glint::accel::BvhSplit;
use glint::assemble::BuildOptions;
use glint::describe::Strategy;
use glint::formats::{Define, ReadOptions};
use glint::lights::LightSelection;
use glint::render::{Aov, Rect, Schedule};
use glint::sampling::SamplerKind;
use glint::session::{integrator_names, Overrides, Session};
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "glint", version, about = "A physically based CPU renderer")]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (.png, .exr or .pfm). Scenes: glint's JSON (.json),
    /// Mitsuba 3 XML (.xml), glTF 2.0 (.gltf, .glb), or a bare mesh (.obj, .ply) in a
    /// preview setting.
    Render(RenderArgs),
    /// Continue a checkpointed render (bit-identical to an uninterrupted one).
    Resume(ResumeArgs),
    /// Add films of one render (disjoint passes or regions) and write the image.
    Merge(MergeArgs),
    /// Print scene statistics: shapes, triangles, lights, BVH quality and memory.
    Info(SceneArgs),
    /// Measure ray throughput (closest hit and occlusion) on a mesh and a ray file.
    Bench(crate::bench::BenchArgs),
    /// Write a benchmark ray set (primary or diffuse rays) for a mesh.
    Rays(crate::rays::RaysArgs),
}

#[derive(Args)]
pub struct SceneArgs {
    /// Scene file: glint JSON (.json), Mitsuba 3 XML (.xml), glTF 2.0 (.gltf, .glb), or a
    /// bare OBJ or PLY mesh.
    pub scene: PathBuf,
    /// BVH split strategy: sah (binned surface area heuristic) or median (the paper's).
    #[arg(long, default_value = "sah", value_parser = parse_split)]
    pub bvh: BvhSplit,
    /// Override a Mitsuba `<default>` value: -D name=value (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
    /// glTF: the camera to render through, by index in the file's `cameras` or by name
    /// (default: the first camera node of the default scene).
    #[arg(long, value_name = "NAME|INDEX")]
    pub camera: Option<String>,
}

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output image; the extension chooses the format (default: the scene's name with .png,
    /// next to the scene).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Samples per pixel (default: the scene's).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Integrator (default: the scene's).
    #[arg(long, value_parser = PossibleValuesParser::new(integrator_names().iter().map(String::as_str)))]
    pub integrator: Option<String>,
    /// Longest path (path: segments, -1 unbounded; whitted: recursion depth).
    #[arg(long, allow_hyphen_values = true)]
    pub max_depth: Option<i64>,
    /// Path tracer estimator: mis, light or bsdf.
    #[arg(long)]
    pub strategy: Option<Strategy>,
    /// Light selection for next-event estimation: power (the default), tree (a light BVH: by what each light can send to the shading point), auto (the tree from 400 lights or on a textured emitting mesh, else power), uniform or area.
    #[arg(long)]
    pub light_selection: Option<LightSelection>,
    /// Image width (overrides the scene's film).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (overrides the scene's film).
    #[arg(long)]
    pub height: Option<u32>,
    /// Sampler: sobol (Owen-scrambled, the default) or independent.
    #[arg(long)]
    pub sampler: Option<SamplerKind>,
    /// Random seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    #[command(flatten)]
    pub run: RunArgs,
    /// Samples per pixel of a pass (default 1; the image does not depend on it).
    #[arg(long)]
    pub pass_spp: Option<u32>,
    /// Render only passes A to B-1 (for splitting a render; see `glint merge`).
    #[arg(long, value_name = "A..B", value_parser = parse_passes)]
    pub passes: Option<std::ops::Range<u32>>,
    /// Render only the pixels X0..X1, Y0..Y1 (X1 and Y1 exclusive).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop)]
    pub crop: Option<Rect>,
    /// Extra layers: albedo, normal, depth, position, variance, spp, bvh-cost (comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub aov: Vec<Aov>,
    /// Denoise with Intel Open Image Denoise (renders the albedo and normal layers to guide
    /// it; the image as rendered is kept as the layer `noisy`).
    #[arg(long)]
    pub denoise: bool,
    /// Adaptive sampling: pixels whose relative standard error is under the threshold stop.
    #[arg(long)]
    pub adaptive: bool,
    /// Target relative standard error of a pixel's mean for --adaptive.
    #[arg(long, default_value_t = 0.02)]
    pub adaptive_threshold: f32,
    /// Passes every pixel takes before --adaptive may stop it.
    #[arg(long, default_value_t = 16)]
    pub adaptive_min_passes: u32,
}

/// Options shared by `render` and `resume`: how long to go on and what to write meanwhile.
#[derive(Args, Clone)]
pub struct RunArgs {
    /// Render whole passes until this many seconds have passed, then write what is done.
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    /// Write the film to FILE every --checkpoint-every seconds and on interrupt (see `glint resume`).
    #[arg(long, value_name = "FILE")]
    pub checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    pub checkpoint_every: f64,
    /// Rewrite the output image every this many seconds as passes finish (a live preview).
    #[arg(long, value_name = "SECONDS")]
    pub write_every: Option<f64>,
    /// Write the raw film (same format as a checkpoint) when done, for `glint merge`.
    #[arg(long, value_name = "FILE")]
    pub film_out: Option<PathBuf>,
    /// How paths are scheduled: wavefront-simd (a tile's paths advanced together, a bounce at
    /// a time, shadow rays traced in packets and the common BSDFs' vertices shaded 8 or 16
    /// paths per instruction; the default), wavefront (the same, one ray and one vertex at a time),
    /// wavefront-interleaved (each batch traced with several rays in flight),
    /// wavefront-packets (shadow rays in packets, vertices one at a time) or one-path (each
    /// path to its end). Same image under each.
    #[arg(long, default_value = "wavefront-simd")]
    pub schedule: Schedule,
    /// Serve a live view of the render in the browser at ADDR (HOST:PORT or PORT; default
    /// 127.0.0.1 at a free port, printed on start): the image as passes land, its layers, a
    /// pixel inspector and a Stop button that ends the render as Ctrl-C does.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "")]
    pub preview: Option<String>,
    /// Send the image and its layers to tev (the image viewer) at HOST:PORT as passes land
    /// (tev listens on 127.0.0.1:14158 by default).
    #[arg(long, value_name = "HOST:PORT")]
    pub tev: Option<String>,
}

#[derive(Args)]
pub struct ResumeArgs {
    /// A checkpoint written by `glint render --checkpoint`.
    #[arg(value_name = "CHECKPOINT")]
    pub from: PathBuf,
    /// Output image (default: the one the render was writing).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Samples per pixel to reach (default: the render's).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    #[command(flatten)]
    pub run: RunArgs,
}

#[derive(Args)]
pub struct MergeArgs {
    /// Films of one render (disjoint passes or pixel regions), from --film-out or --checkpoint.
    #[arg(required = true)]
    pub films: Vec<PathBuf>,
    /// Output image (.png, .exr or .pfm).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the merged film.
    #[arg(long, value_name = "FILE")]
    pub film_out: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

fn parse_passes(s: &str) -> Result<std::ops::Range<u32>, String> {
    let (a, b) = s.split_once("..").ok_or_else(|| format!("'{s}' is not A..B"))?;
    let a: u32 = a.trim().parse().map_err(|_| format!("'{a}' is not a pass number"))?;
    let b: u32 = b.trim().parse().map_err(|_| format!("'{b}' is not a pass number"))?;
    if a >= b {
        return Err(format!("{a}..{b} is empty (B must be greater than A)"));
    }
    Ok(a..b)
}

fn parse_crop(s: &str) -> Result<Rect, String> {
    let v: Vec<u32> = s
        .split(',')
        .map(|t| t.trim().parse::<u32>().map_err(|_| format!("'{t}' is not a pixel coordinate")))
        .collect::<Result<_, _>>()?;
    let [x0, y0, x1, y1] = v[..] else { return Err(format!("'{s}' is not X0,Y0,X1,Y1")) };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("crop {s} is empty (need X0 < X1 and Y0 < Y1)"));
    }
    Ok(Rect { x0, y0, x1, y1 })
}

fn parse_split(s: &str) -> Result<BvhSplit, String> {
    s.parse()
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    let (k, v) = s.split_once('=').ok_or_else(|| format!("'{s}' is not NAME=VALUE"))?;
    Ok((k.to_string(), v.to_string()))
}

pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Render(a) => crate::render::render_cmd(a),
        Command::Resume(a) => crate::render::resume_cmd(a),
        Command::Merge(a) => crate::merge::merge_cmd(a),
        Command::Info(a) => Ok(crate::info::info_cmd(a)?),
        Command::Bench(a) => Ok(crate::bench::bench_cmd(a)?),
        Command::Rays(a) => Ok(crate::rays::rays_cmd(a)?),
    }
}

/// An error and the exit code it ends the process with.
pub struct CliError {
    pub message: String,
    pub code: i32,
}

impl From<glint::Error> for CliError {
    fn from(e: glint::Error) -> CliError {
        CliError { message: e.to_string(), code: 1 }
    }
}

impl From<String> for CliError {
    fn from(message: String) -> CliError {
        CliError { message: glint::Error::new(message).to_string(), code: 1 }
    }
}

impl From<&str> for CliError {
    fn from(message: &str) -> CliError {
        CliError::from(message.to_string())
    }
}

impl RenderArgs {
    /// The flags that override the scene's settings.
    pub fn overrides(&self) -> Overrides {
        Overrides {
            integrator: self.integrator.clone(),
            max_depth: self.max_depth,
            strategy: self.strategy,
            light_selection: self.light_selection,
            sampler: self.sampler,
            spp: self.spp,
            seed: self.seed,
            width: self.width,
            height: self.height,
        }
    }
}

impl SceneArgs {
    /// Opens the scene with the `-D` overrides and BVH choice of the command line.
    pub fn open(&self) -> Result<Session, glint::Error> {
        let defines =
            self.define.iter().map(|(name, value)| Define { name: name.clone(), value: value.clone() }).collect();
        let mut s = Session::open(&self.scene, &ReadOptions { defines, camera: self.camera.clone() })?;
        s.set_build_options(BuildOptions { bvh_split: self.bvh });
        Ok(s)
    }
}
