#![no_main]
//! Mitsuba's curve files (`linearcurve`, `bsplinecurve`) on arbitrary bytes: the first byte
//! picks the basis; what parses is built into a curve set (its BVH) and traced by a few
//! rays, as a scene would use it.
use glint::accel::BvhSplit;
use glint::geometry::{CurveBasis, Curves};
use glint::math::{vec3, Ray};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else { return };
    let basis = if pick & 1 == 0 { CurveBasis::Linear } else { CurveBasis::BSpline };
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let Ok(file) = glint::io::curves::parse_curves(std::path::Path::new("in.txt"), text, basis) else { return };
    let Ok(curves) = Curves::new(basis, file.points, file.curve_starts, BvhSplit::Sah) else { return };
    let c = curves.bounds().center();
    for d in [vec3(1.0, 0.0, 0.0), vec3(0.0, -1.0, 0.0), vec3(0.3, 0.4, -0.5)] {
        let ray = Ray::new(c - d * 10.0, d);
        if let Some(h) = curves.intersect(&ray) {
            let _ = curves.point(&ray, &h);
        }
        let _ = curves.occluded(&ray);
    }
});
