//! What a render writes, by one rule for every front end (the command line, Python's
//! `write_image`, the distributed driver): in EXR, the layers are channels beside the
//! beauty (`albedo.R`, `depth.Z`, `noisy.G`, ...); for PNG and PFM, each layer is a PNG of
//! its own, `OUT.NAME.png`, mapped to a visible range. Every file is written to a
//! temporary name and renamed.

use crate::denoise::Denoiser;
use crate::error::{Error, SourceLoc};
use crate::io::image_io::ImageFormat;
use crate::io::layers::{write_exr_channels, Channel};
use crate::io::Image;
use crate::materials::SceneDesc;
use crate::math::Rgb;
use crate::render::{Aov, AovImage, Film};
use std::path::{Path, PathBuf};

/// The layer that keeps the image as rendered when the output is denoised.
pub const NOISY_LAYER: &str = "noisy";

/// The image of a render and its layers, as written.
#[derive(Clone, Debug)]
pub struct Outputs {
    pub image: Image,
    pub layers: Vec<AovImage>,
}

impl Outputs {
    /// The film's image and its AOV layers.
    pub fn of_film(film: &Film) -> Outputs {
        Outputs { image: film.image(), layers: film.aovs().iter().filter_map(|a| film.aov(*a)).collect() }
    }

    /// The image denoised, guided by the film's albedo and normal layers; the image as
    /// rendered becomes the layer [`NOISY_LAYER`], ahead of the others.
    pub fn denoised(self, denoiser: &Denoiser) -> Result<Outputs, Error> {
        let guide = |aov: Aov| {
            let l = self.layers.iter().find(|l| l.name == aov.name() && l.channels.len() == 3);
            l.map(layer_image).ok_or_else(|| Error::new(format!("denoise: the film has no {} layer", aov.name())))
        };
        let (albedo, normal) = (guide(Aov::Albedo)?, guide(Aov::Normal)?);
        let clean = denoiser.denoise(&self.image, Some(&albedo), Some(&normal))?;
        let noisy = AovImage {
            name: NOISY_LAYER.to_string(),
            channels: layer_channels(NOISY_LAYER, 3),
            width: self.image.width,
            height: self.image.height,
            data: self.image.pixels.iter().flat_map(|p| p.to_array()).collect(),
        };
        let layers = std::iter::once(noisy).chain(self.layers).collect();
        Ok(Outputs { image: clean, layers })
    }

    /// Whether [`Outputs::write`] can write these to `out`: a known format and, beside a
    /// PNG or PFM image, layers a PNG can show. Checked before anything is written.
    pub fn check(&self, out: &Path) -> Result<(), String> {
        match ImageFormat::from_path(out)? {
            ImageFormat::Exr => Ok(()),
            ImageFormat::Png | ImageFormat::Pfm => self.layers.iter().try_for_each(|l| look(l).map(|_| ())),
        }
    }

    /// Writes the image to `out` (the extension chooses the format) and the layers beside
    /// it; nothing is written when [`Outputs::check`] fails.
    pub fn write(&self, out: &Path) -> Result<(), String> {
        self.check(out)?;
        let image = &self.image;
        match ImageFormat::from_path(out)? {
            ImageFormat::Exr => {
                let planes = |data: &[f32], nc: usize| -> Vec<Vec<f32>> {
                    (0..nc).map(|c| data.iter().skip(c).step_by(nc).copied().collect()).collect()
                };
                let beauty: Vec<f32> = image.pixels.iter().flat_map(|p| p.to_array()).collect();
                let mut named = vec![(vec!["R".to_string(), "G".into(), "B".into()], planes(&beauty, 3))];
                for l in &self.layers {
                    named.push((l.channels.clone(), planes(&l.data, l.channels.len())));
                }
                let channels: Vec<Channel> = named
                    .iter()
                    .flat_map(|(names, values)| names.iter().zip(values))
                    .map(|(name, values)| Channel { name: name.clone(), values })
                    .collect();
                write_exr_channels(out, image.width, image.height, &channels)
            }
            ImageFormat::Png | ImageFormat::Pfm => {
                crate::io::write_image(image, out)?;
                for l in &self.layers {
                    crate::io::write_image(&visible(l)?, &layer_png(out, &l.name))?;
                }
                Ok(())
            }
        }
    }
}

/// The files writing layers named `layers` beside the image `out` makes (the image first).
pub fn output_files(out: &Path, layers: &[&str]) -> Vec<PathBuf> {
    let mut files = vec![out.to_path_buf()];
    if !matches!(ImageFormat::from_path(out), Ok(ImageFormat::Exr)) {
        files.extend(layers.iter().map(|name| layer_png(out, name)));
    }
    files
}

/// The names of a film's layers, as [`Outputs`] of it names them (`denoised`: with the
/// noisy image first).
pub fn layer_names(aovs: &[Aov], denoised: bool) -> Vec<&'static str> {
    denoised.then_some(NOISY_LAYER).into_iter().chain(aovs.iter().map(|a| a.name())).collect()
}

/// The channel names of a layer of `count` channels called `name`: an AOV's own
/// (`albedo.R`, `normal.X`, `depth.Z`), else `NAME.R/G/B` for three channels, `NAME.Y` for
/// one, `NAME.0`, `NAME.1`, ... for other counts.
pub fn layer_channels(name: &str, count: usize) -> Vec<String> {
    if let Ok(aov) = name.parse::<Aov>() {
        let own = aov.channels();
        if own.len() == count {
            return own;
        }
    }
    match count {
        3 => ["R", "G", "B"].iter().map(|c| format!("{name}.{c}")).collect(),
        1 => vec![format!("{name}.Y")],
        _ => (0..count).map(|i| format!("{name}.{i}")).collect(),
    }
}

