//! Every non-delta BSDF lobe: sampled directions follow `pdf` (chi-square), sample weights
//! equal eval/pdf, the pdf integrates to at most one, and the mean sample weight matches the
//! integrated `eval`. One list of cases; add a BSDF with one line in `cases()`.

mod common;

use common::bsdf_check::{chi2_of, dir, draw_samples, integrate, BsdfCase, Integrals, Samples};
use common::stats::{sidak, z_critical, FALSE_ALARM};
use glint::bsdf::{Microfacet, MicrofacetKind};
use glint::materials::{
    normal_map_frame, BlendBsdf, BlendPart, Bsdf, Conductor, Diffuse, GltfPbr, HairBsdf, PPlasticParams, Phong,
    PlasticParams, Principled, PrincipledInputs, PrincipledRates, PrincipledThin, PrincipledThinInputs,
    PrincipledThinRates, RoughConductor, RoughDielectric, ShadedBsdf,
};
use glint::math::vec3;
use glint::math::{rgb, Rgb};
use rayon::prelude::*;
use std::sync::OnceLock;

/// Samples per case: enough for the chi-square test to see a few-percent error in a bin.
const SAMPLES: u64 = 1_000_000;
/// Family-wise significance of the chi-square battery, Šidák-corrected over the cases.
const CHI2_SIGNIFICANCE: f64 = 0.01;
/// Bound on the quadrature error of ∫ pdf and ∫ eval over the sphere (adaptive Simpson with
/// 1e-8 per bin on 512 bins gives under 1e-5; checked on the diffuse lobe, where both
/// integrals are known exactly).
const QUADRATURE_TOLERANCE: f64 = 1e-5;

fn case(name: &str, bsdf: Bsdf, wo_deg: f32, complete: bool) -> BsdfCase {
    BsdfCase { name: format!("{name}, wo at {wo_deg}°"), bsdf: bsdf.into(), wo: dir(wo_deg), complete }
}

/// `bsdf` in the frame a normal map with tangent-space normal `n` tilts it to (samples below
/// the real surface are refused, so sampling is never complete).
fn tilted(name: &str, bsdf: Bsdf, n: glint::math::Vec3, wo_deg: f32) -> BsdfCase {
    let tilt = normal_map_frame(n, dir(wo_deg));
    assert!(tilt.is_some());
    BsdfCase {
        name: format!("{name}, wo at {wo_deg}°"),
        bsdf: ShadedBsdf { bsdf, tilt },
        wo: dir(wo_deg),
        complete: false,
    }
}

/// A case seen from polar angle `theta_deg` at azimuth `phi_deg` (for anisotropic lobes).
fn azimuth_case(name: &str, bsdf: Bsdf, theta_deg: f32, phi_deg: f32) -> BsdfCase {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    let wo = glint::math::Vec3 { x: t.sin() * p.cos(), y: t.sin() * p.sin(), z: t.cos() };
    BsdfCase {
        name: format!("{name}, wo at {theta_deg}°, azimuth {phi_deg}°"), bsdf: bsdf.into(), wo, complete: false
    }
}

fn ggx(a: f32) -> Microfacet {
    Microfacet::new(MicrofacetKind::Ggx, a)
}
fn beckmann(a: f32) -> Microfacet {
    Microfacet::new(MicrofacetKind::Beckmann, a)
}

