//! The editable parameters of a description: mutable places that a parameter name (the
//! Python API's `traverse`) points at, and the helpers materials list theirs with.

use super::{Matrix4, Roughness, ScalarTexture, Texels, TextureDesc};
use crate::math::Rgb;
use std::path::Path;

/// A mutable place in the description that a parameter names.
pub enum Slot<'a> {
    Float(&'a mut f32),
    Color(&'a mut Rgb),
    Matrix(&'a mut Matrix4),
    /// The camera's transform, which may be unset (the bounds are framed).
    OptionalMatrix(&'a mut Option<Matrix4>),
    /// An image's texels: its file's (read as `raw` says) until an edit sets `texels`.
    /// `uv` is the texture's mapping of surface uv, (scale, offset): the identity for an
    /// environment map, which maps directions.
    Texels {
        file: &'a Path,
        raw: bool,
        texels: &'a mut Option<Texels>,
        uv: [[f32; 2]; 2],
    },
}

/// A roughness's constant values, if it has a roughness.
pub fn roughness_slots<'a>(r: &'a mut Option<Roughness>, out: &mut Vec<(&'static str, Slot<'a>)>) {
    if let Some(r) = r {
        roughness_value_slots(r, out);
    }
}

/// The constant roughness values (textured ones are not edited in place).
pub fn roughness_value_slots<'a>(r: &'a mut Roughness, out: &mut Vec<(&'static str, Slot<'a>)>) {
    if let ScalarTexture::Value(a) = &mut r.alpha {
        out.push(("alpha", Slot::Float(a)));
    }
    if let Some(ScalarTexture::Value(a)) = &mut r.alpha_v {
        out.push(("alpha_v", Slot::Float(a)));
    }
}

/// A texture's colour where it is a constant, its texels where it is an image file.
pub fn texture_slot<'a>(name: &'static str, t: &'a mut TextureDesc, out: &mut Vec<(&'static str, Slot<'a>)>) {
    match t {
        TextureDesc::Constant { color } => out.push((name, Slot::Color(color))),
        TextureDesc::Bitmap { file, raw, texels, uv_scale, uv_offset, .. } => {
            out.push((name, Slot::Texels { file, raw: *raw, texels, uv: [*uv_scale, *uv_offset] }))
        }
        TextureDesc::Checkerboard { .. } | TextureDesc::MeshAttribute { .. } | TextureDesc::Gltf(_) => {}
    }
}
