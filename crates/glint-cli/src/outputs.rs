//! Writing what a film holds: the image and its AOV layers. In EXR the layers are channels
//! beside the beauty (`albedo.R`, `depth.Z`, ...); for PNG and PFM each layer is its own PNG,
//! `OUT.NAME.png`, mapped to a visible range.

use glint::io::image_io::ImageFormat;
use glint::io::layers::{temp_path, write_exr_channels, Channel};
use glint::io::Image;
use glint::math::Rgb;
use glint::render::{Aov, AovImage, Film};
use std::path::{Path, PathBuf};

/// The files a render with these AOVs writes to `out`.
pub fn output_files(out: &Path, aovs: &[Aov]) -> Vec<PathBuf> {
    let mut files = vec![out.to_path_buf()];
    if !matches!(ImageFormat::from_path(out), Ok(ImageFormat::Exr)) {
        files.extend(aovs.iter().map(|a| layer_png(out, *a)));
    }
    files
}

/// Every temporary file those writes may create.
pub fn temp_files(out: &Path, aovs: &[Aov]) -> Vec<PathBuf> {
    output_files(out, aovs).iter().map(|p| temp_path(p)).collect()
}

fn layer_png(out: &Path, aov: Aov) -> PathBuf {
    let stem = out.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
    out.with_file_name(format!("{stem}.{}.png", aov.name()))
}

/// Writes the film's image and layers to `out` (extra layers named `extra` go beside them).
pub fn write_film_image(film: &Film, out: &Path, extra: &[(String, Image)]) -> Result<(), String> {
    write_image_and_layers(&film.image(), film, out, extra)
}

pub fn write_image_and_layers(image: &Image, film: &Film, out: &Path, extra: &[(String, Image)]) -> Result<(), String> {
    let layers: Vec<AovImage> = film.aovs().iter().filter_map(|a| film.aov(*a)).collect();
    match ImageFormat::from_path(out)? {
        ImageFormat::Exr => {
            let (w, h) = (image.width, image.height);
            let split = |img: &Image| -> [Vec<f32>; 3] {
                [
                    img.pixels.iter().map(|p| p.r).collect(),
                    img.pixels.iter().map(|p| p.g).collect(),
                    img.pixels.iter().map(|p| p.b).collect(),
                ]
            };
            let beauty = split(image);
            let extras: Vec<(String, [Vec<f32>; 3])> = extra.iter().map(|(n, img)| (n.clone(), split(img))).collect();
            let layer_values: Vec<Vec<Vec<f32>>> = layers
                .iter()
                .map(|l| {
                    let nc = l.channels.len();
                    (0..nc).map(|c| l.data.iter().skip(c).step_by(nc).copied().collect()).collect()
                })
                .collect();
            let mut channels: Vec<Channel> =
                ["R", "G", "B"].iter().zip(&beauty).map(|(n, v)| Channel { name: n.to_string(), values: v }).collect();
            for (name, values) in &extras {
                for (c, v) in ["R", "G", "B"].iter().zip(values) {
                    channels.push(Channel { name: format!("{name}.{c}"), values: v });
                }
            }
            for (l, values) in layers.iter().zip(&layer_values) {
                for (name, v) in l.channels.iter().zip(values) {
                    channels.push(Channel { name: name.clone(), values: v });
                }
            }
            write_exr_channels(out, w, h, &channels)
        }
        // Extra layers (the noisy image of a denoised render) are EXR-only.
        ImageFormat::Png | ImageFormat::Pfm => {
            glint::io::write_image(image, out)?;
            for l in &layers {
                let aov: Aov = l.name.parse()?;
                glint::io::write_image(&visible(l, aov), &layer_png(out, aov))?;
            }
            Ok(())
        }
    }
}

/// A layer as an 8-bit-friendly image: normals from [-1, 1] to [0, 1], colours as they are,
/// and scalar layers (depth, spp, cost) and positions scaled by their largest value.
fn visible(l: &AovImage, aov: Aov) -> Image {
    let nc = l.channels.len();
    let mut img = Image::new(l.width, l.height);
    let max = l.data.iter().copied().filter(|v| v.is_finite()).fold(0.0f32, |a, v| a.max(v.abs())).max(1e-20);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        let v = &l.data[i * nc..(i + 1) * nc];
        *p = match aov {
            Aov::Albedo => Rgb { r: v[0], g: v[1], b: v[2] },
            Aov::Normal => Rgb { r: 0.5 * v[0] + 0.5, g: 0.5 * v[1] + 0.5, b: 0.5 * v[2] + 0.5 },
            Aov::Position => Rgb { r: 0.5 + 0.5 * v[0] / max, g: 0.5 + 0.5 * v[1] / max, b: 0.5 + 0.5 * v[2] / max },
            Aov::Variance => Rgb { r: v[0] / max, g: v[1] / max, b: v[2] / max },
            Aov::Depth | Aov::Spp | Aov::BvhCost => Rgb::splat(v[0] / max),
        };
        // PNG output applies the sRGB curve; these are data, so undo it to keep them linear
        // on screen.
        *p = p.map(|c| glint::math::srgb_decode(c.clamp(0.0, 1.0)));
    }
    img
}