fn cases() -> Vec<BsdfCase> {
    let gold = (rgb(0.143, 0.375, 1.442), rgb(3.983, 2.386, 1.603));
    let mut v = Vec::new();
    for wo in [0.0, 45.0, 85.0] {
        v.push(case("diffuse", Bsdf::Diffuse(Diffuse { reflectance: rgb(0.8, 0.5, 0.2) }), wo, true));
    }
    for (exponent, wo) in [(10.0, 0.0), (10.0, 60.0), (200.0, 30.0), (200.0, 80.0)] {
        let p = Phong { kd: Rgb::splat(0.4), ks: Rgb::splat(0.5), exponent };
        v.push(case(&format!("phong n={exponent}"), Bsdf::Phong(p), wo, false));
    }
    for (name, dist) in [
        ("GGX 0.05", ggx(0.05)),
        ("GGX 0.2", ggx(0.2)),
        ("GGX 0.6", ggx(0.6)),
        ("Beckmann 0.1", beckmann(0.1)),
        ("Beckmann 0.3", beckmann(0.3)),
        ("Beckmann 0.7", beckmann(0.7)),
    ] {
        for wo in [0.0, 45.0, 80.0] {
            let b = Bsdf::RoughConductor(RoughConductor { dist, eta: gold.0, k: gold.1, specular: Rgb::WHITE });
            v.push(case(&format!("rough conductor {name}"), b, wo, false));
        }
    }
    // Below the surface, 110° is beyond the critical angle (41.8° from the normal).
    for (name, dist) in
        [("GGX 0.1", ggx(0.1)), ("GGX 0.5", ggx(0.5)), ("Beckmann 0.1", beckmann(0.1)), ("Beckmann 0.5", beckmann(0.5))]
    {
        for wo in [30.0, 75.0, 150.0, 110.0] {
            let b =
                Bsdf::RoughDielectric(RoughDielectric { dist, eta: 1.5, reflect: Rgb::WHITE, transmit: Rgb::WHITE });
            v.push(case(&format!("rough dielectric {name}"), b, wo, false));
        }
    }
    // Anisotropic lobes, seen from azimuths off both axes (the lobe is not symmetric there).
    let aniso = |kind, u, v| Microfacet::anisotropic(kind, u, v);
    for (name, dist) in [
        ("GGX 0.05x0.4", aniso(MicrofacetKind::Ggx, 0.05, 0.4)),
        ("Beckmann 0.4x0.1", aniso(MicrofacetKind::Beckmann, 0.4, 0.1)),
    ] {
        for (theta, phi) in [(0.0, 0.0), (50.0, 30.0), (80.0, 120.0)] {
            let b = Bsdf::RoughConductor(RoughConductor { dist, eta: gold.0, k: gold.1, specular: Rgb::WHITE });
            v.push(azimuth_case(&format!("rough conductor {name}"), b, theta, phi));
        }
        for (theta, phi) in [(40.0, 60.0), (140.0, 200.0)] {
            let b =
                Bsdf::RoughDielectric(RoughDielectric { dist, eta: 1.5, reflect: Rgb::WHITE, transmit: Rgb::WHITE });
            v.push(azimuth_case(&format!("rough dielectric {name}"), b, theta, phi));
        }
    }
    for (theta, phi) in [(0.0, 0.0), (60.0, 45.0)] {
        let p = PPlasticParams {
            diffuse: rgb(0.05, 0.03, 0.1),
            specular: Rgb::WHITE,
            eta: 1.49,
            dist: Microfacet::anisotropic(MicrofacetKind::Beckmann, 0.06, 0.2),
            specular_probability: 0.94,
        };
        v.push(azimuth_case("pplastic Beckmann 0.06x0.2", Bsdf::PPlastic(p), theta, phi));
    }
    for wo in [0.0, 70.0] {
        let p = PlasticParams { nonlinear: true, ..PlasticParams::new(rgb(0.9, 0.3, 0.1), Rgb::WHITE, 1.5, None) };
        v.push(case("smooth nonlinear plastic", Bsdf::Plastic(p), wo, true));
        let p = PlasticParams {
            nonlinear: true,
            ..PlasticParams::new(rgb(0.9, 0.3, 0.1), Rgb::WHITE, 1.5, Some(ggx(0.3)))
        };
        v.push(case("rough nonlinear plastic GGX 0.3", Bsdf::Plastic(p), wo, false));
    }
    for wo in [0.0, 70.0] {
        let p = PlasticParams::new(rgb(0.6, 0.3, 0.1), Rgb::WHITE, 1.5, None);
        v.push(case("smooth plastic", Bsdf::Plastic(p), wo, true));
    }
    for (name, dist) in [("GGX 0.2", ggx(0.2)), ("Beckmann 0.3", beckmann(0.3))] {
        for wo in [0.0, 70.0] {
            let p = PlasticParams::new(rgb(0.6, 0.3, 0.1), Rgb::WHITE, 1.5, Some(dist));
            v.push(case(&format!("rough plastic {name}"), Bsdf::Plastic(p), wo, false));
        }
    }
    // Normal- and bump-mapped: the BSDF in a tilted frame, with the shadowing term.
    for (tilt, n) in [("30°", vec3(0.5, 0.0, 0.866)), ("50° skew", vec3(-0.5, 0.55, 0.67))] {
        for wo in [10.0, 60.0] {
            let d = Bsdf::Diffuse(Diffuse { reflectance: rgb(0.8, 0.5, 0.2) });
            v.push(tilted(&format!("diffuse tilted {tilt}"), d, n, wo));
            let m =
                Bsdf::RoughConductor(RoughConductor { dist: ggx(0.3), eta: gold.0, k: gold.1, specular: Rgb::WHITE });
            v.push(tilted(&format!("rough conductor GGX 0.3 tilted {tilt}"), m, n, wo));
        }
    }
    principled_and_blend_cases(&mut v);
    principled_thin_cases(&mut v);
    hair_cases(&mut v);
    gltf_cases(&mut v);
    v
}

