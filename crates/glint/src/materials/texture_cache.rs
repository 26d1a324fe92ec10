//! The texture cache of a build: a described texture made into a [`Texture`], its image
//! file read once.

use super::{Bitmap, GltfTexture, Texture};
use crate::describe::{GltfTextureDesc, TextureDesc};
use crate::error::{Error, SourceLoc};
use crate::io::gltf::{decode_image, image_bytes, open_cached, RgbaImage};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Textures of a build, each image file decoded once however many materials and lights use
/// it.
#[derive(Default)]
pub struct TextureCache {
    bitmaps: HashMap<(PathBuf, bool), Arc<Bitmap>>,
    /// glTF images by file, image index and whether sRGB-decoded.
    gltf_images: HashMap<(PathBuf, usize, bool), Arc<RgbaImage>>,
}

impl TextureCache {
    pub(crate) fn bitmap(&mut self, file: &Path, raw: bool, loc: &SourceLoc) -> Result<Arc<Bitmap>, Error> {
        if let Some(b) = self.bitmaps.get(&(file.to_path_buf(), raw)) {
            return Ok(b.clone());
        }
        let bm = Arc::new(Bitmap::load(file, raw).map_err(|e| Error::at(loc, e))?);
        self.bitmaps.insert((file.to_path_buf(), raw), bm.clone());
        Ok(bm)
    }

    pub(crate) fn texture(&mut self, t: &TextureDesc) -> Result<Texture, Error> {
        Ok(match t {
            TextureDesc::Constant { color } => Texture::Constant(*color),
            TextureDesc::Bitmap { texels: Some(t), uv_scale, uv_offset, .. } => {
                Texture::Bitmap { image: Arc::new(Bitmap::of_texels(t)), uv_scale: *uv_scale, uv_offset: *uv_offset }
            }
            TextureDesc::Bitmap { file, raw, uv_scale, uv_offset, loc, texels: None } => {
                Texture::Bitmap { image: self.bitmap(file, *raw, loc)?, uv_scale: *uv_scale, uv_offset: *uv_offset }
            }
            TextureDesc::Checkerboard { color0, color1, uv_scale, uv_offset } => {
                Texture::Checkerboard { color0: *color0, color1: *color1, uv_scale: *uv_scale, uv_offset: *uv_offset }
            }
            TextureDesc::MeshAttribute { name, scale, .. } => {
                Texture::MeshAttribute { name: name.clone(), scale: *scale }
            }
            TextureDesc::Gltf(d) => Texture::Gltf(self.gltf_texture(d)?),
        })
    }
}

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

    pub(crate) fn gltf_texture(&mut self, d: &GltfTextureDesc) -> Result<Arc<GltfTexture>, Error> {
        let image = self.gltf_image(d)?;
        let mut t = GltfTexture::new(image, d.texcoord, [d.wrap_s, d.wrap_t], d.nearest);
        t.transform = d.transform;
        t.scale = d.scale;
        Ok(Arc::new(t))
    }

    pub(crate) fn optional_gltf(&mut self, t: &Option<TextureDesc>) -> Result<Option<Arc<GltfTexture>>, Error> {
        match t {
            Some(TextureDesc::Gltf(d)) => Ok(Some(self.gltf_texture(d)?)),
            Some(_) => Err(Error::new("a glTF material's textures must be glTF textures")),
            None => Ok(None),
        }
    }
}
