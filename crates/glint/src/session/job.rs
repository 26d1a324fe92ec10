//! What a film was rendered with, stored in its checkpoint beside the sums: the edited scene
//! description, the build and film settings. `glint resume` and `glint merge` read it back;
//! two films merge only when their jobs agree (`output` aside).

use crate::accel::BvhSplit;
use crate::error::Error;
use crate::materials::SceneDesc;
use crate::render::{Adaptive, Aov};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Version of this JSON payload inside the film format (the film format has its own).
pub const JOB_VERSION: u32 = 1;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderJob {
    pub version: u32,
    pub desc: SceneDesc,
    pub bvh_split: BvhSplit,
    pub spp: u32,
    pub pass_spp: u32,
    pub aovs: Vec<Aov>,
    pub adaptive: Option<Adaptive>,
    /// Where the image goes (for `glint resume`); not part of what must agree to merge.
    pub output: Option<PathBuf>,
}

impl RenderJob {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a job serialises")
    }

    pub fn from_json(text: &str) -> Result<RenderJob, Error> {
        let v: serde_json::Value =
            serde_json::from_str(text).map_err(|e| Error::new(format!("the film's settings are not valid: {e}")))?;
        let version = v.get("version").and_then(|v| v.as_u64()).unwrap_or(0);
        if version != JOB_VERSION as u64 {
            return Err(Error::new(format!(
                "the film's settings are version {version}; this glint reads version {JOB_VERSION}"
            )));
        }
        serde_json::from_value(v).map_err(|e| Error::new(format!("the film's settings are not valid: {e}")))
    }

    /// True when films of the two jobs can be added together.
    pub fn same_render(&self, other: &RenderJob) -> bool {
        RenderJob { output: None, ..self.clone() } == RenderJob { output: None, ..other.clone() }
    }
}