/// The glTF default material (white rough metal) with `f` applied.
pub fn gltf(f: impl FnOnce(&mut GltfPbr)) -> Bsdf {
    let mut m = GltfPbr::default_material();
    f(&mut m);
    Bsdf::GltfPbr(m)
}

/// The glTF BRDF: each lobe and extension alone, then together, seen from above and (for
/// thin walls and volume boundaries) from below; 110° and 130° are beyond the critical
/// angle of ior 1.5 from inside.
fn gltf_cases(v: &mut Vec<BsdfCase>) {
    let copper = rgb(0.95, 0.64, 0.54);
    let metal = |r: f32| gltf(|m| (m.base_color, m.roughness) = (copper, r));
    let dielectric = |r: f32| gltf(|m| (m.base_color, m.metallic, m.roughness) = (rgb(0.7, 0.3, 0.1), 0.0, r));
    let mut add = |name: &str, b: Bsdf, wos: &[f32]| {
        for &wo in wos {
            v.push(case(&format!("glTF {name}"), b.clone(), wo, false));
        }
    };
    add("metal 0.5", metal(0.5), &[0.0, 45.0, 80.0]);
    add("metal 0.15", metal(0.15), &[30.0]);
    add("dielectric 0.5", dielectric(0.5), &[0.0, 60.0, 85.0]);
    add("dielectric 0.15", dielectric(0.15), &[45.0]);
    let lambert = gltf(|m| (m.base_color, m.metallic, m.specular) = (rgb(0.8, 0.5, 0.2), 0.0, 0.0));
    add("specular 0", lambert, &[30.0]);
    let tinted = gltf(|m| {
        (m.base_color, m.metallic, m.roughness, m.ior) = (rgb(0.2, 0.5, 0.3), 0.3, 0.4, 1.8);
        (m.specular, m.specular_color) = (0.7, rgb(1.5, 0.8, 0.4));
    });
    add("specular colour, ior 1.8, metallic 0.3", tinted, &[50.0]);
    let thin = gltf(|m| (m.base_color, m.metallic, m.roughness, m.transmission) = (rgb(0.9, 0.8, 0.5), 0.0, 0.3, 0.8));
    add("thin transmission 0.8", thin, &[30.0, 150.0]);
    let volume = gltf(|m| {
        (m.base_color, m.metallic, m.roughness, m.transmission) = (rgb(0.9, 0.9, 0.7), 0.0, 0.3, 1.0);
        m.thin_walled = false;
    });
    add("volume transmission", volume, &[30.0, 75.0, 150.0, 130.0]);
    let coated = gltf(|m| {
        (m.base_color, m.metallic, m.roughness) = (rgb(0.1, 0.3, 0.8), 0.0, 0.6);
        (m.clearcoat, m.clearcoat_roughness) = (1.0, 0.2);
    });
    add("clearcoat", coated, &[20.0, 70.0]);
    let sheen = gltf(|m| {
        (m.base_color, m.metallic, m.roughness) = (rgb(0.3, 0.1, 0.1), 0.0, 0.7);
        (m.sheen_color, m.sheen_roughness) = (rgb(0.9, 0.8, 0.8), 0.4);
    });
    add("sheen", sheen, &[10.0, 60.0]);
    let all = gltf(|m| {
        (m.base_color, m.metallic, m.roughness, m.transmission) = (rgb(0.8, 0.6, 0.3), 0.4, 0.35, 0.5);
        (m.clearcoat, m.clearcoat_roughness, m.sheen_color, m.sheen_roughness) = (0.5, 0.1, rgb(0.5, 0.5, 0.6), 0.5);
        (m.ior, m.specular, m.thin_walled) = (1.4, 0.8, false);
    });
    add("every lobe, volume", all, &[40.0, 140.0, 110.0]);
}

