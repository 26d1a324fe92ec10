//! Materials: what a surface is made of, with textured parameters. `Material::bsdf`
//! evaluates the textures at a hit point and returns the [`Bsdf`] to scatter with.

mod roughness;
mod texture;
pub use roughness::RoughnessMap;
pub use texture::{Bitmap, Texture};

use crate::bsdf::{Bsdf, Microfacet, PPlasticParams, Phong, PlasticParams};
use crate::math::Rgb;

#[derive(Clone, Debug)]
pub enum MaterialKind {
    Diffuse {
        reflectance: Texture,
    },
    /// Whitted-style diffuse + glossy; `ks` may be zero.
    Phong {
        kd: Texture,
        ks: Rgb,
        exponent: f32,
    },
    Conductor {
        eta: Rgb,
        k: Rgb,
        specular: Rgb,
    },
    RoughConductor {
        dist: RoughnessMap,
        eta: Rgb,
        k: Rgb,
        specular: Rgb,
    },
    Dielectric {
        eta: f32,
        reflect: Rgb,
        transmit: Rgb,
    },
    RoughDielectric {
        dist: RoughnessMap,
        eta: f32,
        reflect: Rgb,
        transmit: Rgb,
    },
    ThinDielectric {
        eta: f32,
        reflect: Rgb,
        transmit: Rgb,
    },
    /// Diffuse base under a coating; `params` holds everything but the textured albedo.
    Plastic {
        diffuse: Texture,
        params: PlasticParams,
    },
    Black,
    /// Mitsuba's `pplastic` (unpolarized); `specular_probability` is fixed per material.
    PPlastic {
        diffuse: Texture,
        specular: Rgb,
        eta: f32,
        dist: RoughnessMap,
        specular_probability: f32,
    },
}

#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
    /// Opaque materials scatter on both faces when true; otherwise the back face is black
    /// (Mitsuba's default, undone there by `twosided`). Dielectrics ignore this.
    pub two_sided: bool,
}

impl Material {
    pub fn new(name: impl Into<String>, kind: MaterialKind, two_sided: bool) -> Material {
        Material { name: name.into(), kind, two_sided }
    }

    pub fn plastic(diffuse: Texture, specular: Rgb, eta: f32, dist: Option<Microfacet>) -> MaterialKind {
        MaterialKind::Plastic { diffuse, params: PlasticParams::new(Rgb::BLACK, specular, eta, dist) }
    }

    /// [`Material::plastic`] with Mitsuba's `nonlinear` internal scattering.
    pub fn nonlinear_plastic(diffuse: Texture, specular: Rgb, eta: f32, dist: Option<Microfacet>) -> MaterialKind {
        let params = PlasticParams { nonlinear: true, ..PlasticParams::new(Rgb::BLACK, specular, eta, dist) };
        MaterialKind::Plastic { diffuse, params }
    }

    /// True for materials that let light through (both faces are meaningful).
    pub fn is_transmissive(&self) -> bool {
        matches!(
            self.kind,
            MaterialKind::Dielectric { .. }
                | MaterialKind::RoughDielectric { .. }
                | MaterialKind::ThinDielectric { .. }
        )
    }

    /// The reflectance a denoiser wants as its albedo guide: the diffuse texture where
    /// there is one, the specular tint of metals, the transmission tint of dielectrics.
    pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
        match &self.kind {
            MaterialKind::Diffuse { reflectance } => reflectance.eval(uv),
            MaterialKind::Phong { kd, ks, .. } => (kd.eval(uv) + *ks).map(|v| v.min(1.0)),
            MaterialKind::Conductor { specular, .. } | MaterialKind::RoughConductor { specular, .. } => *specular,
            MaterialKind::Dielectric { transmit, .. }
            | MaterialKind::RoughDielectric { transmit, .. }
            | MaterialKind::ThinDielectric { transmit, .. } => *transmit,
            MaterialKind::Plastic { diffuse, .. } | MaterialKind::PPlastic { diffuse, .. } => diffuse.eval(uv),
            MaterialKind::Black => Rgb::BLACK,
        }
    }

    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        match &self.kind {
            MaterialKind::Diffuse { reflectance } => Bsdf::Diffuse { reflectance: reflectance.eval(uv) },
            MaterialKind::Phong { kd, ks, exponent } => {
                Bsdf::Phong(Phong { kd: kd.eval(uv), ks: *ks, exponent: *exponent })
            }
            MaterialKind::Conductor { eta, k, specular } => Bsdf::Conductor { eta: *eta, k: *k, specular: *specular },
            MaterialKind::RoughConductor { dist, eta, k, specular } => {
                Bsdf::RoughConductor { dist: dist.at(uv), eta: *eta, k: *k, specular: *specular }
            }
            MaterialKind::Dielectric { eta, reflect, transmit } => {
                Bsdf::Dielectric { eta: *eta, reflect: *reflect, transmit: *transmit }
            }
            MaterialKind::RoughDielectric { dist, eta, reflect, transmit } => {
                Bsdf::RoughDielectric { dist: dist.at(uv), eta: *eta, reflect: *reflect, transmit: *transmit }
            }
            MaterialKind::ThinDielectric { eta, reflect, transmit } => {
                Bsdf::ThinDielectric { eta: *eta, reflect: *reflect, transmit: *transmit }
            }
            MaterialKind::Plastic { diffuse, params } => {
                Bsdf::Plastic(PlasticParams { diffuse: diffuse.eval(uv), ..*params })
            }
            MaterialKind::Black => Bsdf::Black,
            MaterialKind::PPlastic { diffuse, specular, eta, dist, specular_probability } => {
                Bsdf::PPlastic(PPlasticParams {
                    diffuse: diffuse.eval(uv),
                    specular: *specular,
                    eta: *eta,
                    dist: dist.at(uv),
                    specular_probability: *specular_probability,
                })
            }
        }
    }
}

