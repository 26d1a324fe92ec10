//! Materials: what a surface is made of, with textured parameters. `Material::bsdf`
//! evaluates the textures at a hit point and returns the [`Bsdf`] to scatter with.
//!
//! # Adding a material
//! A material is one module here: its built form (textures made, constants folded) with an
//! `impl Shade` (the BSDF at a hit point, the denoiser's albedo, whether it transmits, the
//! material it wraps: none has a default, so the compiler names any the new type lacks) and
//! the `build` that makes it from its description; and one line in the `materials!` list
//! below, which makes the [`MaterialKind`] variant, its static dispatch and its `From`
//! conversion. Its BSDF (an `impl Scatter`, see `bsdf`) lives in the same module, with one
//! line in the `bsdfs!` list, which makes the [`Bsdf`] variant the same way.
//! docs/rendering.md ("Adding a material") lists what else a material touches.

mod blend;
mod conductor;
mod conductor_presets;
mod dielectric;
mod diffuse;
mod gltf;
mod hair;
mod passthrough;
mod perturbed;
mod phong;
mod plastic;
mod pplastic;
mod principled;
mod roughness;
mod surface;
mod texture;
mod texture_cache;
pub use blend::{BlendBsdf, BlendMaterial, BlendMaterialPart, BlendPart};
pub use conductor::{Conductor, ConductorMaterial, RoughConductor, RoughConductorMaterial};
pub use dielectric::{
    Dielectric, DielectricMaterial, RoughDielectric, RoughDielectricMaterial, ThinDielectric, ThinDielectricMaterial,
};
pub use diffuse::{Diffuse, DiffuseMaterial};
pub use gltf::{
    sheen_albedo, sheen_albedo_quadrature, GltfAlpha, GltfExtensionTextures, GltfMaterial, GltfPbr, GltfTexture,
    ALPHA_ATTRIBUTE, COLOR_ATTRIBUTE, SHEEN_ALBEDO_TOLERANCE, SHEEN_MIN_ROUGHNESS, TANGENT_ATTRIBUTE,
    TANGENT_SIGN_ATTRIBUTE, UV1_ATTRIBUTE,
};
pub use hair::{HairBsdf, EUMELANIN_SIGMA_A, PHEOMELANIN_SIGMA_A};
pub use passthrough::{Black, Null};
pub use perturbed::{bump_shadowing, flip_invalid, normal_map_frame, ShadedBsdf};
pub use phong::{Phong, PhongMaterial};
pub use plastic::{PlasticMaterial, PlasticParams};
pub use pplastic::{PPlasticMaterial, PPlasticParams};
pub use principled::{principled_alphas, AnisoGgx, Principled, PrincipledInputs, PrincipledMaterial, PrincipledRates};
pub use roughness::RoughnessMap;
pub(crate) use roughness::{constant_microfacet, roughness_map};
pub use surface::{BumpMapMaterial, MaskMaterial, NormalMapMaterial, Perturbation};
pub use texture::{Bitmap, ScalarTexture, Texture, TexturePoint};
pub use texture_cache::TextureCache;

use crate::bsdf::{BsdfSample, Scatter};
use crate::describe::MaterialModel;
use crate::error::Error;
use crate::math::{Rgb, Vec3};

