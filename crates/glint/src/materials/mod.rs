//! Materials: what a surface is made of. `Material::bsdf` evaluates the textures at a hit
//! point and returns the [`Bsdf`] to scatter with.
//!
//! # Adding a material
//! A material is one module here (`diffuse.rs`, `conductor.rs`, ...; a folder where it is
//! long, as `principled/`), holding, with its parameters listed in its documentation:
//! - its description (serde, the `type` a JSON scene names) with an `impl Describe`: how it
//!   builds, the check of its numbers, the textures it reads;
//! - its built form (textures made, constants folded) with an `impl Shade`: the BSDF at a hit
//!   point, the denoiser's albedo, whether it transmits, the material it wraps;
//! - its BSDF with an `impl Scatter` (see `bsdf`): eval, pdf, sample.
//!
//! None of the three traits has a default method (but `Scatter::passage_transmission`, for
//! the surfaces volpath crosses), so the compiler names any the new type lacks. Its `mod`
//! line and one entry in the `materials!` list below then make the [`MaterialModel`],
//! [`MaterialKind`] and [`Bsdf`] variants, their static dispatch, their `From` conversions
//! and the module's re-export; each scene format reads it with one
//! function of its reader.
//! docs/rendering.md ("Adding a material") walks through it.

// The material modules (each named in the `materials!` list below, which re-exports it) and
// what they share.
mod blend;
mod coated_diffuse;
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
mod principled_thin;
mod roughness;
mod surface;
mod texture;
mod texture_cache;
pub use perturbed::{bump_shadowing, flip_invalid, normal_map_frame, ShadedBsdf};
pub use roughness::RoughnessMap;
pub(crate) use roughness::{constant_microfacet, roughness_map};
pub use texture::{Bitmap, ScalarTexture, Texture, TexturePoint};
pub use texture_cache::TextureCache;

use crate::bsdf::{BsdfSample, Scatter};
use crate::describe::slots::Slot;
use crate::describe::{self, checks, TextureDesc};
use crate::error::{Error, SourceLoc};
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

/// What every material description answers: how it builds, whether its numbers are in
/// range, which textures it reads. No method has a default.
pub trait Describe {
    /// What it builds into (a [`MaterialKind`] variant's type, or a `MaterialKind` for a
    /// description that builds wrappers around its material, as glTF's does).
    type Built: Into<MaterialKind>;

    /// The built material, its textures made (or found in `textures`).
    fn build(&self, textures: &mut TextureCache) -> Result<Self::Built, Error>;

    /// Checks the parameters' numbers (textures are checked by the caller); the message
    /// names the parameter.
    fn validate(&self) -> Result<(), String>;

    /// Every texture, colours and roughness maps alike, nested materials' included, in a
    /// fixed order.
    fn textures(&self) -> Vec<&TextureDesc>;

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc>;

    /// The parameters a session may edit in place (the Python API's `traverse`), named as
    /// `materials.NAME.` followed by the name given here.
    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)>;
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

