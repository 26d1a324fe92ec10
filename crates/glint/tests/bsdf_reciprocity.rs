//! Helmholtz reciprocity of every non-delta BSDF, in glint's radiance convention: with
//! f = eval / |cos θi| and η(w) the index on w's side, f(wo, wi) / η(wo)² = f(wi, wo) / η(wi)²
//! (Veach 1997, §5.2). For reflection both sides match and f is symmetric; for refraction the
//! (η(wo)/η(wi))² radiance scaling is what makes the two sides agree.

use glint::bsdf::{fresnel_dielectric, Microfacet, MicrofacetKind};
use glint::materials::{
    BlendBsdf, BlendPart, Bsdf, Diffuse, GltfPbr, HairBsdf, PPlasticParams, Phong, PlasticParams, Principled,
    PrincipledInputs, PrincipledRates, PrincipledThin, PrincipledThinInputs, PrincipledThinRates, RoughConductor,
    RoughDielectric,
};
use glint::math::{rgb, vec3, Rgb, Vec3};
use glint::sampling::{warp, Rng};

fn bsdfs() -> Vec<(&'static str, Bsdf)> {
    let ggx = Microfacet::new(MicrofacetKind::Ggx, 0.3);
    let beckmann = Microfacet::new(MicrofacetKind::Beckmann, 0.4);
    let ggx_aniso = Microfacet::anisotropic(MicrofacetKind::Ggx, 0.1, 0.5);
    let beckmann_aniso = Microfacet::anisotropic(MicrofacetKind::Beckmann, 0.6, 0.15);
    let gold = (rgb(0.143, 0.375, 1.442), rgb(3.983, 2.386, 1.603));
    vec![
        ("diffuse", Bsdf::Diffuse(Diffuse { reflectance: rgb(0.8, 0.5, 0.2) })),
        ("phong", Bsdf::Phong(Phong { kd: Rgb::splat(0.4), ks: Rgb::splat(0.5), exponent: 20.0 })),
        (
            "rough conductor GGX",
            Bsdf::RoughConductor(RoughConductor { dist: ggx, eta: gold.0, k: gold.1, specular: Rgb::WHITE }),
        ),
        (
            "rough conductor Beckmann",
            Bsdf::RoughConductor(RoughConductor { dist: beckmann, eta: gold.0, k: gold.1, specular: Rgb::WHITE }),
        ),
        (
            "rough dielectric GGX",
            Bsdf::RoughDielectric(RoughDielectric { dist: ggx, eta: 1.5, reflect: Rgb::WHITE, transmit: Rgb::WHITE }),
        ),
        (
            "rough dielectric Beckmann",
            Bsdf::RoughDielectric(RoughDielectric {
                dist: beckmann,
                eta: 1.33,
                reflect: Rgb::WHITE,
                transmit: Rgb::WHITE,
            }),
        ),
        (
            "anisotropic rough conductor GGX",
            Bsdf::RoughConductor(RoughConductor { dist: ggx_aniso, eta: gold.0, k: gold.1, specular: Rgb::WHITE }),
        ),
        (
            "anisotropic rough conductor Beckmann",
            Bsdf::RoughConductor(RoughConductor { dist: beckmann_aniso, eta: gold.0, k: gold.1, specular: Rgb::WHITE }),
        ),
        (
            "anisotropic rough dielectric GGX",
            Bsdf::RoughDielectric(RoughDielectric {
                dist: ggx_aniso,
                eta: 1.5,
                reflect: Rgb::WHITE,
                transmit: Rgb::WHITE,
            }),
        ),
        (
            "anisotropic rough dielectric Beckmann",
            Bsdf::RoughDielectric(RoughDielectric {
                dist: beckmann_aniso,
                eta: 1.33,
                reflect: Rgb::WHITE,
                transmit: Rgb::WHITE,
            }),
        ),
        (
            "pplastic",
            Bsdf::PPlastic(PPlasticParams {
                diffuse: rgb(0.3, 0.2, 0.1),
                specular: Rgb::WHITE,
                eta: 1.49,
                dist: beckmann_aniso,
                specular_probability: 0.7,
            }),
        ),
        ("smooth plastic", Bsdf::Plastic(PlasticParams::new(rgb(0.6, 0.3, 0.1), Rgb::WHITE, 1.5, None))),
        (
            "nonlinear rough plastic",
            Bsdf::Plastic(PlasticParams {
                nonlinear: true,
                ..PlasticParams::new(rgb(0.9, 0.3, 0.1), Rgb::WHITE, 1.5, Some(beckmann))
            }),
        ),
        ("rough plastic", Bsdf::Plastic(PlasticParams::new(rgb(0.6, 0.3, 0.1), Rgb::WHITE, 1.5, Some(ggx)))),
        ("principled, every lobe", principled(0.0)),
        ("principled with spec_trans", principled(0.6)),
        // A thin sheet does not bend light: η is 1 on both sides and f itself is symmetric,
        // but for Mitsuba's specular transmission (see `reflection_only`).
        ("principledthin, every lobe", principled_thin(0.5, 0.8)),
        ("principledthin, diffuse reflection and transmission", principled_thin(0.0, 0.8)),
        (
            "blend of principled and rough gold",
            Bsdf::Blend(BlendBsdf::new(
                0.35,
                BlendPart { bsdf: principled(0.0), two_sided: true },
                BlendPart {
                    bsdf: Bsdf::RoughConductor(RoughConductor {
                        dist: ggx,
                        eta: gold.0,
                        k: gold.1,
                        specular: Rgb::WHITE,
                    }),
                    two_sided: false,
                },
            )),
        ),
        ("glTF metal and dielectric with sheen", gltf(0.0, true)),
        ("glTF thin transmission", gltf(0.7, true)),
        ("glTF volume transmission", gltf(0.7, false)),
    ]
}

