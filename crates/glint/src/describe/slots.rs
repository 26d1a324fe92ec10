//! The editable parameters of a description: mutable places that a parameter name (the
//! Python API's `traverse`) points at, and the helpers materials list theirs with.

use super::{Matrix4, Roughness, ScalarTexture, TextureDesc};
use crate::math::Rgb;

/// A mutable place in the description that a parameter names.
pub enum Slot<'a> {
    Float(&'a mut f32),
    Color(&'a mut Rgb),
    Matrix(&'a mut Matrix4),
    /// The camera's transform, which may be unset (the bounds are framed).
    OptionalMatrix(&'a mut Option<Matrix4>),
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

/// A texture's colour where it is a constant (image textures are not edited in place).
pub fn texture_slot<'a>(name: &'static str, t: &'a mut TextureDesc, out: &mut Vec<(&'static str, Slot<'a>)>) {
    if let TextureDesc::Constant { color } = t {
        out.push((name, Slot::Color(color)));
    }
}
