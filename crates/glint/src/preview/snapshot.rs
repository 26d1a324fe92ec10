//! A copy of the film's means for a live view: the beauty, each layer, and per pixel the
//! samples taken and the relative error; tone-mapped to 8-bit RGB on request.

use super::RenderProgress;
use crate::math::srgb_encode;
use crate::render::{relative_error, Aov, Film};
use rayon::prelude::*;

/// How a layer's values read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LayerKind {
    /// Radiance or reflectance: exposure, then sRGB or linear.
    Color,
    /// A unit vector in [-1, 1] (normals), shown as (v + 1) / 2.
    Direction,
    /// Anything else (position, depth, spp, cost): scaled by its largest magnitude.
    Data,
}

/// One image of the snapshot: `channels` values per pixel, row-major.
#[derive(Clone, Debug)]
pub struct Layer {
    pub name: String,
    pub kind: LayerKind,
    pub channels: usize,
    /// Channel names as in EXR: `R`, `G`, `B` for the beauty, `albedo.R`, `depth.Z`, ...
    pub channel_names: Vec<String>,
    pub data: Vec<f32>,
}

/// The film's state at one pass.
#[derive(Clone, Debug)]
pub struct Snapshot {
    pub width: usize,
    pub height: usize,
    /// The beauty first, then the film's layers.
    pub layers: Vec<Layer>,
    /// Samples taken in each pixel.
    pub spp: Vec<u32>,
    /// The relative standard error of each pixel's mean (what adaptive sampling reads).
    pub rel_error: Vec<f32>,
    pub progress: RenderProgress,
}

/// How the page wants a layer drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    Srgb,
    Linear,
    /// Luminance through a colour map (black, blue, red, yellow, white).
    FalseColor,
}

impl View {
    pub fn parse(s: &str) -> Option<View> {
        match s {
            "srgb" => Some(View::Srgb),
            "linear" => Some(View::Linear),
            "false" => Some(View::FalseColor),
            _ => None,
        }
    }
}

/// Exposure (in stops) and view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneMap {
    pub exposure: f32,
    pub view: View,
}

impl Snapshot {
    /// Copies the film's means (the beauty, every layer it keeps) and per-pixel statistics.
    pub fn of(film: &Film, progress: &RenderProgress) -> Snapshot {
        let (width, height) = (film.width() as usize, film.height() as usize);
        let (beauty, spp, rel_error) = beauty_and_statistics(film);
        let mut layers = vec![Layer {
            name: "beauty".into(),
            kind: LayerKind::Color,
            channels: 3,
            channel_names: ["R", "G", "B"].map(String::from).to_vec(),
            data: beauty,
        }];
        for &aov in film.aovs() {
            let Some(img) = film.aov(aov) else { continue };
            let kind = match aov {
                Aov::Albedo | Aov::Variance => LayerKind::Color,
                Aov::Normal => LayerKind::Direction,
                _ => LayerKind::Data,
            };
            layers.push(Layer {
                name: img.name,
                kind,
                channels: img.channels.len(),
                channel_names: img.channels,
                data: img.data,
            });
        }
        Snapshot { width, height, layers, spp, rel_error, progress: progress.clone() }
    }

    pub fn layer(&self, name: &str) -> Option<&Layer> {
        self.layers.iter().find(|l| l.name == name)
    }