/// A glTF material with every reciprocal lobe (the clearcoat is not: the extension weights
/// it by the Fresnel term of the view direction alone).
fn gltf(transmission: f32, thin_walled: bool) -> Bsdf {
    Bsdf::GltfPbr(GltfPbr {
        base_color: rgb(0.8, 0.5, 0.3),
        metallic: 0.3,
        roughness: 0.5,
        ior: 1.5,
        specular: 0.8,
        specular_color: rgb(1.2, 0.9, 0.7),
        transmission,
        thin_walled,
        clearcoat: 0.0,
        clearcoat_roughness: 0.0,
        sheen_color: rgb(0.4, 0.5, 0.6),
        sheen_roughness: 0.4,
    })
}

fn principled(spec_trans: f32) -> Bsdf {
    Bsdf::Principled(Principled::new(&PrincipledInputs {
        base_color: rgb(0.8, 0.4, 0.2),
        roughness: 0.45,
        anisotropic: 0.5,
        metallic: 0.3,
        spec_trans,
        eta: 1.45,
        spec_tint: 0.3,
        sheen: 0.4,
        sheen_tint: 0.5,
        flatness: 0.3,
        clearcoat: 0.5,
        clearcoat_gloss: 0.2,
        rates: PrincipledRates::default(),
    }))
}

fn principled_thin(spec_trans: f32, diff_trans: f32) -> Bsdf {
    Bsdf::PrincipledThin(PrincipledThin::new(&PrincipledThinInputs {
        base_color: rgb(0.8, 0.4, 0.2),
        roughness: 0.45,
        anisotropic: 0.5,
        spec_trans,
        eta: 1.4,
        spec_tint: 0.3,
        sheen: 0.4,
        sheen_tint: 0.5,
        flatness: 0.3,
        diff_trans,
        rates: PrincipledThinRates::default(),
    }))
}

fn eta_of(bsdf: &Bsdf, w: Vec3) -> f32 {
    match bsdf {
        Bsdf::RoughDielectric(RoughDielectric { eta, .. }) if w.z < 0.0 => *eta,
        Bsdf::Principled(p) if w.z < 0.0 && p.spec_trans > 0.0 => p.eta,
        Bsdf::GltfPbr(m) if w.z < 0.0 && !m.thin_walled => m.ior,
        _ => 1.0,
    }
}

/// BSDFs checked on pairs of directions on the same side only. Mitsuba's `principledthin`
/// is not reciprocal in its specular transmission: it mirrors the transmitted direction to
/// find the half vector but tests the microfacet compatibility (and Smith's one-sided
/// masking) with the unmirrored one, so a pair can pass one way and fail the other (glint
/// keeps Mitsuba's term: both renderers must agree).
fn reflection_only(bsdf: &Bsdf) -> bool {
    matches!(bsdf, Bsdf::PrincipledThin(p) if p.spec_trans > 0.0)
}

