//! Materials: what a surface is made of, with textured parameters. `Material::bsdf`
//! evaluates the textures at a hit point and returns the [`Bsdf`] to scatter with.

mod principled_blend;
mod texture;
pub use principled_blend::{BlendMaterial, BlendMaterialPart, PrincipledMaterial, ScalarTexture};
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
    /// Diffuse base under a coating; `params` holds everything but the textured albedo.
    Plastic {
        diffuse: Texture,
        params: PlasticParams,
    },
    Black,
    /// Mitsuba's `principled`, with its textured parameters.
    Principled(PrincipledMaterial),
    /// Mitsuba's `blendbsdf` of two material kinds.
    Blend(BlendMaterial),
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

    /// True for materials that let light through (both faces are meaningful).
    pub fn is_transmissive(&self) -> bool {
        self.kind.is_transmissive()
    }

    /// The reflectance a denoiser wants as its albedo guide: the diffuse texture where
    /// there is one, the specular tint of metals, the transmission tint of dielectrics.
    pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.kind.albedo(uv)
    }

    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        self.kind.bsdf(uv)
    }
}

impl MaterialKind {
    /// See [`Material::is_transmissive`].
    pub fn is_transmissive(&self) -> bool {
        match self {
            MaterialKind::Dielectric { .. }
            | MaterialKind::RoughDielectric { .. }
            | MaterialKind::ThinDielectric { .. } => true,
            MaterialKind::Principled(p) => p.is_transmissive(),
            MaterialKind::Blend(b) => b.is_transmissive(),
            _ => false,
        }
    }

    /// See [`Material::albedo`].
    pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
        match self {
            MaterialKind::Diffuse { reflectance } => reflectance.eval(uv),
            MaterialKind::Phong { kd, ks, .. } => (kd.eval(uv) + *ks).map(|v| v.min(1.0)),
            MaterialKind::Conductor { specular, .. } | MaterialKind::RoughConductor { specular, .. } => *specular,
            MaterialKind::Dielectric { transmit, .. }
            | MaterialKind::RoughDielectric { transmit, .. }
            | MaterialKind::ThinDielectric { transmit, .. } => *transmit,
            MaterialKind::Plastic { diffuse, .. } => diffuse.eval(uv),
            MaterialKind::Black => Rgb::BLACK,
            MaterialKind::Principled(p) => p.base_color.eval(uv),
            MaterialKind::Blend(b) => b.albedo(uv),
        }
    }

    /// The BSDF at surface point `uv`: textures looked up.
    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        match self {
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
            MaterialKind::Plastic { diffuse, params } => {
                Bsdf::Plastic(PlasticParams { diffuse: diffuse.eval(uv), ..*params })
            }
            MaterialKind::Black => Bsdf::Black,
            MaterialKind::Principled(p) => Bsdf::Principled(p.bsdf(uv)),
            MaterialKind::Blend(b) => b.bsdf(uv),
        }
    }
}

/// Complex refractive indices (eta, k) in RGB for Mitsuba's named conductor presets: the
/// values Mitsuba 3.9.1's `scalar_rgb` variant uses (read back from it with `mi.traverse`).
pub fn conductor_preset(name: &str) -> Option<(Rgb, Rgb)> {
    use crate::math::rgb;
    Some(match name {
        "Au" => (rgb(0.143036, 0.375307, 1.44205), rgb(3.983, 2.38556, 1.60336)),
        "Ag" => (rgb(0.155276, 0.116728, 0.138388), rgb(4.82835, 3.12222, 2.1469)),
        "Cu" => (rgb(0.201005, 0.92375, 1.10222), rgb(3.91326, 2.45305, 2.14209)),
        "Al" => (rgb(1.6575, 0.880405, 0.521244), rgb(9.22381, 6.2695, 4.837)),
        "Cr" => (rgb(4.36967, 2.91651, 1.6549), rgb(5.20655, 4.23131, 3.7547)),
        "none" => (Rgb::BLACK, Rgb::WHITE),
        _ => return None,
    })
}