/// A three-channel layer as an image.
fn layer_image(l: &AovImage) -> Image {
    let mut img = Image::new(l.width, l.height);
    for (p, c) in img.pixels.iter_mut().zip(l.data.chunks_exact(3)) {
        *p = Rgb { r: c[0], g: c[1], b: c[2] };
    }
    img
}

fn layer_png(out: &Path, name: &str) -> PathBuf {
    let stem = out.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
    out.with_file_name(format!("{stem}.{name}.png"))
}

/// How a layer is shown in a PNG.
#[derive(Clone, Copy)]
enum Look {
    /// Colours as they are (albedo, a noisy image).
    Color,
    /// Directions from [-1, 1] to [0, 1].
    Direction,
    /// Points, centred, scaled by the largest coordinate.
    Point,
    /// Each channel scaled by the largest value.
    Scaled,
    /// One channel as grey, scaled by the largest value.
    Grey,
}

fn look(l: &AovImage) -> Result<Look, String> {
    let nc = l.channels.len();
    if let Ok(aov) = l.name.parse::<Aov>() {
        if aov.channels() == l.channels {
            return Ok(match aov {
                Aov::Albedo => Look::Color,
                Aov::Normal => Look::Direction,
                Aov::Position => Look::Point,
                Aov::Variance => Look::Scaled,
                Aov::Depth | Aov::Spp | Aov::BvhCost => Look::Grey,
            });
        }
    }
    match nc {
        3 => Ok(Look::Color),
        1 => Ok(Look::Grey),
        _ => Err(format!("layer {}: {nc} channels do not make a PNG (1 or 3 do)", l.name)),
    }
}

/// A layer as an 8-bit-friendly image.
fn visible(l: &AovImage) -> Result<Image, String> {
    let look = look(l)?;
    let nc = l.channels.len();
    let mut img = Image::new(l.width, l.height);
    let max = l.data.iter().copied().filter(|v| v.is_finite()).fold(0.0f32, |a, v| a.max(v.abs())).max(1e-20);
    for (p, v) in img.pixels.iter_mut().zip(l.data.chunks_exact(nc)) {
        *p = match look {
            Look::Color => Rgb { r: v[0], g: v[1], b: v[2] },
            Look::Direction => Rgb { r: 0.5 * v[0] + 0.5, g: 0.5 * v[1] + 0.5, b: 0.5 * v[2] + 0.5 },
            Look::Point => Rgb { r: 0.5 + 0.5 * v[0] / max, g: 0.5 + 0.5 * v[1] / max, b: 0.5 + 0.5 * v[2] / max },
            Look::Scaled => Rgb { r: v[0] / max, g: v[1] / max, b: v[2] / max },
            Look::Grey => Rgb::splat(v[0] / max),
        };
        // PNG output applies the sRGB curve; layers are data, so undo it to keep them
        // linear on screen.
        *p = p.map(|c| crate::math::srgb_decode(c.clamp(0.0, 1.0)));
    }
    Ok(img)
}

/// Before any sample is taken: the output's folder exists and is writable, and the output
/// is not one of the scene's own files.
pub fn check_output(out: &Path, desc: &SceneDesc) -> Result<(), Error> {
    let loc = SourceLoc::file(out);
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(Error::at(&loc, format!("the output folder {} does not exist", dir.display())));
    }
    let probe = dir.join(format!(".glint-write-test-{}", std::process::id()));
    match std::fs::File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) => return Err(Error::at(&loc, format!("cannot write to the folder {}: {e}", dir.display()))),
    }
    let same = |p: &Path| match (std::fs::canonicalize(p), std::fs::canonicalize(&dir)) {
        (Ok(input), Ok(d)) => out.file_name().is_some_and(|n| d.join(n) == input),
        _ => false,
    };
    if let Some(p) = desc.files().iter().find(|p| same(p)) {
        return Err(Error::at(&loc, format!("the output would overwrite the scene's input file {}", p.display())));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_channels_are_the_aovs_own_else_follow_the_count() {
        assert_eq!(layer_channels("normal", 3), ["normal.X", "normal.Y", "normal.Z"]);
        assert_eq!(layer_channels("depth", 1), ["depth.Z"]);
        assert_eq!(layer_channels("noisy", 3), ["noisy.R", "noisy.G", "noisy.B"]);
        assert_eq!(layer_channels("mask", 1), ["mask.Y"]);
        assert_eq!(layer_channels("depth", 2), ["depth.0", "depth.1"]);
    }

    #[test]
    fn png_outputs_get_one_file_per_layer_and_exr_one_in_all() {
        let names = layer_names(&[Aov::Albedo, Aov::Depth], true);
        assert_eq!(names, ["noisy", "albedo", "depth"]);
        let files = output_files(Path::new("out/x.pfm"), &names);
        let want: Vec<PathBuf> =
            ["out/x.pfm", "out/x.noisy.png", "out/x.albedo.png", "out/x.depth.png"].iter().map(PathBuf::from).collect();
        assert_eq!(files, want);
        assert_eq!(output_files(Path::new("x.exr"), &names), [PathBuf::from("x.exr")]);
    }
}