#[test]
fn bsdfs_are_reciprocal() {
    let mut rng = Rng::new(42, 7);
    let mut failures = Vec::new();
    for (name, bsdf) in bsdfs() {
        let mut checked = 0;
        for _ in 0..100_000 {
            let wo = warp::uniform_sphere(rng.next_2d());
            let mut wi = warp::uniform_sphere(rng.next_2d());
            if reflection_only(&bsdf) && wo.z * wi.z < 0.0 {
                wi.z = -wi.z;
            }
            // Skip directions grazing the surface or the microfacet (the generalised half
            // vector), or, for glass, near the critical angle: there f32 cosines (and 1 - F,
            // with its square-root singularity at total internal reflection) lose most of
            // their digits and the two sides cannot agree closely.
            let h = (wi * eta_of(&bsdf, wi) + wo * eta_of(&bsdf, wo)).normalize();
            let cos_t = match &bsdf {
                Bsdf::RoughDielectric(RoughDielectric { eta, .. }) => {
                    fresnel_dielectric(wo.dot(h) * h.z.signum(), *eta).cos_t
                }
                Bsdf::Principled(p) if p.spec_trans > 0.0 => fresnel_dielectric(wo.dot(h) * h.z.signum(), p.eta).cos_t,
                Bsdf::GltfPbr(m) if !m.thin_walled => fresnel_dielectric(wo.dot(h) * h.z.signum(), m.ior).cos_t,
                _ => 1.0,
            };
            if [wo.z, wi.z, wo.dot(h), wi.dot(h), cos_t].iter().any(|c| c.abs() < 0.05) {
                continue;
            }
            let a = bsdf.eval(wo, wi).average() / wi.z.abs() / eta_of(&bsdf, wo).powi(2);
            let b = bsdf.eval(wi, wo).average() / wo.z.abs() / eta_of(&bsdf, wi).powi(2);
            if a == 0.0 && b == 0.0 {
                continue;
            }
            checked += 1;
            // Both sides are the same float expressions with the roles swapped, so only
            // rounding differs (measured under 1e-5); a wrong factor is off by far more (a
            // missing η² by η⁴ ≈ 5). Below 1e-6 both sides are rounding noise.
            let tolerance = 1e-4;
            if (a - b).abs() > tolerance * a.abs().max(b.abs()) + 1e-6 {
                failures.push(format!("{name}: wo {wo:?} wi {wi:?}: f/η(wo)² = {a}, reversed {b}"));
                break;
            }
        }
        assert!(checked > 1000 || !failures.is_empty(), "{name}: only {checked} non-zero pairs");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Mitsuba's `hair` (Chiang et al. 2016, as pbrt-v4 also has it) is not reciprocal in
/// general, so it is not in the test above: the offset h across the fibre is the viewing
/// direction's, the attenuation is computed along the viewing direction's refracted path, and
/// the scale tilt shifts the viewing side's lobes only (Mitsuba flags the plugin
/// non-symmetric). Where none of the three breaks the symmetry the model is reciprocal, and
/// that is checked: no tilt, both directions in the plane of the normal and the fibre (h = 0
/// on either side, front or back, so the R, TT and TRT lobes and the rest all contribute)
/// and equal |sin θ|. The same pairs with a 3° tilt must differ: the check sees an asymmetry.
#[test]
fn hair_is_reciprocal_where_the_model_is() {
    let mut rng = Rng::new(17, 3);
    let (mut checked, mut tilted_differ, mut failures) = (0, 0, Vec::new());
    for case in 0..2000 {
        let sigma_a = Rgb { r: 2.0 * rng.next_f32(), g: 2.0 * rng.next_f32(), b: 2.0 * rng.next_f32() };
        let (eta, beta_m, beta_n) = (1.2 + rng.next_f32(), 0.1 + 0.8 * rng.next_f32(), 0.1 + 0.8 * rng.next_f32());
        let straight = HairBsdf::new(sigma_a, eta, beta_m, beta_n, 0.0);
        let tilted = HairBsdf::new(sigma_a, eta, beta_m, beta_n, 3.0);
        // |sin θ| below 0.9 keeps cos θ (the |cos| the eval carries) away from zero.
        let sin_theta = 0.9 * (2.0 * rng.next_f32() - 1.0);
        let cos_theta = (1.0 - sin_theta * sin_theta).sqrt();
        let side = |bit: usize| if case >> bit & 1 == 0 { 1.0 } else { -1.0 };
        let wo = vec3(0.0, sin_theta, side(0) * cos_theta);
        let wi = vec3(0.0, side(1) * sin_theta, side(2) * cos_theta);
        let f = |b: &HairBsdf, wo: Vec3, wi: Vec3| Bsdf::Hair(*b).eval(wo, wi).average() / wi.z.abs();
        let (a, b) = (f(&straight, wo, wi), f(&straight, wi, wo));
        if !(a > 1e-6 || b > 1e-6) {
            continue;
        }
        checked += 1;
        // The same float expressions with the roles swapped: only rounding differs.
        if (a - b).abs() > 1e-4 * a.max(b) {
            failures.push(format!("sigma_a {sigma_a:?} eta {eta} wo {wo:?} wi {wi:?}: {a} reversed {b}"));
        }
        let (ta, tb) = (f(&tilted, wo, wi), f(&tilted, wi, wo));
        if (ta - tb).abs() > 1e-3 * ta.max(tb) {
            tilted_differ += 1;
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(checked > 1500, "only {checked} non-zero pairs");
    assert!(tilted_differ > checked / 2, "the tilt broke the symmetry on only {tilted_differ} of {checked} pairs");
}
