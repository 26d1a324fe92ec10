//! Arbitrary output variables: the layers a film can keep beside the beauty image.
//!
//! Albedo, normal, depth, position and BVH cost are averaged per sample (first hit of the
//! camera ray; zero where the ray escapes). Variance and spp are derived from the beauty
//! sums, so they cost no storage.

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

    fn channel_suffixes(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo | Aov::Variance => &["R", "G", "B"],
            Aov::Normal | Aov::Position => &["X", "Y", "Z"],
            Aov::Depth => &["Z"],
            Aov::Spp | Aov::BvhCost => &["Y"],
        }
    }

    /// EXR channel names, e.g. `albedo.R`, `depth.Z`.
    pub fn channels(self) -> Vec<String> {
        self.channel_suffixes().iter().map(|s| format!("{}.{s}", self.name())).collect()
    }

    /// Channels whose per-sample sums the film stores (derived layers store none).
    pub fn stored_channels(self) -> usize {
        match self {
            Aov::Variance | Aov::Spp => 0,
            _ => self.channel_suffixes().len(),
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

/// One layer as an image: `data` holds `channels.len()` values per pixel, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct AovImage {
    pub name: String,
    pub channels: Vec<String>,
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_channels_follow_exr_conventions() {
        for aov in Aov::ALL {
            assert_eq!(aov.name().parse::<Aov>().unwrap(), aov);
        }
        assert_eq!(Aov::BvhCost.channels(), ["bvh-cost.Y"]);
        assert_eq!(Aov::Normal.channels(), ["normal.X", "normal.Y", "normal.Z"]);
        assert_eq!(Aov::Depth.channels(), ["depth.Z"]);
        assert!("bvh_cost".parse::<Aov>().unwrap_err().contains("bvh-cost"));
    }
}
