#![no_main]
//! End to end: any JSON or Mitsuba scene that reads is built and rendered at 4x4 pixels,
//! 1 sample per pixel (the first byte chooses the format).
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, rest)) = data.split_first() else { return };
    let Ok(text) = std::str::from_utf8(rest) else { return };
    let desc = if kind % 2 == 0 {
        glint::formats::json::read(std::path::Path::new("fuzz.json"), text)
    } else {
        glint::formats::mitsuba::read_str(text, std::path::Path::new("/nonexistent/fuzz.xml"), &[])
    };
    let Ok(mut desc) = desc else { return };
    desc.film.width = 4;
    desc.film.height = 4;
    desc.sampler.spp = 1;
    let Ok(world) = glint::assemble::build(&desc, &Default::default()) else { return };
    let integrator = glint::integrators::Integrator::from(desc.integrator.clone());
    let settings = glint::render::RenderSettings { spp: 1, ..Default::default() };
    let out = glint::render::render(&world, &integrator, &settings, &glint::render::Silent);
    assert!(out.image.pixels.iter().all(|p| p.is_finite()), "a non-finite pixel");
});
