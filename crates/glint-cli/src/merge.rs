//! `glint merge`: adds films of one render (disjoint pass ranges or pixel regions, written
//! by `--film-out` or `--checkpoint`) and writes the image. Films of another scene, other
//! settings, or overlapping work are refused.

use crate::commands::{CliError, MergeArgs};
use glint::session::{check_output, layer_names, merge_films, output_files, Outputs};

pub fn merge_cmd(a: MergeArgs) -> Result<(), CliError> {
    glint::io::image_io::ImageFormat::from_path(&a.output)?;
    let (film, job, hash) = merge_films(&a.films)?;
    for out in output_files(&a.output, &layer_names(film.aovs(), false)).iter().chain(&a.film_out) {
        check_output(out, &job.desc)?;
    }
    Outputs::of_film(&film).write(&a.output)?;
    if let Some(f) = &a.film_out {
        let meta = glint::render::FilmMeta { scene_hash: hash, settings: job.to_json() };
        glint::render::write_film(f, &film, &meta)?;
    }
    if !a.quiet {
        let r = film.region();
        eprintln!(
            "glint: merged {} films: {}x{} pixels, {} of {} passes complete -> {}",
            a.films.len(),
            r.width(),
            r.height(),
            film.passes_done(),
            film.pass_count(),
            a.output.display()
        );
    }
    Ok(())
}
