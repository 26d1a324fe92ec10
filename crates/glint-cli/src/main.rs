//! The `glint` command line: a thin front end over the `glint` library's session API.

mod bench;
mod bench_curves;
mod commands;
mod info;
mod merge;
mod meshsrc;
mod progress;
mod rays;
mod render;
mod signals;

use clap::Parser;

fn main() {
    let cli = commands::Cli::parse();
    if let Err(e) = commands::run(cli) {
        // An interrupted render has already said what it wrote.
        if !e.message.is_empty() {
            // Several errors (a scene's unsupported features) come one a line.
            for line in e.message.lines() {
                eprintln!("glint: error: {line}");
            }
        }
        std::process::exit(e.code);
    }
}
