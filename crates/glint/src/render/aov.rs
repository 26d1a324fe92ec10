//! Arbitrary output variables: the layers a film can keep beside the beauty image.
//!
//! Albedo, normal, depth, position and BVH cost are averaged per sample (first hit of the
//! camera ray; zero where the ray escapes). Variance and spp are derived from the beauty
//! sums, so they cost no storage.

pub use crate::describe::Aov;

// The film's side of the layers; the enum, its names and parsing are the description's.
impl Aov {
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
