//! The command line's arguments and its dispatch to the subcommands.

use clap::{Args, Parser, Subcommand};
use glint::accel::BvhSplit;
use glint::build::BuildOptions;
use glint::describe::Strategy;
use glint::formats::{Define, ReadOptions};
use glint::lights::LightSelection;
use glint::sampling::SamplerKind;
use glint::session::Session;
use std::path::PathBuf;

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
    Info(SceneArgs),
    /// Measure ray throughput (closest hit and occlusion) on a mesh and a ray file.
    Bench(crate::bench::BenchArgs),
    /// Write a benchmark ray set (primary or diffuse rays) for a mesh.
    Rays(crate::rays::RaysArgs),
}

#[derive(Args)]
pub struct SceneArgs {
    /// Scene file.
    pub scene: PathBuf,
    /// BVH split strategy: sah (binned surface area heuristic) or median (the paper's).
    #[arg(long, default_value = "sah", value_parser = parse_split)]
    pub bvh: BvhSplit,
    /// Override a Mitsuba `<default>` value: -D name=value (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
}

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output image; the extension chooses the format.
    #[arg(short, long, default_value = "out.png")]
    pub output: PathBuf,
    /// Samples per pixel (default: the scene's).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Integrator (default: the scene's).
    #[arg(long, value_parser = ["whitted", "path"])]
    pub integrator: Option<String>,
    /// Longest path (path: segments, -1 unbounded; whitted: recursion depth).
    #[arg(long, allow_hyphen_values = true)]
    pub max_depth: Option<i64>,
    /// Path tracer estimator: mis, light or bsdf.
    #[arg(long)]
    pub strategy: Option<Strategy>,
    /// Light selection for next-event estimation: uniform, area or power.
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

impl SceneArgs {
    /// Opens the scene with the `-D` overrides and BVH choice of the command line.
    pub fn open(&self) -> Result<Session, glint::Error> {
        let defines =
            self.define.iter().map(|(name, value)| Define { name: name.clone(), value: value.clone() }).collect();
        let mut s = Session::open(&self.scene, &ReadOptions { defines })?;
        s.set_build_options(BuildOptions { bvh_split: self.bvh });
        Ok(s)
    }
}
