//! Integrator settings as a scene describes them (the integrators themselves live in
//! `integrators`, which reads these).

use serde::{Deserialize, Serialize};

/// Which estimators contribute; all three converge to the same image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Strategy {
    /// Light sampling and BSDF sampling combined by MIS (the default).
    #[default]
    Mis,
    /// Light sampling only (emitters hit by BSDF rays count only after delta bounces).
    Light,
    /// BSDF sampling only (no shadow rays).
    Bsdf,
}

impl std::str::FromStr for Strategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mis" => Ok(Strategy::Mis),
            "light" => Ok(Strategy::Light),
            "bsdf" => Ok(Strategy::Bsdf),
            _ => Err(format!("unknown strategy '{s}' (expected mis, light or bsdf)")),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PathSettings {
    /// Longest path in segments; `None` is unbounded.
    pub max_depth: Option<u32>,
    /// Depth (segments) from which Russian roulette may end paths.
    pub rr_depth: u32,
    /// A fixed survival probability (the paper's P) instead of the throughput-based one.
    pub rr_probability: Option<f32>,
    pub strategy: Strategy,
    /// Look through emitters seen directly by the camera (as Mitsuba does: what lies behind
    /// an area light shows instead), and leave the sky black.
    pub hide_emitters: bool,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            max_depth: None,
            rr_depth: 5,
            rr_probability: None,
            strategy: Strategy::Mis,
            hide_emitters: false,
        }
    }
}

/// Direct illumination only (Mitsuba's `direct`): at the first hit, `emitter_samples` light
/// samples and `bsdf_samples` BSDF samples combined by MIS weighted by those counts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DirectSettings {
    pub emitter_samples: u32,
    pub bsdf_samples: u32,
    /// Look through emitters seen directly by the camera, and leave the sky black.
    pub hide_emitters: bool,
}

impl Default for DirectSettings {
    fn default() -> Self {
        DirectSettings { emitter_samples: 1, bsdf_samples: 1, hide_emitters: false }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WhittedSettings {
    pub max_depth: u32,
    /// Radiance of rays that leave the scene (when no environment light is defined).
    pub background: [f32; 3],
}

impl Default for WhittedSettings {
    fn default() -> Self {
        WhittedSettings { max_depth: 5, background: [0.0, 0.0, 0.0] }
    }
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
