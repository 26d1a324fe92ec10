//! The description of a glTF 2.0 material: metallic-roughness with the KHR extensions
//! Blender writes, its textures as [`TextureDesc::Gltf`] references.

use crate::describe::TextureDesc;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};

/// How a glTF material's alpha is used.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "mode", rename_all = "lowercase")]
pub enum GltfAlphaMode {
    Opaque,
    /// Opaque where alpha >= cutoff, else fully transparent.
    Mask {
        cutoff: f32,
    },
    /// Opacity alpha, rendered stochastically.
    Blend,
}

/// A glTF material: the factors and, as [`TextureDesc::Gltf`], the textures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GltfMaterialDesc {
    pub base_color: Rgb,
    pub base_alpha: f32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_color_texture: Option<TextureDesc>,
    pub metallic: f32,
    pub roughness: f32,
    /// Blue channel metallic, green channel roughness (linear).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub metallic_roughness_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_texture: Option<TextureDesc>,
    /// `normalTexture.scale`: scales the tangent-space normal's x and y.
    pub normal_scale: f32,
    pub alpha: GltfAlphaMode,
    pub double_sided: bool,
    /// `KHR_materials_ior`.
    pub ior: f32,
    /// `KHR_materials_specular` factor and colour factor.
    pub specular: f32,
    pub specular_color: Rgb,
    /// `KHR_materials_transmission` factor.
    pub transmission: f32,
    /// `KHR_materials_volume`: thickness 0 (or no extension) is a thin wall.
    pub thin_walled: bool,
    /// `KHR_materials_volume` attenuation colour and distance (infinite: no absorption).
    pub attenuation_color: Rgb,
    pub attenuation_distance: f32,
    /// `KHR_materials_clearcoat` factor and roughness factor.
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    /// `KHR_materials_sheen` colour and roughness factors.
    pub sheen_color: Rgb,
    pub sheen_roughness: f32,
    /// `KHR_materials_unlit`: the base colour is emitted, nothing scatters.
    pub unlit: bool,
    /// The extensions' textures, each multiplying its factor: `specularTexture` (alpha),
    /// `specularColorTexture` (RGB, sRGB), `transmissionTexture` (red), `clearcoatTexture`
    /// (red), `clearcoatRoughnessTexture` (green), `sheenColorTexture` (RGB, sRGB),
    /// `sheenRoughnessTexture` (alpha), `thicknessTexture` (green; read, but a path tracer
    /// measures a volume's thickness from its geometry, so it changes nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular_color_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmission_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearcoat_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearcoat_roughness_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sheen_color_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sheen_roughness_texture: Option<TextureDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_texture: Option<TextureDesc>,
}

impl GltfMaterialDesc {
    /// The specification's default material (a primitive without one): white, metallic 1,
    /// roughness 1, single-sided.
    pub fn default_material() -> GltfMaterialDesc {
        GltfMaterialDesc {
            base_color: Rgb::splat(1.0),
            base_alpha: 1.0,
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            alpha: GltfAlphaMode::Opaque,
            double_sided: false,
            ior: 1.5,
            specular: 1.0,
            specular_color: Rgb::splat(1.0),
            transmission: 0.0,
            thin_walled: true,
            attenuation_color: Rgb::splat(1.0),
            attenuation_distance: f32::MAX,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_color: Rgb::BLACK,
            sheen_roughness: 0.0,
            unlit: false,
            specular_texture: None,
            specular_color_texture: None,
            transmission_texture: None,
            clearcoat_texture: None,
            clearcoat_roughness_texture: None,
            sheen_color_texture: None,
            sheen_roughness_texture: None,
            thickness_texture: None,
        }
    }

    /// Whether a ray meeting the surface's back face passes through it (the specification's
    /// back-face culling for `doubleSided: false`): every single-sided surface but the
    /// boundary of a volume (`KHR_materials_volume` with thickness > 0), which stays
    /// two-sided as that extension says.
    pub fn culls_back_faces(&self) -> bool {
        !self.double_sided && self.thin_walled
    }

    /// The textures, in a fixed order (base colour, metal/rough, normal, then the
    /// extensions' in the order of the fields).
    pub fn textures(&self) -> Vec<&TextureDesc> {
        [
            &self.base_color_texture,
            &self.metallic_roughness_texture,
            &self.normal_texture,
            &self.specular_texture,
            &self.specular_color_texture,
            &self.transmission_texture,
            &self.clearcoat_texture,
            &self.clearcoat_roughness_texture,
            &self.sheen_color_texture,
            &self.sheen_roughness_texture,
            &self.thickness_texture,
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    pub fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        [
            &mut self.base_color_texture,
            &mut self.metallic_roughness_texture,
            &mut self.normal_texture,
            &mut self.specular_texture,
            &mut self.specular_color_texture,
            &mut self.transmission_texture,
            &mut self.clearcoat_texture,
            &mut self.clearcoat_roughness_texture,
            &mut self.sheen_color_texture,
            &mut self.sheen_roughness_texture,
            &mut self.thickness_texture,
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}
