//! The description of a blend of two materials (Mitsuba's `blendbsdf`).

use super::{MaterialModel, TextureDesc};
use serde::{Deserialize, Serialize};

/// One of a blend's two materials, with its own sidedness (a `twosided` inside the blend).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlendPartDesc {
    pub model: MaterialModel,
    pub two_sided: bool,
}

/// (1 - weight) · first + weight · second; the weight is a grey texture (its luminance).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlendDesc {
    pub weight: TextureDesc,
    pub first: Box<BlendPartDesc>,
    pub second: Box<BlendPartDesc>,
}