/// Makes the closed [`Bsdf`] enum from one list of `Variant(Type)`, each type a
/// [`Scatter`]: the enum, its static dispatch of every `Scatter` method (one arm per
/// variant, no wildcard) and `From<Type> for Bsdf`.
macro_rules! bsdfs {
    ($($(#[doc = $doc:literal])* $variant:ident($ty:ty),)+) => {
        /// Not `Copy`: a blend owns its two parts (see `blend.rs`); every other variant is
        /// plain data.
        #[derive(Clone, Debug)]
        pub enum Bsdf {
            $($(#[doc = $doc])* $variant($ty),)+
        }

        // Inherent, so that callers of a `Bsdf` need not import `Scatter`.
        impl Bsdf {
            /// See [`Scatter::is_delta`].
            pub fn is_delta(&self) -> bool {
                match self { $(Bsdf::$variant(b) => b.is_delta(),)+ }
            }

            /// See [`Scatter::has_delta_lobe`].
            pub fn has_delta_lobe(&self) -> bool {
                match self { $(Bsdf::$variant(b) => b.has_delta_lobe(),)+ }
            }

            /// See [`Scatter::eval`].
            pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
                match self { $(Bsdf::$variant(b) => b.eval(wo, wi),)+ }
            }

            /// See [`Scatter::pdf`].
            pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                match self { $(Bsdf::$variant(b) => b.pdf(wo, wi),)+ }
            }

            /// See [`Scatter::sample`].
            pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
                match self { $(Bsdf::$variant(b) => b.sample(wo, u_lobe, u),)+ }
            }

            /// See [`Scatter::diffuse_reflectance`].
            pub fn diffuse_reflectance(&self) -> Rgb {
                match self { $(Bsdf::$variant(b) => b.diffuse_reflectance(),)+ }
            }

            /// See [`Scatter::passage_transmission`].
            pub fn passage_transmission(&self, wo: Vec3) -> Option<Rgb> {
                match self { $(Bsdf::$variant(b) => b.passage_transmission(wo),)+ }
            }
        }

        $(impl From<$ty> for Bsdf {
            fn from(b: $ty) -> Bsdf {
                Bsdf::$variant(b)
            }
        })+
    };
}

bsdfs! {
    /// Lambertian reflection.
    Diffuse(Diffuse),
    /// Diffuse plus a normalised Phong lobe (the Whitted integrator's glossy term).
    Phong(Phong),
    /// Perfectly smooth metal with complex index of refraction per channel.
    Conductor(Conductor),
    /// Microfacet metal (GGX or Beckmann).
    RoughConductor(RoughConductor),
    /// Smooth glass: `eta` is n_inside / n_outside.
    Dielectric(Dielectric),
    /// Rough glass with a microfacet interface.
    RoughDielectric(RoughDielectric),
    /// An infinitely thin slab of glass: reflection and straight-through transmission with
    /// the inter-reflections summed (Mitsuba's `thindielectric`).
    ThinDielectric(ThinDielectric),
    /// Diffuse base under a smooth or rough dielectric coating (Mitsuba's `plastic` and
    /// `roughplastic`), with the internal-scattering correction of the diffuse term.
    Plastic(PlasticParams),
    /// Absorbs everything (light sources with no material).
    Black(Black),
    /// Passes light straight through, unchanged (Mitsuba's `null`): a medium's boundary.
    Null(Null),
    /// Mitsuba's `principled` (Disney) BSDF.
    Principled(Principled),
    /// Mitsuba's `blendbsdf`: a weighted mixture of two BSDFs.
    Blend(BlendBsdf),
    /// Mitsuba's `pplastic` as its unpolarized variants render it.
    PPlastic(PPlasticParams),
    /// Mitsuba's `hair` (Chiang et al. 2016), in a curve's frame (x around, y along).
    Hair(HairBsdf),
    /// The glTF 2.0 metallic-roughness BRDF with the KHR material extensions.
    GltfPbr(GltfPbr),
}

/// What every built material answers. No method has a default, so that a new material
/// states each answer.
pub trait Shade {
    /// The BSDF at a hit point, textures looked up (black for the wrappers: normal and bump
    /// maps and masks, whose nested material scatters).
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf;

    /// The reflectance a denoiser wants as its albedo guide at `uv`.
    fn albedo(&self, uv: [f32; 2]) -> Rgb;

    /// True when the material lets light through (both faces are meaningful).
    fn is_transmissive(&self) -> bool;

    /// The material a wrapper (normal map, bump map, mask) holds; `None` for one that
    /// scatters.
    fn nested(&self) -> Option<&MaterialKind>;
}

/// Makes the closed [`MaterialKind`] enum from one list of `Variant(Type)`, each type a
/// [`Shade`]: the enum, its static dispatch of every `Shade` method (one arm per variant, no
/// wildcard) and `From<Type> for MaterialKind`.
macro_rules! materials {
    ($($(#[doc = $doc:literal])* $variant:ident($ty:ty),)+) => {
        // Unboxed on purpose: materials are read at every hit, and a box is a pointer chase.
        #[allow(clippy::large_enum_variant)]
        #[derive(Clone, Debug)]
        pub enum MaterialKind {
            $($(#[doc = $doc])* $variant($ty),)+
        }

        // Inherent, so that callers need not import `Shade`.
        impl MaterialKind {
            /// This kind's own BSDF at a hit point (see [`Shade::bsdf_at`]).
            #[inline]
            pub fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
                match self { $(MaterialKind::$variant(m) => m.bsdf_at(p),)+ }
            }

            /// See [`Material::albedo`].
            pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
                match self { $(MaterialKind::$variant(m) => m.albedo(uv),)+ }
            }

            /// See [`Material::is_transmissive`].
            pub fn is_transmissive(&self) -> bool {
                match self { $(MaterialKind::$variant(m) => m.is_transmissive(),)+ }
            }

            /// The material a normal map, bump map or mask wraps; `None` for a material
            /// that scatters.
            pub fn nested(&self) -> Option<&MaterialKind> {
                match self { $(MaterialKind::$variant(m) => m.nested(),)+ }
            }
        }

        $(impl From<$ty> for MaterialKind {
            fn from(m: $ty) -> MaterialKind {
                MaterialKind::$variant(m)
            }
        })+
    };
}

materials! {
    /// Lambertian reflection.
    Diffuse(DiffuseMaterial),
    /// Whitted-style diffuse + glossy.
    Phong(PhongMaterial),
    /// Smooth metal.
    Conductor(ConductorMaterial),
    /// Microfacet metal.
    RoughConductor(RoughConductorMaterial),
    /// Smooth glass.
    Dielectric(DielectricMaterial),
    /// Rough glass.
    RoughDielectric(RoughDielectricMaterial),
    /// An infinitely thin slab of glass.
    ThinDielectric(ThinDielectricMaterial),
    /// Diffuse base under a coating.
    Plastic(PlasticMaterial),
    /// Absorbs everything.
    Black(Black),
    /// A normal-mapped material.
    NormalMap(NormalMapMaterial),
    /// A bump-mapped material.
    BumpMap(BumpMapMaterial),
    /// A material with an opacity.
    Mask(MaskMaterial),
    /// Lets light through unchanged: a medium's boundary.
    Null(Null),
    /// Mitsuba's `principled`, with its textured parameters.
    Principled(PrincipledMaterial),
    /// Mitsuba's `blendbsdf` of two material kinds.
    Blend(BlendMaterial),
    /// Mitsuba's `pplastic` (unpolarized).
    PPlastic(PPlasticMaterial),
    /// Mitsuba's `hair`.
    Hair(HairBsdf),
    /// A glTF 2.0 material with its textures.
    Gltf(GltfMaterial),
}

impl MaterialKind {
    /// The material a description gives, its textures made (or found in the cache).
    pub fn build(m: &MaterialModel, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
        Ok(match m {
            MaterialModel::Diffuse { reflectance } => DiffuseMaterial::build(reflectance, textures)?.into(),
            MaterialModel::Phong { kd, ks, exponent } => PhongMaterial::build(kd, *ks, *exponent, textures)?.into(),
            MaterialModel::Conductor { eta, k, specular, roughness } => {
                conductor::build(*eta, *k, *specular, roughness.as_ref(), textures)?
            }
            MaterialModel::Dielectric { eta, reflect, transmit, roughness, thin } => {
                dielectric::build(*eta, *reflect, *transmit, roughness.as_ref(), *thin, textures)?
            }
            MaterialModel::Plastic { diffuse, specular, eta, roughness, nonlinear } => {
                PlasticMaterial::build(diffuse, *specular, *eta, roughness.as_ref(), *nonlinear, textures)?.into()
            }
            MaterialModel::Black => Black.into(),
            MaterialModel::NormalMap { normals, nested } => NormalMapMaterial::build(normals, nested, textures)?.into(),
            MaterialModel::BumpMap { height, scale, nested } => {
                BumpMapMaterial::build(height, *scale, nested, textures)?.into()
            }
            MaterialModel::Mask { opacity, nested } => MaskMaterial::build(opacity, nested, textures)?.into(),
            MaterialModel::Null => Null.into(),
            MaterialModel::Principled(p) => PrincipledMaterial::build(p, textures)?.into(),
            MaterialModel::Blend(b) => BlendMaterial::build(b, textures)?.into(),
            MaterialModel::PPlastic { diffuse, specular, eta, roughness } => {
                PPlasticMaterial::build(diffuse, *specular, *eta, roughness, textures)?.into()
            }
            MaterialModel::Hair(h) => hair::build(h).into(),
            MaterialModel::Gltf(g) => gltf::build(g, textures)?,
        })
    }

    /// The BSDF at surface point `uv` (see [`MaterialKind::bsdf_at`]).
    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        self.bsdf_at(&TexturePoint::uv(uv))
    }
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
