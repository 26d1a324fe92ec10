//! The layers a film can keep beside the image (arbitrary output variables), as a scene or
//! a command line names them. The film's side (channels, storage) is in `render::aov`.

use serde::{Deserialize, Serialize};
use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Aov {
    /// Reflectance at the first hit (what denoisers want as their albedo guide).
    Albedo,
    /// Shading normal at the first hit, world space.
    Normal,
    /// Distance along the camera ray to the first hit.
    Depth,
    /// World-space position of the first hit.
    Position,
    /// Variance of the pixel mean, per channel.
    Variance,
    /// Samples taken in the pixel.
    Spp,
    /// BVH nodes plus primitives visited by the camera ray's closest-hit query.
    BvhCost,
}

impl Aov {
    pub const ALL: [Aov; 7] =
        [Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Position, Aov::Variance, Aov::Spp, Aov::BvhCost];

    /// The name on the command line and the prefix of the EXR channels.
    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
            Aov::Position => "position",
            Aov::Variance => "variance",
            Aov::Spp => "spp",
            Aov::BvhCost => "bvh-cost",
        }
    }
}

impl fmt::Display for Aov {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Aov {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Aov::ALL.into_iter().find(|a| a.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Aov::ALL.iter().map(|a| a.name()).collect();
            format!("unknown AOV '{s}' (expected one of {})", names.join(", "))
        })
    }
}
