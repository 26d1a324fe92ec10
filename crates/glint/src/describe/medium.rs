//! Participating media as a scene describes them, and the settings of the volumetric path
//! tracer that renders them (the media themselves live in `media`).

use crate::error::SourceLoc;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};

/// A homogeneous medium (Mitsuba's `homogeneous`): extinction `sigma_t * scale` per unit
/// length in every channel, and the single-scattering albedo (scattering over extinction).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    pub name: String,
    pub sigma_t: Rgb,
    pub albedo: Rgb,
    #[serde(default = "one")]
    pub scale: f32,
    #[serde(default)]
    pub phase: PhaseDesc,
    /// Next-event estimation from scattering points inside the medium (Mitsuba's
    /// `sample_emitters`): off only pays where shadow rays cannot reach a light anyway (a
    /// medium inside glass).
    #[serde(default = "yes")]
    pub sample_emitters: bool,
    #[serde(default)]
    pub loc: SourceLoc,
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

/// The volumetric path tracer (Mitsuba's `volpath`): the path tracer's depth, roulette and
/// `hide_emitters`, with media; depth counts scattering events in media and at surfaces
/// (not passages through `null` boundaries), as Mitsuba counts them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolpathSettings {
    /// Longest path in segments; `None` is unbounded.
    pub max_depth: Option<u32>,
    /// Depth from which Russian roulette may end paths.
    pub rr_depth: u32,
    pub hide_emitters: bool,
}

impl Default for VolpathSettings {
    fn default() -> Self {
        VolpathSettings { max_depth: None, rr_depth: 5, hide_emitters: false }
    }
}
