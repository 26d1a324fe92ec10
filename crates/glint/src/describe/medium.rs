//! Participating media as a scene describes them (the media themselves live in `media`;
//! the volumetric path tracer's settings are with the other integrators').

use super::Matrix4;
use crate::error::SourceLoc;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A homogeneous medium (Mitsuba's `homogeneous`): extinction `sigma_t * scale` per unit
/// length in every channel, and the single-scattering albedo (scattering over extinction),
/// constant or looked up in a grid volume at each scattering point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    pub name: String,
    pub sigma_t: Rgb,
    pub albedo: VolumeDesc,
    #[serde(default = "one")]
    pub scale: f32,
    #[serde(default)]
    pub phase: PhaseDesc,
    /// Next-event estimation from scattering points inside the medium (Mitsuba's
    /// `sample_emitters`): off only pays where shadow rays cannot reach a light anyway (a
    /// medium inside glass).
    #[serde(default = "yes")]
    pub sample_emitters: bool,
    /// Mitsuba's `heterogeneous` with a `gridvolume` `sigma_t`: a grey density grid (1
    /// channel) that multiplies `sigma_t` (then grey) point by point; `None` is homogeneous.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<GridVolumeDesc>,
    /// The medium only absorbs (homogeneous, constant albedo 0: glTF's
    /// `KHR_materials_volume` attenuation): a path crossing it carries its transmittance
    /// instead of ending where an absorption is sampled (the same expectation, no variance).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub absorbing_only: bool,
    #[serde(default)]
    pub loc: SourceLoc,
}

/// A quantity that may vary through space (Mitsuba's `<volume>`): a constant (a colour, or
/// a `constvolume`) or a grid of values read from a `.vol` file (`gridvolume`). A constant
/// is written as its colour alone.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum VolumeDesc {
    Constant(Rgb),
    Grid(GridVolumeDesc),
}

impl VolumeDesc {
    /// The constant value, `None` for a grid.
    pub fn constant(&self) -> Option<Rgb> {
        match self {
            VolumeDesc::Constant(c) => Some(*c),
            VolumeDesc::Grid(_) => None,
        }
    }
}

impl From<Rgb> for VolumeDesc {
    fn from(c: Rgb) -> Self {
        VolumeDesc::Constant(c)
    }
}

/// Mitsuba's `gridvolume`: the values of a `.vol` file (1 or 3 channels) on the unit cube,
/// placed in the world by `to_world` (the file's own bounding box is not used, as in
/// Mitsuba 3). Cell (i, j, k) holds the value at the cell's centre ((i + 0.5) / res_x, ...).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridVolumeDesc {
    pub file: PathBuf,
    #[serde(default)]
    pub filter: GridFilter,
    #[serde(default)]
    pub wrap: GridWrap,
    #[serde(default = "identity")]
    pub to_world: Matrix4,
    #[serde(default)]
    pub loc: SourceLoc,
}

fn identity() -> Matrix4 {
    super::IDENTITY
}

/// How a grid volume is interpolated between cell centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GridFilter {
    /// Trilinear interpolation between the 8 nearest cell centres.
    #[default]
    Trilinear,
    /// The value of the cell the point lies in.
    Nearest,
}

/// What a grid volume holds outside the unit cube.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GridWrap {
    /// The edge cells extend outwards (Mitsuba's default).
    #[default]
    Clamp,
    /// The grid tiles space.
    Repeat,
    /// The grid tiles space, every other copy mirrored.
    Mirror,
}

fn one() -> f32 {
    1.0
}
fn yes() -> bool {
    true
}

/// How a medium scatters: the phase function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum PhaseDesc {
    #[default]
    Isotropic,
    /// Henyey-Greenstein with mean cosine `g` in (-1, 1): positive scatters forwards.
    Hg { g: f32 },
}