    /// The layer as 8-bit RGB, row-major.
    pub fn tone_map(&self, layer: &Layer, tm: ToneMap) -> Vec<u8> {
        let n = self.width * self.height;
        let c = layer.channels;
        let scale = 2f32.powf(tm.exposure);
        // Data layers are scaled by their largest magnitude so that any range is visible.
        let norm = match layer.kind {
            LayerKind::Data => {
                let m = layer.data.iter().filter(|v| v.is_finite()).fold(0f32, |m, v| m.max(v.abs()));
                if m > 0.0 {
                    1.0 / m
                } else {
                    1.0
                }
            }
            _ => 1.0,
        };
        let mut out = Vec::with_capacity(n * 3);
        for px in layer.data.chunks_exact(c) {
            let rgb = if c >= 3 { [px[0], px[1], px[2]] } else { [px[0]; 3] };
            let rgb = match layer.kind {
                LayerKind::Direction => rgb.map(|v| (v * 0.5 + 0.5) * scale),
                LayerKind::Data => rgb.map(|v| v.abs() * norm * scale),
                LayerKind::Color => rgb.map(|v| v * scale),
            };
            let mapped = match tm.view {
                View::Srgb => rgb.map(srgb_encode),
                View::Linear => rgb,
                View::FalseColor => false_color(0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]),
            };
            out.extend(mapped.map(to_byte));
        }
        out
    }

    /// What the pixel inspector shows at (x, y): its linear values in every layer, its
    /// samples and its relative error, as JSON. None outside the image.
    pub fn pixel_json(&self, x: usize, y: usize) -> Option<String> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = y * self.width + x;
        let layers: serde_json::Map<String, serde_json::Value> = self
            .layers
            .iter()
            .map(|l| {
                let v: Vec<serde_json::Value> =
                    l.data[i * l.channels..(i + 1) * l.channels].iter().map(|&v| finite_or_null(v)).collect();
                (l.name.clone(), serde_json::Value::Array(v))
            })
            .collect();
        let v = serde_json::json!({
            "x": x,
            "y": y,
            "spp": self.spp[i],
            "rel_error": finite_or_null(self.rel_error[i]),
            "layers": layers,
        });
        Some(v.to_string())
    }
}

/// The beauty (RGB, as [`Film::image`] gives it), the samples and the relative error of each
/// pixel, in one parallel pass over the film's sums: the render's threads are idle while this
/// runs between passes, and its time is what a watched render pays.
fn beauty_and_statistics(film: &Film) -> (Vec<f32>, Vec<u32>, Vec<f32>) {
    let (width, height) = (film.width() as usize, film.height() as usize);
    let mut beauty = vec![0f32; width * height * 3];
    let mut spp = vec![0u32; width * height];
    let mut rel_error = vec![f32::INFINITY; width * height];
    let region = film.region();
    let (x0, rw) = (region.x0 as usize, region.width() as usize);
    let sums = film.region_sums();
    let rows = beauty.par_chunks_mut(width * 3).zip(spp.par_chunks_mut(width)).zip(rel_error.par_chunks_mut(width));
    rows.enumerate().skip(region.y0 as usize).take(region.height() as usize).for_each(|(y, ((b, n), e))| {
        let row = &sums[(y - region.y0 as usize) * rw..][..rw];
        for (i, s) in row.iter().enumerate() {
            let m = s.mean();
            b[(x0 + i) * 3..][..3].copy_from_slice(&m.map(|v| v as f32));
            n[x0 + i] = s.count.min(u32::MAX as u64) as u32;
            if s.count > 1 {
                e[x0 + i] = relative_error(s) as f32;
            }
        }
    });
    if film.splat_rect().is_some() {
        // A splatting filter's pixel values are weighted means of the splats it received.
        beauty = film.image().pixels.iter().flat_map(|p| [p.r, p.g, p.b]).collect();
    }
    (beauty, spp, rel_error)
}

fn finite_or_null(v: f32) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}

fn to_byte(v: f32) -> u8 {
    // NaN maps to 0 (`as` saturates and sends NaN to 0).
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// A colour map from black through blue, red and yellow to white, over [0, 1].
fn false_color(v: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] =
        [[0.0, 0.0, 0.0], [0.15, 0.1, 0.7], [0.85, 0.15, 0.25], [1.0, 0.85, 0.1], [1.0, 1.0, 1.0]];
    let t = if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 } * (STOPS.len() - 1) as f32;
    let k = (t as usize).min(STOPS.len() - 2);
    let f = t - k as f32;
    [0, 1, 2].map(|c| STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn false_color_runs_from_black_to_white_and_maps_nan_to_black() {
        assert_eq!(false_color(0.0), [0.0; 3]);
        assert_eq!(false_color(1.0), [1.0; 3]);
        assert_eq!(false_color(f32::NAN), [0.0; 3]);
        assert_eq!(to_byte(f32::NAN), 0);
        assert_eq!(to_byte(2.0), 255);
    }
}
