#![no_main]
//! glTF end to end: a file that names no other file is written to a folder of its own, read
//! as a whole scene (`formats::gltf::read`), built (meshes, instances, textures, emissive
//! triangles as lights) and rendered at 4x4 pixels, 1 sample per pixel, with every pixel
//! required finite. The input's last byte picks the light selection (power or the light
//! tree, which weighs textured emitters by their texels). Inputs that name external buffers
//! or images are skipped: the target reads no file of the machine's.
use glint::describe::LightSelection;
use libfuzzer_sys::fuzz_target;
use std::sync::atomic::{AtomicU64, Ordering};

static INPUTS: AtomicU64 = AtomicU64::new(0);

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("glint-fuzz-gltf-{}", std::process::id()));
    // A new name for every input: the build's file cache knows a file by its length and
    // modification time, which two inputs written in the same clock tick may share.
    let path = dir.join(format!("{}.gltf", INPUTS.fetch_add(1, Ordering::Relaxed)));
    if !glint::io::gltf::side_files(&path, data).is_empty() {
        return;
    }
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    std::fs::write(&path, data).expect("a temporary file");
    render(&path, data.last().is_some_and(|b| b % 2 == 1));
    let _ = std::fs::remove_file(&path);
});

fn render(path: &std::path::Path, tree: bool) {
    let Ok(mut desc) = glint::formats::gltf::read(path, None) else { return };
    desc.film.width = 4;
    desc.film.height = 4;
    desc.sampler.spp = 1;
    desc.light_selection = if tree { LightSelection::Tree } else { LightSelection::Power };
    let Ok(world) = glint::assemble::build(&desc, &Default::default()) else { return };
    let integrator = glint::integrators::Integrator::from(desc.integrator.clone());
    let settings = glint::render::RenderSettings { spp: 1, ..Default::default() };
    let out = glint::render::render(&world, &integrator, &settings, &glint::render::Silent);
    assert!(out.image.pixels.iter().all(|p| p.is_finite()), "a non-finite pixel");
}
