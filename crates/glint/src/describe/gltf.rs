//! The description of a glTF 2.0 material (metallic-roughness with the KHR extensions
//! Blender writes) and of a glTF texture reference (image, sampler, texture coordinate set,
//! `KHR_texture_transform`).

use crate::error::SourceLoc;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A sampler's wrap mode along one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GltfWrap {
    Repeat,
    Clamp,
    Mirror,
}

/// An image of a glTF file as a texture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GltfTextureDesc {
    /// The `.gltf` or `.glb` file the image belongs to.
    pub file: PathBuf,
    /// Index into the file's `images`.
    pub image: usize,
    /// Colour channels stored sRGB-encoded (base colour, emission) rather than linear.
    pub srgb: bool,
    /// Which `TEXCOORD_n` set: 0 or 1.
    pub texcoord: u32,
    pub wrap_s: GltfWrap,
    pub wrap_t: GltfWrap,
    /// Nearest-texel lookup (else bilinear).
    pub nearest: bool,
    /// `KHR_texture_transform` as the 2x3 matrix uv' = M (u, v, 1) (identity without it).
    pub transform: [[f32; 3]; 2],
    /// Multiplies the colour channels (emissive factor and strength, for instance).
    pub scale: Rgb,
    pub loc: SourceLoc,
}