/// Mitsuba's `hair`, seen from directions along, across and against the fibre (its frame:
/// x around, y along, z the normal), from near its edge (h near ±1) and head-on.
fn hair_cases(v: &mut Vec<BsdfCase>) {
    let brown = HairBsdf::new(HairBsdf::pigment_absorption(1.3, 0.2), 1.55, 0.3, 0.3, 2.0);
    let blond_rough = HairBsdf::new(HairBsdf::pigment_absorption(0.3, 0.1), 1.55, 0.6, 0.8, 4.0);
    let clear_smooth = HairBsdf::new(Rgb::BLACK, 1.55, 0.15, 0.2, 2.0);
    for (name, h) in [("hair brown", brown), ("hair blond rough", blond_rough), ("hair clear smooth", clear_smooth)] {
        for (theta, phi) in [(10.0, 90.0), (60.0, 30.0), (85.0, 250.0)] {
            v.push(azimuth_case(name, Bsdf::Hair(h), theta, phi));
        }
    }
}

/// Mitsuba's principled defaults with `f` applied.
fn principled(f: impl FnOnce(&mut PrincipledInputs)) -> Bsdf {
    let mut p = PrincipledInputs {
        base_color: rgb(0.8, 0.4, 0.2),
        roughness: 0.5,
        anisotropic: 0.0,
        metallic: 0.0,
        spec_trans: 0.0,
        eta: 1.5,
        spec_tint: 0.0,
        sheen: 0.0,
        sheen_tint: 0.0,
        flatness: 0.0,
        clearcoat: 0.0,
        clearcoat_gloss: 0.0,
        rates: PrincipledRates::default(),
    };
    f(&mut p);
    Bsdf::Principled(Principled::new(&p))
}

/// Mitsuba's principledthin defaults with `f` applied.
fn principled_thin(f: impl FnOnce(&mut PrincipledThinInputs)) -> Bsdf {
    let mut p = PrincipledThinInputs {
        base_color: rgb(0.8, 0.4, 0.2),
        roughness: 0.5,
        anisotropic: 0.0,
        spec_trans: 0.0,
        eta: 1.5,
        spec_tint: 0.0,
        sheen: 0.0,
        sheen_tint: 0.0,
        flatness: 0.0,
        diff_trans: 0.0,
        rates: PrincipledThinRates::default(),
    };
    f(&mut p);
    Bsdf::PrincipledThin(PrincipledThin::new(&p))
}