/// Complex refractive indices (eta, k) in RGB for Mitsuba's named conductor presets: the
/// values Mitsuba 3.9.1's `scalar_rgb` variant uses (read back from it with `mi.traverse`),
/// every preset it accepts (its `W_palik` fails to load there, so is absent here too).
pub fn conductor_preset(name: &str) -> Option<(Rgb, Rgb)> {
    use crate::math::rgb;
    Some(match name {
        "a-C" => (rgb(2.94405, 2.22714, 1.96816), rgb(0.887465, 0.799299, 0.81529)),
        "Ag" => (rgb(0.155276, 0.116728, 0.138388), rgb(4.82835, 3.12222, 2.1469)),
        "Al" => (rgb(1.6575, 0.880405, 0.521244), rgb(9.22381, 6.2695, 4.837)),
        "AlAs" => (rgb(3.6053, 3.23294, 2.21632), rgb(0.000679437, 0.0, 0.00751271)),
        "AlAs_palik" => (rgb(3.6053, 3.23294, 2.21632), rgb(0.000679437, 0.0, 0.00751271)),
        "AlSb" => (rgb(0.0, 4.13937, 4.66925), rgb(0.0, 0.0940091, 1.30057)),
        "AlSb_palik" => (rgb(0.0, 4.13937, 4.66925), rgb(0.0, 0.0940091, 1.30057)),
        "Au" => (rgb(0.143036, 0.375307, 1.44205), rgb(3.983, 2.38556, 1.60336)),
        "Be" => (rgb(4.18501, 3.18503, 2.78406), rgb(3.83547, 3.01012, 2.86899)),
        "Be_palik" => (rgb(4.18501, 3.18503, 2.78406), rgb(3.83547, 3.01012, 2.86899)),
        "Cr" => (rgb(4.36967, 2.91651, 1.6549), rgb(5.20655, 4.23131, 3.7547)),
        "CsI" => (rgb(2.1449, 1.70232, 1.66243), rgb(0.0, 0.0, 0.0)),
        "CsI_palik" => (rgb(2.1449, 1.70232, 1.66243), rgb(0.0, 0.0, 0.0)),
        "Cu" => (rgb(0.201005, 0.92375, 1.10222), rgb(3.91326, 2.45305, 2.14209)),
        "Cu_palik" => (rgb(0.213229, 0.919715, 1.10241), rgb(3.92187, 2.45733, 2.13658)),
        "Cu2O" => (rgb(3.55177, 2.94987, 2.75188), rgb(0.114207, 0.193897, 0.606134)),
        "Cu2O_palik" => (rgb(3.55177, 2.94987, 2.75188), rgb(0.114207, 0.193897, 0.606134)),
        "CuO" => (rgb(3.24754, 2.44781, 2.21022), rgb(0.52109, 0.570031, 0.722179)),
        "CuO_palik" => (rgb(3.24754, 2.44781, 2.21022), rgb(0.52109, 0.570031, 0.722179)),
        "d-C" => (rgb(2.70872, 2.31883, 2.2289), rgb(0.0, 0.0, 0.0)),
        "d-C_palik" => (rgb(2.70872, 2.31883, 2.2289), rgb(0.0, 0.0, 0.0)),
        "Hg" => (rgb(2.39894, 1.44003, 0.90957), rgb(6.32759, 4.37192, 3.42176)),
        "Hg_palik" => (rgb(2.39894, 1.44003, 0.90957), rgb(6.32759, 4.37192, 3.42176)),
        "HgTe" => (rgb(4.77904, 3.2312, 2.6599), rgb(1.63161, 1.58081, 1.72929)),
        "HgTe_palik" => (rgb(4.77904, 3.2312, 2.6599), rgb(1.63161, 1.58081, 1.72929)),
        "Ir" => (rgb(3.0863, 2.08219, 1.61791), rgb(5.59215, 4.06709, 3.26731)),
        "Ir_palik" => (rgb(3.0863, 2.08219, 1.61791), rgb(5.59215, 4.06709, 3.26731)),
        "K" => (rgb(0.0640432, 0.0464098, 0.0381849), rgb(2.1042, 1.34894, 0.913126)),
        "K_palik" => (rgb(0.0640432, 0.0464098, 0.0381849), rgb(2.1042, 1.34894, 0.913126)),
        "Li" => (rgb(0.265791, 0.195618, 0.220949), rgb(3.54015, 2.31112, 1.66861)),
        "Li_palik" => (rgb(0.265791, 0.195618, 0.220949), rgb(3.54015, 2.31112, 1.66861)),
        "MgO" => (rgb(2.08958, 1.65072, 1.59488), rgb(4.3327e-12, 0.0, 2.49865e-11)),
        "MgO_palik" => (rgb(2.08958, 1.65072, 1.59488), rgb(4.3327e-12, 0.0, 2.49865e-11)),
        "Mo" => (rgb(4.48397, 3.52513, 2.77631), rgb(4.11144, 3.42083, 3.15061)),
        "Mo_palik" => (rgb(4.48397, 3.52513, 2.77631), rgb(4.11144, 3.42083, 3.15061)),
        "Na_palik" => (rgb(0.0602694, 0.0561409, 0.0619884), rgb(3.17927, 2.11249, 1.57904)),
        "Nb" => (rgb(3.42007, 2.79009, 2.39563), rgb(3.44139, 2.73767, 2.57975)),
        "Nb_palik" => (rgb(3.42007, 2.79009, 2.39563), rgb(3.44139, 2.73767, 2.57975)),
        "Ni_palik" => (rgb(2.3673, 1.66337, 1.46708), rgb(4.49881, 3.05015, 2.34544)),
        "Rh" => (rgb(2.58579, 1.86022, 1.55426), rgb(6.78226, 4.70299, 3.97607)),
        "Rh_palik" => (rgb(2.58579, 1.86022, 1.55426), rgb(6.78226, 4.70299, 3.97607)),
        "Se" => (rgb(4.05831, 2.84294, 2.82085), rgb(0.75405, 0.638444, 0.521808)),
        "Se_palik" => (rgb(4.05831, 2.84294, 2.82085), rgb(0.75405, 0.638444, 0.521808)),
        "SiC" => (rgb(3.17234, 2.52597, 2.47937), rgb(7.53766e-07, 0.0, 1.01925e-05)),
        "SiC_palik" => (rgb(3.17234, 2.52597, 2.47937), rgb(7.53766e-07, 0.0, 1.01925e-05)),
        "SnTe" => (rgb(4.52425, 1.98164, 1.28159), rgb(0.0, 0.0, 0.0)),
        "SnTe_palik" => (rgb(4.52425, 1.98164, 1.28159), rgb(0.0, 0.0, 0.0)),
        "Ta" => (rgb(2.06272, 2.39294, 2.62793), rgb(2.40836, 1.74149, 1.94703)),
        "Ta_palik" => (rgb(2.06272, 2.39294, 2.62793), rgb(2.40836, 1.74149, 1.94703)),
        "Te" => (rgb(7.39023, 4.4821, 2.63711), rgb(3.25602, 3.52706, 3.29205)),
        "Te_palik" => (rgb(7.39023, 4.4821, 2.63711), rgb(3.25602, 3.52706, 3.29205)),
        "ThF4" => (rgb(1.83071, 1.44223, 1.38765), rgb(0.0, 0.0, 0.0)),
        "ThF4_palik" => (rgb(1.83071, 1.44223, 1.38765), rgb(0.0, 0.0, 0.0)),
        "TiC" => (rgb(3.70053, 2.83742, 2.58229), rgb(3.26564, 2.35159, 2.17279)),
        "TiC_palik" => (rgb(3.70053, 2.83742, 2.58229), rgb(3.26564, 2.35159, 2.17279)),
        "TiN" => (rgb(1.64845, 1.15052, 1.37982), rgb(3.36833, 1.9435, 1.10207)),
        "TiN_palik" => (rgb(1.64845, 1.15052, 1.37982), rgb(3.36833, 1.9435, 1.10207)),
        "TiO2" => (rgb(3.45661, 2.80174, 2.90517), rgb(0.000105265, 0.0, 0.000652887)),
        "TiO2_palik" => (rgb(3.45661, 2.80174, 2.90517), rgb(0.000105265, 0.0, 0.000652887)),
        "VC" => (rgb(3.65757, 2.75274, 2.53267), rgb(3.0683, 2.19869, 1.96319)),
        "VC_palik" => (rgb(3.65757, 2.75274, 2.53267), rgb(3.0683, 2.19869, 1.96319)),
        "V_palik" => (rgb(4.27758, 3.51295, 2.76107), rgb(3.4913, 2.88945, 3.11152)),
        "VN" => (rgb(2.8656, 2.11919, 1.94009), rgb(3.03224, 2.05612, 1.61631)),
        "VN_palik" => (rgb(2.8656, 2.11919, 1.94009), rgb(3.03224, 2.05612, 1.61631)),
        "W" => (rgb(4.37082, 3.30025, 2.99841), rgb(3.50064, 2.60487, 2.27323)),
        "none" => (Rgb::BLACK, Rgb::WHITE),
        _ => return None,
    })
}
