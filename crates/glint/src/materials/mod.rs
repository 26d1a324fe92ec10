//! Materials: what a surface is made of, with textured parameters. `Material::bsdf`
//! evaluates the textures at a hit point and returns the [`Bsdf`] to scatter with.

mod blend;
mod conductor_presets;
mod gltf;
mod principled;
mod roughness;
mod surface;
mod texture;
pub use blend::{BlendMaterial, BlendMaterialPart};
pub use gltf::{
    GltfAlpha, GltfExtensionTextures, GltfMaterial, GltfTexture, ALPHA_ATTRIBUTE, COLOR_ATTRIBUTE, TANGENT_ATTRIBUTE,
    TANGENT_SIGN_ATTRIBUTE, UV1_ATTRIBUTE,
};
pub use principled::PrincipledMaterial;
pub use roughness::RoughnessMap;
pub use surface::Perturbation;
pub use texture::{Bitmap, ScalarTexture, Texture, TexturePoint};

use crate::bsdf::{
    Black, Bsdf, Conductor, Dielectric, Diffuse, HairBsdf, Microfacet, Null, PPlasticParams, Phong, PlasticParams,
    RoughConductor, RoughDielectric, ThinDielectric,
};
use crate::math::Rgb;

#[derive(Clone, Debug)]
// Unboxed on purpose: materials are read at every hit, and a box is a pointer chase.
#[allow(clippy::large_enum_variant)]
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
    /// `nested`, shaded in a frame tilted by a tangent-space normal map (Mitsuba's
    /// `normalmap`): the texture's RGB in [0, 1] is the normal's xyz in [-1, 1].
    NormalMap {
        normals: Texture,
        nested: Box<MaterialKind>,
    },
    /// `nested`, shaded in a frame tilted by the gradient of `scale` times a height texture
    /// (Mitsuba's `bumpmap`).
    BumpMap {
        height: Texture,
        scale: f32,
        nested: Box<MaterialKind>,
    },
    /// `nested` where a surface point is opaque, which it is with probability `opacity`
    /// (clamped to [0, 1]); light passes straight through otherwise (Mitsuba's `mask`).
    Mask {
        opacity: Texture,
        nested: Box<MaterialKind>,
    },
    /// Lets light through unchanged: a medium's boundary.
    Null,
    /// Mitsuba's `principled`, with its textured parameters.
    Principled(PrincipledMaterial),
    /// Mitsuba's `blendbsdf` of two material kinds.
    Blend(BlendMaterial),
    /// Mitsuba's `pplastic` (unpolarized); `specular_probability` is fixed per material.
    PPlastic {
        diffuse: Texture,
        specular: Rgb,
        eta: f32,
        dist: RoughnessMap,
        specular_probability: f32,
    },
    /// Mitsuba's `hair`.
    Hair(HairBsdf),
    /// A glTF 2.0 material with its textures.
    Gltf(GltfMaterial),
}

#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
    /// Opaque materials scatter on both faces when true; otherwise the back face is black
    /// (Mitsuba's default, undone there by `twosided`). Dielectrics ignore this.
    pub two_sided: bool,
    /// The back face is not there (glTF's `doubleSided: false`): a ray that meets the
    /// surface from behind its geometric normal passes through it unscattered, as through a
    /// fully transparent mask (see `integrators::surface::opacity`). False for every
    /// material but single-sided glTF ones that do not bound a volume.
    pub cull_back_faces: bool,
}

impl Material {
    pub fn new(name: impl Into<String>, kind: MaterialKind, two_sided: bool) -> Material {
        Material { name: name.into(), kind, two_sided, cull_back_faces: false }
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
        self.kind.base().is_transmissive()
    }

    /// The reflectance a denoiser wants as its albedo guide: the diffuse texture where
    /// there is one, the specular tint of metals, the transmission tint of dielectrics.
    pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.kind.base().albedo(uv)
    }

    /// The BSDF at surface point `uv`: textures looked up.
    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        self.bsdf_at(&TexturePoint::uv(uv))
    }

    /// The BSDF at a hit point (of the innermost material, inside normal maps, bump maps and
    /// masks: those are applied by the integrators, see [`Perturbation`]).
    #[inline]
    pub fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        self.kind.base().bsdf_at(p)
    }
}