/// The thin sheet: both faces scatter alike (so each set is also seen from below), and both
/// transmissions leave on the other side.
fn principled_thin_cases(v: &mut Vec<BsdfCase>) {
    for wo in [0.0, 60.0] {
        v.push(case("principledthin defaults", principled_thin(|_| {}), wo, false));
    }
    let glossy = principled_thin(|p| {
        (p.roughness, p.spec_trans, p.eta, p.spec_tint) = (0.4, 0.8, 1.33, 0.3);
    });
    for wo in [30.0, 80.0, 150.0] {
        v.push(case("principledthin spec_trans 0.8", glossy.clone(), wo, false));
    }
    let aniso = principled_thin(|p| {
        (p.roughness, p.anisotropic, p.spec_trans, p.sheen, p.sheen_tint) = (0.5, 0.7, 0.5, 0.8, 0.5);
    });
    for (theta, phi) in [(20.0, 30.0), (70.0, 120.0)] {
        v.push(azimuth_case("principledthin anisotropic sheen", aniso.clone(), theta, phi));
    }
    let leaf = principled_thin(|p| (p.roughness, p.diff_trans, p.flatness) = (0.6, 1.5, 0.6));
    for wo in [40.0, 130.0] {
        v.push(case("principledthin diff_trans 1.5 flatness", leaf.clone(), wo, false));
    }
    let every = principled_thin(|p| {
        (p.roughness, p.anisotropic, p.spec_trans, p.eta) = (0.45, 0.3, 0.4, 1.7);
        (p.diff_trans, p.spec_tint, p.sheen, p.sheen_tint, p.flatness) = (1.0, 1.0, 0.3, 0.2, 0.4);
        p.rates = PrincipledThinRates {
            diffuse_reflectance: 0.5,
            diffuse_transmittance: 2.0,
            specular_reflectance: 1.5,
            specular_transmittance: 1.0,
        };
    });
    for (theta, phi) in [(45.0, 60.0), (160.0, 200.0)] {
        v.push(azimuth_case("principledthin every lobe, rates", every.clone(), theta, phi));
    }
}

fn blend(weight: f32, first: Bsdf, second: Bsdf, first_two_sided: bool) -> Bsdf {
    Bsdf::Blend(BlendBsdf::new(
        weight,
        BlendPart { bsdf: first, two_sided: first_two_sided },
        BlendPart { bsdf: second, two_sided: false },
    ))
}

