//! The `glint` command line: a thin front end over the `glint` library.

mod bench;
mod commands;
mod meshsrc;
mod rays;

use clap::Parser;

fn main() {
    let cli = commands::Cli::parse();
    if let Err(e) = commands::run(cli) {
        eprintln!("glint: error: {e}");
        std::process::exit(1);
    }
}