/// Makes the three closed sets of materials from one list, grouped by module
/// (`mod module { Variant(Description => Built) [BsdfVariant(BsdfType), ...], }`, a line
/// per material), and re-exports each module:
/// - [`MaterialModel`], the descriptions (serde, tagged by `type`: the variant's name in
///   lower case), with the [`Describe`] dispatch;
/// - [`MaterialKind`], the built materials, with the [`Shade`] dispatch;
/// - [`Bsdf`], every material's BSDFs, with the [`Scatter`] dispatch;
///
/// each dispatch one arm per variant, no wildcard, and the `From` conversions into each enum.
macro_rules! materials {
    ($(mod $module:ident { $($(#[doc = $doc:literal])* $variant:ident($desc:ty => $kind:ty) [$($bvariant:ident($bty:ty)),*],)+ })+) => {
        $(pub use $module::*;)+

        /// A material as a scene describes it.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "type", rename_all = "lowercase")]
        // Kept unboxed: a description is built once and read once.
        #[allow(clippy::large_enum_variant)]
        pub enum MaterialModel {
            $($($(#[doc = $doc])* $variant($desc),)+)+
        }

        impl MaterialModel {
            /// The built material (see [`Describe::build`]).
            pub fn build(&self, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
                match self { $($(MaterialModel::$variant(d) => Ok(Describe::build(d, textures)?.into()),)+)+ }
            }

            /// Checks every texture as a colour, then the parameters (see
            /// [`Describe::validate`]).
            pub fn validate(&self) -> Result<(), String> {
                for t in self.textures() {
                    checks::texture(t, "colour")?;
                }
                match self { $($(MaterialModel::$variant(d) => Describe::validate(d),)+)+ }
            }

            /// See [`Describe::textures`].
            pub fn textures(&self) -> Vec<&TextureDesc> {
                match self { $($(MaterialModel::$variant(d) => Describe::textures(d),)+)+ }
            }

            /// See [`Describe::textures_mut`].
            pub fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
                match self { $($(MaterialModel::$variant(d) => Describe::textures_mut(d),)+)+ }
            }

            /// See [`Describe::slots`].
            pub fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
                match self { $($(MaterialModel::$variant(d) => Describe::slots(d),)+)+ }
            }
        }

        $($(impl From<$desc> for MaterialModel {
            fn from(d: $desc) -> MaterialModel {
                MaterialModel::$variant(d)
            }
        })+)+

        /// A material built: textures made, constants folded.
        // Unboxed on purpose: materials are read at every hit, and a box is a pointer chase.
        #[allow(clippy::large_enum_variant)]
        #[derive(Clone, Debug)]
        pub enum MaterialKind {
            $($($(#[doc = $doc])* $variant($kind),)+)+
        }

        // Inherent, so that callers need not import `Shade`.
        impl MaterialKind {
            /// This kind's own BSDF at a hit point (see [`Shade::bsdf_at`]).
            #[inline]
            pub fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
                match self { $($(MaterialKind::$variant(m) => Shade::bsdf_at(m, p),)+)+ }
            }

            /// See [`Material::albedo`].
            pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
                match self { $($(MaterialKind::$variant(m) => Shade::albedo(m, uv),)+)+ }
            }

            /// See [`Material::is_transmissive`].
            pub fn is_transmissive(&self) -> bool {
                match self { $($(MaterialKind::$variant(m) => Shade::is_transmissive(m),)+)+ }
            }

            /// The material a normal map, bump map or mask wraps; `None` for a material
            /// that scatters.
            pub fn nested(&self) -> Option<&MaterialKind> {
                match self { $($(MaterialKind::$variant(m) => Shade::nested(m),)+)+ }
            }
        }

        $($(impl From<$kind> for MaterialKind {
            fn from(m: $kind) -> MaterialKind {
                MaterialKind::$variant(m)
            }
        })+)+

        /// A material's BSDF at one point: textures looked up. Not `Copy`: a blend owns its
        /// two parts (see `blend.rs`); every other variant is plain data.
        #[derive(Clone, Debug)]
        pub enum Bsdf {
            $($($($bvariant($bty),)*)+)+
        }

        // Inherent, so that callers of a `Bsdf` need not import `Scatter`.
        impl Bsdf {
            /// See [`Scatter::is_delta`].
            pub fn is_delta(&self) -> bool {
                match self { $($($(Bsdf::$bvariant(b) => b.is_delta(),)*)+)+ }
            }

            /// See [`Scatter::has_delta_lobe`].
            pub fn has_delta_lobe(&self) -> bool {
                match self { $($($(Bsdf::$bvariant(b) => b.has_delta_lobe(),)*)+)+ }
            }

            /// See [`Scatter::eval`].
            pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
                match self { $($($(Bsdf::$bvariant(b) => b.eval(wo, wi),)*)+)+ }
            }

            /// See [`Scatter::pdf`].
            pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                match self { $($($(Bsdf::$bvariant(b) => b.pdf(wo, wi),)*)+)+ }
            }

            /// See [`Scatter::sample`].
            pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
                match self { $($($(Bsdf::$bvariant(b) => b.sample(wo, u_lobe, u),)*)+)+ }
            }

            /// See [`Scatter::diffuse_reflectance`].
            pub fn diffuse_reflectance(&self) -> Rgb {
                match self { $($($(Bsdf::$bvariant(b) => b.diffuse_reflectance(),)*)+)+ }
            }

            /// See [`Scatter::passage_transmission`].
            pub fn passage_transmission(&self, wo: Vec3) -> Option<Rgb> {
                match self { $($($(Bsdf::$bvariant(b) => b.passage_transmission(wo),)*)+)+ }
            }
        }

        $($($(impl From<$bty> for Bsdf {
            fn from(b: $bty) -> Bsdf {
                Bsdf::$bvariant(b)
            }
        })*)+)+
    };
}

materials! {
    mod diffuse {
        /// Lambertian reflection (`diffuse`).
        Diffuse(DiffuseDesc => DiffuseMaterial) [Diffuse(Diffuse)],
    }
    mod phong {
        /// Diffuse plus a normalised Phong lobe (the Whitted integrator's glossy term).
        Phong(PhongDesc => PhongMaterial) [Phong(Phong)],
    }
    mod conductor {
        /// Metal, smooth or rough (`conductor`, `roughconductor`).
        Conductor(ConductorDesc => ConductorMaterial) [Conductor(Conductor), RoughConductor(RoughConductor)],
    }
    mod dielectric {
        /// Glass, smooth, rough or thin (`dielectric`, `roughdielectric`, `thindielectric`).
        Dielectric(DielectricDesc => DielectricMaterial)
            [Dielectric(Dielectric), RoughDielectric(RoughDielectric), ThinDielectric(ThinDielectric)],
    }
    mod plastic {
        /// A diffuse base under a smooth or rough coating (`plastic`, `roughplastic`).
        Plastic(PlasticDesc => PlasticMaterial) [Plastic(PlasticParams)],
    }
    mod passthrough {
        /// Absorbs everything (emitters without a material).
        Black(BlackDesc => Black) [Black(Black)],
        /// Lets light through unchanged (`null`): a medium's boundary.
        Null(NullDesc => Null) [Null(Null)],
    }
    mod surface {
        /// A material shaded with a tangent-space normal map (`normalmap`).
        NormalMap(NormalMapDesc => NormalMapMaterial) [],
        /// A material shaded with the normals of a height field (`bumpmap`).
        BumpMap(BumpMapDesc => BumpMapMaterial) [],
        /// A material with an opacity (`mask`).
        Mask(MaskDesc => MaskMaterial) [],
    }
    mod principled {
        /// Mitsuba's `principled` (Disney) BSDF.
        Principled(PrincipledDesc => PrincipledMaterial) [Principled(Principled)],
    }
    mod principled_thin {
        /// Mitsuba's `principledthin`: the Disney BSDF of a thin translucent sheet.
        PrincipledThin(PrincipledThinDesc => PrincipledThinMaterial) [PrincipledThin(PrincipledThin)],
    }
    mod blend {
        /// Mitsuba's `blendbsdf`: a weighted mixture of two materials.
        Blend(BlendDesc => BlendMaterial) [Blend(BlendBsdf)],
    }
    mod pplastic {
        /// Mitsuba's `pplastic` as its unpolarized variants render it.
        PPlastic(PPlasticDesc => PPlasticMaterial) [PPlastic(PPlasticParams)],
    }
    mod hair {
        /// Mitsuba's `hair` (Chiang et al. 2016), in a curve's frame (x around, y along).
        Hair(HairDesc => HairBsdf) [Hair(HairBsdf)],
    }
    mod gltf {
        /// A glTF 2.0 metallic-roughness material with the KHR extensions.
        Gltf(GltfMaterialDesc => GltfMaterial) [GltfPbr(GltfPbr)],
    }
    mod coated_diffuse {
        /// pbrt-v4's `coateddiffuse`: a diffuse base under a slab and a coating, by random walks.
        CoatedDiffuse(CoatedDiffuseDesc => CoatedDiffuseMaterial) [CoatedDiffuse(CoatedDiffuse)],
    }
}

impl MaterialModel {
    /// The mesh attributes (`vertex_...`, `face_...`) the material's textures read, with
    /// where each is named.
    pub fn mesh_attributes(&self) -> Vec<(&str, &SourceLoc)> {
        self.textures()
            .into_iter()
            .filter_map(|t| match t {
                TextureDesc::MeshAttribute { name, loc, .. } => Some((name.as_str(), loc)),
                TextureDesc::Constant { .. }
                | TextureDesc::Bitmap { .. }
                | TextureDesc::Checkerboard { .. }
                | TextureDesc::Gltf(_) => None,
            })
            .collect()
    }
}

impl describe::MaterialSet for MaterialModel {
    fn textures(&self) -> Vec<&TextureDesc> {
        MaterialModel::textures(self)
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        MaterialModel::textures_mut(self)
    }
}

/// A scene description with glint's materials.
pub type SceneDesc = describe::SceneDesc<MaterialModel>;

/// A described material with glint's material set.
pub type MaterialDesc = describe::MaterialDesc<MaterialModel>;

impl MaterialKind {
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
