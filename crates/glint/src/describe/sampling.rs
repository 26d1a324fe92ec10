//! How a scene asks to be sampled: the sampler, the pixel filter and the choice of lights
//! for next-event estimation (the samplers, filters and lights themselves live in
//! `sampling` and `lights`).

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum SamplerKind {
    Independent,
    #[default]
    Sobol,
}

impl std::str::FromStr for SamplerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "independent" => Ok(SamplerKind::Independent),
            "sobol" => Ok(SamplerKind::Sobol),
            _ => Err(format!("unknown sampler '{s}' (expected sobol or independent)")),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub enum PixelFilter {
    /// Uniform over the pixel.
    #[default]
    Box,
    /// Triangle of the given radius (pixels).
    Tent { radius: f32 },
    /// Gaussian of the given standard deviation (pixels), windowed at 4 standard deviations
    /// as Mitsuba does.
    Gaussian { stddev: f32 },
}

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
    /// By a light BVH, from each shading point, in proportion to a bound of what each group
    /// of lights sends there (`lights::LightTree`).
    Tree,
    /// `Tree` where it was measured to win (`World::AUTO_TREE_LIGHTS` or more bounded lights,
    /// or a mesh light whose radiance varies over the triangles it is split into: not a
    /// rectangle or a disk sampled by its texels, which is one leaf), else `Power`. Not the
    /// default: with a few lights the tree's error was higher than power's on 8 of 9 of
    /// Mitsuba's documentation scenes it would change (BENCHMARKS.md, "Light selection").
    Auto,
}

impl std::str::FromStr for LightSelection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "uniform" => Ok(LightSelection::Uniform),
            "area" => Ok(LightSelection::Area),
            "power" => Ok(LightSelection::Power),
            "tree" => Ok(LightSelection::Tree),
            "auto" => Ok(LightSelection::Auto),
            _ => Err(format!("unknown light selection '{s}' (expected auto, tree, power, uniform or area)")),
        }
    }
}
