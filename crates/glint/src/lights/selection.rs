//! How the integrators choose which light to sample for next-event estimation.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightSelection {
    Uniform,
    /// Proportional to area (the paper's choice); non-area lights get the mean weight.
    Area,
    /// Proportional to emitted power among bounded lights; each infinite light (sky,
    /// environment map, directional) is chosen as often as all bounded lights together; half
    /// of the choices are made so, the other half uniformly (see `World::POWER_SHARE`).
    #[default]
    Power,
}

impl std::str::FromStr for LightSelection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "uniform" => Ok(LightSelection::Uniform),
            "area" => Ok(LightSelection::Area),
            "power" => Ok(LightSelection::Power),
            _ => Err(format!("unknown light selection '{s}' (expected uniform, area or power)")),
        }
    }
}
