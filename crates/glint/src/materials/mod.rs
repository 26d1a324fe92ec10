//! Materials: what a surface is made of, with textured parameters. `Material::bsdf`
//! evaluates the textures at a hit point and returns the [`Bsdf`] to scatter with.

mod texture;
pub use texture::{Bitmap, Texture};

use crate::bsdf::{Bsdf, Microfacet, Phong, PlasticParams};
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
        dist: Microfacet,
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
        dist: Microfacet,
        eta: f32,
        reflect: Rgb,
        transmit: Rgb,
    },
    ThinDielectric {
        eta: f32,
        reflect: Rgb,
        transmit: Rgb,
    },
    Plastic {
        diffuse: Texture,
        specular: Rgb,
        eta: f32,
        dist: Option<Microfacet>,
        fdr_internal: f32,
    },
    Black,
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
        let p = PlasticParams::new(Rgb::BLACK, specular, eta, dist);
        MaterialKind::Plastic { diffuse, specular, eta, dist, fdr_internal: p.fdr_internal }
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

    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        match &self.kind {
            MaterialKind::Diffuse { reflectance } => Bsdf::Diffuse { reflectance: reflectance.eval(uv) },
            MaterialKind::Phong { kd, ks, exponent } => {
                Bsdf::Phong(Phong { kd: kd.eval(uv), ks: *ks, exponent: *exponent })
            }
            MaterialKind::Conductor { eta, k, specular } => Bsdf::Conductor { eta: *eta, k: *k, specular: *specular },
            MaterialKind::RoughConductor { dist, eta, k, specular } => {
                Bsdf::RoughConductor { dist: *dist, eta: *eta, k: *k, specular: *specular }
            }
            MaterialKind::Dielectric { eta, reflect, transmit } => {
                Bsdf::Dielectric { eta: *eta, reflect: *reflect, transmit: *transmit }
            }
            MaterialKind::RoughDielectric { dist, eta, reflect, transmit } => {
                Bsdf::RoughDielectric { dist: *dist, eta: *eta, reflect: *reflect, transmit: *transmit }
            }
            MaterialKind::ThinDielectric { eta, reflect, transmit } => {
                Bsdf::ThinDielectric { eta: *eta, reflect: *reflect, transmit: *transmit }
            }
            MaterialKind::Plastic { diffuse, specular, eta, dist, fdr_internal } => Bsdf::Plastic(PlasticParams {
                diffuse: diffuse.eval(uv),
                specular: *specular,
                eta: *eta,
                dist: *dist,
                fdr_internal: *fdr_internal,
            }),
            MaterialKind::Black => Bsdf::Black,
        }
    }
}

/// Complex refractive indices (eta, k) at RGB wavelengths for Mitsuba's named conductor
/// presets, from the same measured data (Palik; averaged to sRGB primaries).
pub fn conductor_preset(name: &str) -> Option<(Rgb, Rgb)> {
    use crate::math::rgb;
    Some(match name {
        "Au" => (rgb(0.1431189557, 0.3749570432, 1.4424785571), rgb(3.9831604247, 2.3857207478, 1.6032152899)),
        "Ag" => (rgb(0.1552646489, 0.1167232965, 0.1383806959), rgb(4.8283433224, 3.1222459278, 2.1469504455)),
        "Cu" => (rgb(0.2004376970, 0.9240334304, 1.1022119527), rgb(3.9129485033, 2.4528477015, 2.1421879552)),
        "Al" => (rgb(1.6574599595, 0.8803689579, 0.5212287346), rgb(9.2238691996, 6.2695232477, 4.8370012281)),
        "Cr" => (rgb(4.3696828663, 2.9167024892, 1.6547005413), rgb(5.2064337956, 4.2313645277, 3.7549467933)),
        "none" => (Rgb::BLACK, Rgb::WHITE),
        _ => return None,
    })
}
