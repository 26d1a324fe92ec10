//! The glTF 2.0 metallic-roughness BRDF (the specification's Appendix B) and the KHR
//! material extensions that change the scattering (`KHR_materials_ior`, `_specular`,
//! `_transmission`, `_volume`'s thin-walled case, `_clearcoat`, `_sheen`), evaluated at one
//! point: textures, factors and vertex colours already multiplied in by the material.
//!
//! Placeholder: only the Lambertian part of the dielectric base is implemented yet; the
//! layered model replaces it.

use super::{BsdfSample, Scatter};
use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;

/// The glTF material at one point. Defaults (without an extension) are the specification's.
#[derive(Clone, Copy, Debug)]
pub struct GltfPbr {
    /// Linear base colour: `baseColorFactor` x `baseColorTexture` (sRGB decoded) x `COLOR_0`.
    pub base_color: Rgb,
    /// 0 dielectric to 1 metal (`metallicFactor` x the texture's blue channel).
    pub metallic: f32,
    /// Perceptual roughness (`roughnessFactor` x the texture's green channel); the GGX
    /// alpha is its square.
    pub roughness: f32,
    /// `KHR_materials_ior` (1.5 without it).
    pub ior: f32,
    /// `KHR_materials_specular`: strength of the dielectric specular layer (1 without it).
    pub specular: f32,
    /// `KHR_materials_specular`: colour of the dielectric F0 (white without it).
    pub specular_color: Rgb,
    /// `KHR_materials_transmission` (0 without it).
    pub transmission: f32,
    /// True without `KHR_materials_volume` (or with thickness 0): light crosses the surface
    /// as through a thin wall, without refraction; false: the surface bounds a volume.
    pub thin_walled: bool,
    /// `KHR_materials_clearcoat` strength (0 without it).
    pub clearcoat: f32,
    /// `KHR_materials_clearcoat` perceptual roughness.
    pub clearcoat_roughness: f32,
    /// `KHR_materials_sheen` colour (black without it).
    pub sheen_color: Rgb,
    /// `KHR_materials_sheen` perceptual roughness.
    pub sheen_roughness: f32,
}

impl GltfPbr {
    /// The specification's default material: white, metallic 1, roughness 1.
    pub fn default_material() -> GltfPbr {
        GltfPbr {
            base_color: Rgb::splat(1.0),
            metallic: 1.0,
            roughness: 1.0,
            ior: 1.5,
            specular: 1.0,
            specular_color: Rgb::splat(1.0),
            transmission: 0.0,
            thin_walled: true,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_color: Rgb::BLACK,
            sheen_roughness: 0.0,
        }
    }

    fn diffuse_albedo(&self) -> Rgb {
        self.base_color * (1.0 - self.metallic)
    }
}

impl Scatter for GltfPbr {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        self.diffuse_albedo() * (INV_PI * wi.z)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            0.0
        } else {
            warp::cosine_hemisphere_pdf(wi.z)
        }
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = warp::cosine_hemisphere(u);
        BsdfSample::non_delta(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.diffuse_albedo()
    }
}