impl MaterialKind {
    /// See [`Material::is_transmissive`].
    pub fn is_transmissive(&self) -> bool {
        match self {
            MaterialKind::Dielectric { .. }
            | MaterialKind::RoughDielectric { .. }
            | MaterialKind::ThinDielectric { .. }
            | MaterialKind::Null => true,
            MaterialKind::Principled(p) => p.is_transmissive(),
            MaterialKind::Gltf(g) => g.is_transmissive(),
            MaterialKind::Blend(b) => b.is_transmissive(),
            MaterialKind::Diffuse { .. }
            | MaterialKind::Phong { .. }
            | MaterialKind::Conductor { .. }
            | MaterialKind::RoughConductor { .. }
            | MaterialKind::Plastic { .. }
            | MaterialKind::PPlastic { .. }
            | MaterialKind::Hair(_)
            | MaterialKind::Black
            | MaterialKind::NormalMap { .. }
            | MaterialKind::BumpMap { .. }
            | MaterialKind::Mask { .. } => false,
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
            MaterialKind::Plastic { diffuse, .. } | MaterialKind::PPlastic { diffuse, .. } => diffuse.eval(uv),
            MaterialKind::Null => Rgb::WHITE,
            MaterialKind::Principled(p) => p.base_color.eval(uv),
            MaterialKind::Gltf(g) => g.albedo(uv),
            MaterialKind::Blend(b) => b.albedo(uv),
            MaterialKind::Black
            | MaterialKind::Hair(_)
            | MaterialKind::NormalMap { .. }
            | MaterialKind::BumpMap { .. }
            | MaterialKind::Mask { .. } => Rgb::BLACK,
        }
    }

    /// The BSDF at surface point `uv` (see [`MaterialKind::bsdf_at`]).
    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        self.bsdf_at(&TexturePoint::uv(uv))
    }

    /// This kind's BSDF at a hit point; wrappers (normal and bump maps, masks) are black here,
    /// their nested material being found by [`MaterialKind::base`].
    #[inline]
    pub fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        match self {
            MaterialKind::Diffuse { reflectance } => Bsdf::Diffuse(Diffuse { reflectance: reflectance.eval_at(p) }),
            MaterialKind::Phong { kd, ks, exponent } => {
                Bsdf::Phong(Phong { kd: kd.eval_at(p), ks: *ks, exponent: *exponent })
            }
            MaterialKind::Conductor { eta, k, specular } => {
                Bsdf::Conductor(Conductor { eta: *eta, k: *k, specular: *specular })
            }
            MaterialKind::RoughConductor { dist, eta, k, specular } => {
                Bsdf::RoughConductor(RoughConductor { dist: dist.at(p.uv), eta: *eta, k: *k, specular: *specular })
            }
            MaterialKind::Dielectric { eta, reflect, transmit } => {
                Bsdf::Dielectric(Dielectric { eta: *eta, reflect: *reflect, transmit: *transmit })
            }
            MaterialKind::RoughDielectric { dist, eta, reflect, transmit } => Bsdf::RoughDielectric(RoughDielectric {
                dist: dist.at(p.uv),
                eta: *eta,
                reflect: *reflect,
                transmit: *transmit,
            }),
            MaterialKind::ThinDielectric { eta, reflect, transmit } => {
                Bsdf::ThinDielectric(ThinDielectric { eta: *eta, reflect: *reflect, transmit: *transmit })
            }
            MaterialKind::Plastic { diffuse, params } => {
                Bsdf::Plastic(PlasticParams { diffuse: diffuse.eval_at(p), ..*params })
            }
            MaterialKind::Black
            | MaterialKind::NormalMap { .. }
            | MaterialKind::BumpMap { .. }
            | MaterialKind::Mask { .. } => Bsdf::Black(Black),
            MaterialKind::Null => Bsdf::Null(Null),
            MaterialKind::Principled(pr) => Bsdf::Principled(pr.bsdf(p.uv)),
            MaterialKind::Blend(b) => b.bsdf(p.uv),
            MaterialKind::PPlastic { diffuse, specular, eta, dist, specular_probability } => {
                Bsdf::PPlastic(PPlasticParams {
                    diffuse: diffuse.eval_at(p),
                    specular: *specular,
                    eta: *eta,
                    dist: dist.at(p.uv),
                    specular_probability: *specular_probability,
                })
            }
            MaterialKind::Hair(h) => Bsdf::Hair(*h),
            MaterialKind::Gltf(g) if g.unlit => Bsdf::Black(Black),
            MaterialKind::Gltf(g) => Bsdf::GltfPbr(g.bsdf(p)),
        }
    }
}

/// Complex refractive indices (eta, k) in RGB for Mitsuba's named conductor presets (the
/// values of Mitsuba 3.9.1's `scalar_rgb` variant, [`conductor_presets`]); "none" is a perfect
/// mirror.
pub fn conductor_preset(name: &str) -> Option<(Rgb, Rgb)> {
    if name == "none" {
        return Some((Rgb::BLACK, Rgb::WHITE));
    }
    let p = conductor_presets::CONDUCTOR_PRESETS.iter().find(|p| p.name == name)?;
    Some((Rgb::from_array(p.eta), Rgb::from_array(p.k)))
}
