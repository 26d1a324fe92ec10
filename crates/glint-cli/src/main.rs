//! The `glint` command line: a thin front end over the `glint` library's session API.

mod bench;
mod commands;
mod info;
mod meshsrc;
mod progress;
mod rays;
mod render;

use clap::Parser;

fn main() {
    let cli = commands::Cli::parse();
    if let Err(e) = commands::run(cli) {
        eprintln!("glint: error: {}", e.message);
        std::process::exit(e.code);
    }
}