fn principled_and_blend_cases(v: &mut Vec<BsdfCase>) {
    for wo in [0.0, 45.0, 80.0] {
        v.push(case("principled defaults", principled(|_| {}), wo, false));
    }
    let coated = principled(|p| {
        p.metallic = 0.7;
        p.roughness = 0.3;
        p.spec_tint = 0.4;
        p.clearcoat = 0.6;
        p.clearcoat_gloss = 0.3;
    });
    for wo in [30.0, 75.0] {
        v.push(case("principled metallic clearcoat", coated.clone(), wo, false));
    }
    let aniso = principled(|p| {
        p.roughness = 0.4;
        p.anisotropic = 0.8;
        p.sheen = 0.5;
        p.sheen_tint = 0.5;
        p.flatness = 0.5;
    });
    for wo in [20.0, 70.0] {
        v.push(case("principled anisotropic sheen", aniso.clone(), wo, false));
    }
    // Below the surface, 120° is beyond the critical angle of eta 1.5 (41.8° from the normal).
    let glassy = principled(|p| {
        p.roughness = 0.4;
        p.spec_trans = 0.7;
        p.eta = 1.5;
        p.anisotropic = 0.3;
    });
    for wo in [30.0, 80.0, 150.0, 120.0] {
        v.push(case("principled spec_trans 0.7", glassy.clone(), wo, false));
    }
    let gold = (rgb(0.143, 0.375, 1.442), rgb(3.983, 2.386, 1.603));
    let rough_gold =
        Bsdf::RoughConductor(RoughConductor { dist: ggx(0.3), eta: gold.0, k: gold.1, specular: Rgb::WHITE });
    let diffuse = Bsdf::Diffuse(Diffuse { reflectance: rgb(0.8, 0.5, 0.2) });
    for wo in [10.0, 70.0] {
        v.push(case(
            "blend 0.3 diffuse / rough gold",
            blend(0.3, diffuse.clone(), rough_gold.clone(), false),
            wo,
            false,
        ));
    }
    // A two-sided part seen from below: the diffuse part scatters, the gold one does not.
    v.push(case("blend 0.5 two-sided diffuse / rough gold", blend(0.5, diffuse, rough_gold, true), 120.0, false));
    let mirror = Bsdf::Conductor(Conductor { eta: gold.0, k: gold.1, specular: Rgb::WHITE });
    let plastic = Bsdf::Plastic(PlasticParams::new(rgb(0.6, 0.3, 0.1), Rgb::WHITE, 1.5, Some(ggx(0.3))));
    for wo in [0.0, 60.0] {
        v.push(case("blend 0.4 mirror / rough plastic", blend(0.4, mirror.clone(), plastic.clone(), false), wo, false));
    }
    let glass = Bsdf::RoughDielectric(RoughDielectric {
        dist: beckmann(0.3),
        eta: 1.5,
        reflect: Rgb::WHITE,
        transmit: Rgb::WHITE,
    });
    for wo in [40.0, 140.0] {
        v.push(case("blend 0.6 principled / rough glass", blend(0.6, glassy.clone(), glass.clone(), false), wo, false));
    }
}

struct Checked {
    case: BsdfCase,
    samples: Samples,
    integrals: Integrals,
}

/// Sampling and quadrature for all cases, computed once and shared by the tests below.
fn checked() -> &'static [Checked] {
    static RESULTS: OnceLock<Vec<Checked>> = OnceLock::new();
    RESULTS.get_or_init(|| {
        cases()
            .into_par_iter()
            .enumerate()
            .map(|(i, case)| {
                let samples = draw_samples(&case, SAMPLES, 1000 + i as u64);
                let integrals = integrate(&case);
                Checked { case, samples, integrals }
            })
            .collect()
    })
}

fn report(failures: Vec<String>) {
    assert!(failures.is_empty(), "{} case(s) failed:\n{}", failures.len(), failures.join("\n"));
}

/// The chi-square battery on `all`, failures described.
fn chi2_failures(all: &[Checked]) -> Vec<String> {
    let alpha = sidak(CHI2_SIGNIFICANCE, all.len());
    let mut failures = Vec::new();
    for c in all {
        match chi2_of(&c.samples, &c.integrals) {
            Err(e) => failures.push(format!("{}: {e}", c.case.name)),
            Ok(r) => {
                println!("{:45} chi2 {:10.1} dof {:4} p {:.3e}", c.case.name, r.statistic, r.dof, r.p_value);
                if r.p_value < alpha {
                    failures.push(format!("{}: p = {:.3e} < {alpha:.2e} ({r:?})", c.case.name, r.p_value));
                }
            }
        }
    }
    failures
}

#[test]
fn sampled_directions_follow_the_pdf() {
    report(chi2_failures(checked()));
}

#[test]
#[ignore = "long: run with `cargo test -- --ignored`"]
fn sampled_directions_follow_the_pdf_with_16_times_the_samples() {
    let all: Vec<Checked> = cases()
        .into_par_iter()
        .enumerate()
        .map(|(i, case)| {
            let samples = draw_samples(&case, 16 * SAMPLES, 5000 + i as u64);
            let integrals = integrate(&case);
            Checked { case, samples, integrals }
        })
        .collect();
    report(chi2_failures(&all));
}

