//! glTF materials and textures of a description, built: images decoded once each, the
//! material's alpha mode and normal map as the `Mask` and `NormalMap` wrappers the
//! integrators already apply.

use super::TextureCache;
use crate::bsdf::GltfPbr;
use crate::describe::{GltfAlphaMode, GltfMaterialDesc, GltfTextureDesc, TextureDesc};
use crate::error::Error;
use crate::io::gltf::{decode_image, image_bytes, open_cached, RgbaImage};
use crate::materials::{GltfAlpha, GltfExtensionTextures, GltfMaterial, GltfTexture, MaterialKind, Texture};
use std::sync::Arc;

impl TextureCache {
    fn gltf_image(&mut self, d: &GltfTextureDesc) -> Result<Arc<RgbaImage>, Error> {
        let key = (d.file.clone(), d.image, d.srgb);
        if let Some(i) = self.gltf_images.get(&key) {
            return Ok(i.clone());
        }
        let at = |e: String| Error::at(&d.loc, e);
        let file = open_cached(&d.file).map_err(at)?;
        let bytes = image_bytes(&file, d.image).map_err(at)?;
        let image = Arc::new(decode_image(&bytes, d.srgb, &format!("images[{}]", d.image)).map_err(at)?);
        self.gltf_images.insert(key, image.clone());
        Ok(image)
    }

    pub(super) fn gltf_texture(&mut self, d: &GltfTextureDesc) -> Result<Arc<GltfTexture>, Error> {
        let image = self.gltf_image(d)?;
        let mut t = GltfTexture::new(image, d.texcoord, [d.wrap_s, d.wrap_t], d.nearest);
        t.transform = d.transform;
        t.scale = d.scale;
        Ok(Arc::new(t))
    }

    fn optional_gltf(&mut self, t: &Option<TextureDesc>) -> Result<Option<Arc<GltfTexture>>, Error> {
        match t {
            Some(TextureDesc::Gltf(d)) => Ok(Some(self.gltf_texture(d)?)),
            Some(_) => Err(Error::new("a glTF material's textures must be glTF textures")),
            None => Ok(None),
        }
    }
}

/// The material kind of a glTF material: the textured [`GltfMaterial`], inside a normal
/// map and a mask where it has them.
pub(super) fn gltf_kind(g: &GltfMaterialDesc, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
    let base_color_texture = textures.optional_gltf(&g.base_color_texture)?;
    let factors = GltfPbr {
        base_color: g.base_color,
        metallic: g.metallic,
        roughness: g.roughness,
        ior: g.ior,
        specular: g.specular,
        specular_color: g.specular_color,
        transmission: g.transmission,
        thin_walled: g.thin_walled,
        clearcoat: g.clearcoat,
        clearcoat_roughness: g.clearcoat_roughness,
        sheen_color: g.sheen_color,
        sheen_roughness: g.sheen_roughness,
    };
    let mut kind = MaterialKind::Gltf(GltfMaterial {
        factors,
        base_color_texture: base_color_texture.clone(),
        metallic_roughness_texture: textures.optional_gltf(&g.metallic_roughness_texture)?,
        extension_textures: GltfExtensionTextures {
            specular: textures.optional_gltf(&g.specular_texture)?,
            specular_color: textures.optional_gltf(&g.specular_color_texture)?,
            transmission: textures.optional_gltf(&g.transmission_texture)?,
            clearcoat: textures.optional_gltf(&g.clearcoat_texture)?,
            clearcoat_roughness: textures.optional_gltf(&g.clearcoat_roughness_texture)?,
            sheen_color: textures.optional_gltf(&g.sheen_color_texture)?,
            sheen_roughness: textures.optional_gltf(&g.sheen_roughness_texture)?,
        },
        unlit: g.unlit,
    });
    if let Some(n) = textures.optional_gltf(&g.normal_texture)? {
        let mut n = (*n).clone();
        n.normal_scale = Some(g.normal_scale);
        kind = MaterialKind::NormalMap { normals: Texture::Gltf(Arc::new(n)), nested: Box::new(kind) };
    }
    let cutoff = match g.alpha {
        GltfAlphaMode::Opaque => return Ok(kind),
        GltfAlphaMode::Mask { cutoff } => Some(cutoff),
        GltfAlphaMode::Blend => None,
    };
    let alpha = GltfAlpha { factor: g.base_alpha, texture: base_color_texture, cutoff };
    Ok(MaterialKind::Mask { opacity: Texture::GltfAlpha(Arc::new(alpha)), nested: Box::new(kind) })
}
