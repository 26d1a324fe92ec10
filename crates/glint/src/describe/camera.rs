//! The camera's and film's vocabulary as a scene states it (the camera itself lives in
//! `camera`).

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum FovAxis {
    X,
    #[default]
    Y,
    Diagonal,
    Smaller,
    Larger,
}

impl std::str::FromStr for FovAxis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "x" => Ok(FovAxis::X),
            "y" => Ok(FovAxis::Y),
            "diagonal" => Ok(FovAxis::Diagonal),
            "smaller" => Ok(FovAxis::Smaller),
            "larger" => Ok(FovAxis::Larger),
            _ => Err(format!("unknown fov axis '{s}' (expected x, y, diagonal, smaller or larger)")),
        }
    }
}

/// How camera space maps onto the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Projection {
    /// Rays from the origin through the image plane at z = 1 (the field of view's).
    #[default]
    Perspective,
    /// Parallel rays along +z from the plane z = `near_clip`, the film spanning x in
    /// [-1, 1] and y in [-1/aspect, 1/aspect] of camera space (Mitsuba's `orthographic`:
    /// its `to_world` scales that window).
    Orthographic,
}

/// Part of the full image that is rendered (Mitsuba's film crop window), in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CropWindow {
    pub offset_x: u32,
    pub offset_y: u32,
    pub width: u32,
    pub height: u32,
}