#[test]
fn sample_weight_is_eval_over_pdf() {
    // The same float expressions recomputed from the sampled direction: only rounding
    // differs (a few ulps through normalisations and one division, far below 1e-3).
    let tolerance = 1e-3;
    let mut failures = Vec::new();
    for c in checked() {
        let s = &c.samples;
        if s.malformed > 0 {
            failures.push(format!("{}: {} malformed samples (direction or weight)", c.case.name, s.malformed));
        }
        if s.worst_weight_error > tolerance || s.worst_pdf_error > tolerance {
            failures.push(format!(
                "{}: weight vs eval/pdf off by {:.2e}, pdf off by {:.2e} (relative)",
                c.case.name, s.worst_weight_error, s.worst_pdf_error
            ));
        }
    }
    report(failures);
}

#[test]
fn pdf_integrates_to_at_most_one() {
    let all = checked();
    let k = z_critical(FALSE_ALARM, all.len());
    let mut failures = Vec::new();
    for c in all {
        let total = c.integrals.pdf_total();
        if total > 1.0 + QUADRATURE_TOLERANCE {
            failures.push(format!("{}: ∫ pdf = {total:.6} > 1", c.case.name));
        }
        if c.case.complete {
            // What the delta lobe does not take must be in the density.
            let n = c.samples.n as f64;
            let p_delta = c.samples.delta as f64 / n;
            let se = (p_delta * (1.0 - p_delta) / n).sqrt();
            if (total - (1.0 - p_delta)).abs() > k * se + QUADRATURE_TOLERANCE {
                failures.push(format!("{}: ∫ pdf = {total:.6} but 1 - P(delta) = {:.6}", c.case.name, 1.0 - p_delta));
            }
        }
    }
    report(failures);
}

#[test]
fn mean_sample_weight_matches_integrated_eval() {
    let all = checked();
    let k = z_critical(FALSE_ALARM, all.len());
    let mut failures = Vec::new();
    for c in all {
        let est = c.samples.albedo();
        let exact = c.integrals.eval_total;
        println!("{:45} albedo {:.5} ± {:.5}, ∫eval {:.5}", c.case.name, est.mean, est.se, exact);
        if (est.mean - exact).abs() > k * est.se + QUADRATURE_TOLERANCE {
            failures.push(format!(
                "{}: mean weight {:.5} ± {:.5} but ∫ eval dω = {exact:.5} ({:.1} standard errors)",
                c.case.name,
                est.mean,
                est.se,
                (est.mean - exact) / est.se
            ));
        }
    }
    report(failures);
}

/// Without absorption the hair model keeps all energy (its attenuations sum to one and each
/// lobe is a density): ∫ eval dω = 1 to quadrature precision, from every direction.
#[test]
fn hair_without_absorption_conserves_energy() {
    let mut failures = Vec::new();
    for c in checked().iter().filter(|c| c.case.name.starts_with("hair clear")) {
        let total = c.integrals.eval_total;
        println!("{:45} ∫eval {total:.6}", c.case.name);
        if (total - 1.0).abs() > 10.0 * QUADRATURE_TOLERANCE {
            failures.push(format!("{}: ∫ eval dω = {total:.6}, not 1", c.case.name));
        }
    }
    report(failures);
}

#[test]
fn quadrature_is_exact_on_the_diffuse_lobe() {
    for c in checked()
        .iter()
        .filter(|c| c.case.bsdf.tilt.is_none() && matches!(c.case.bsdf.bsdf, Bsdf::Diffuse(Diffuse { .. })))
    {
        let albedo = (0.8 + 0.5 + 0.2) / 3.0;
        assert!((c.integrals.pdf_total() - 1.0).abs() < QUADRATURE_TOLERANCE, "{}", c.integrals.pdf_total());
        assert!((c.integrals.eval_total - albedo).abs() < QUADRATURE_TOLERANCE, "{}", c.integrals.eval_total);
    }
}
