//! A film that accumulates samples in passes and can be stopped, resumed and merged.
//!
//! Per pixel it keeps sums that can be added: Σf and Σf² per RGB channel, the sample count,
//! and Σ of each stored AOV channel. **The sums are exact**, so the order in which samples,
//! tiles, passes or films are added never changes a bit of the result: every sample value
//! `v` is quantised to fixed point, `(v as f64 * 2^40).round() as i128` (40 fractional
//! bits), and the integers are added with `saturating_add`. The resolution is
//! 2^-40 ≈ 9.1e-13 per sample; values up to about 1.5e26 (and squares of values up to about
//! 1.2e13) are represented, beyond which the cast saturates (NaN becomes 0; the renderer drops
//! non-finite samples before they get here). An image rendered in one go, in passes, resumed
//! from a checkpoint, split into pass ranges or pixel regions rendered separately and merged,
//! or on any number of threads is therefore bit-identical by construction.
//!
//! Pass `p` covers sample indices `[p * pass_spp, min((p + 1) * pass_spp, spp))`. The film
//! records what it holds as [`Block`]s (a pixel region and a range of passes); merging
//! refuses blocks that overlap, so no sample can be counted twice.
//!
//! A film made with a filter other than the box also keeps splat sums ([`super::splat`]) over
//! its region grown by the filter's margin; its image is then the splatted one, while the
//! per-pixel sums above (of the samples taken in each pixel) still give the variance, sample
//! count and adaptive decisions.

use super::aov::{Aov, AovImage};
use super::splat::{splat_rect, SplatBuffer, SplatSums};
use crate::io::Image;
use crate::math::Rgb;
use crate::sampling::PixelFilter;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Largest reconstruction filter radius (pixels) a film takes; the scene validation allows less.
pub const MAX_FILTER_RADIUS: f32 = 64.0;

/// Fractional bits of the fixed-point sums.
pub const FIXED_POINT_BITS: u32 = 40;
const FIXED_SCALE: f64 = (1u64 << FIXED_POINT_BITS) as f64;

/// A sample value in fixed point (saturating; NaN becomes 0).
#[inline]
pub fn to_fixed(v: f64) -> i128 {
    let x = v * FIXED_SCALE;
    // `x.round() as i128` (half away from zero, NaN to 0, saturating), without the libm call
    // `round` is on baseline x86-64: below 2^52 a value has a fraction, which truncating to
    // i64 and subtracting gives exactly; from 2^52 up (and NaN, infinities) it has none.
    if x.abs() < 4_503_599_627_370_496.0 {
        let whole = x as i64;
        let fraction = x - whole as f64;
        (whole + (fraction >= 0.5) as i64 - (fraction <= -0.5) as i64) as i128
    } else {
        x as i128
    }
}

#[inline]
fn from_fixed(s: i128) -> f64 {
    // Sums that fit in an i64 (nearly all) convert in one instruction instead of the i128
    // routine; the integer is the same, so the rounding, and the result, are too.
    match i64::try_from(s) {
        Ok(small) => small as f64 / FIXED_SCALE,
        Err(_) => s as f64 / FIXED_SCALE,
    }
}

/// A pixel rectangle; `x1` and `y1` are exclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Rect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Rect {
    pub fn full(width: u32, height: u32) -> Rect {
        Rect { x0: 0, y0: 0, x1: width, y1: height }
    }
    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }
    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }
    pub fn area(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }
    pub fn is_empty(&self) -> bool {
        self.area() == 0
    }
    pub fn intersection(&self, o: &Rect) -> Rect {
        Rect { x0: self.x0.max(o.x0), y0: self.y0.max(o.y0), x1: self.x1.min(o.x1), y1: self.y1.min(o.y1) }
    }
    pub fn intersects(&self, o: &Rect) -> bool {
        !self.intersection(o).is_empty()
    }
    pub fn bounding(&self, o: &Rect) -> Rect {
        Rect { x0: self.x0.min(o.x0), y0: self.y0.min(o.y0), x1: self.x1.max(o.x1), y1: self.y1.max(o.y1) }
    }
    pub fn contains(&self, o: &Rect) -> bool {
        o.x0 >= self.x0 && o.y0 >= self.y0 && o.x1 <= self.x1 && o.y1 <= self.y1
    }
}

impl std::fmt::Display for Rect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "x {}..{}, y {}..{}", self.x0, self.x1, self.y0, self.y1)
    }
}

/// Samples a film holds: every pass of `passes` over every pixel of `region`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Block {
    pub region: Rect,
    pub passes: Range<u32>,
}

impl Block {
    pub fn overlaps(&self, o: &Block) -> bool {
        self.region.intersects(&o.region) && self.passes.start < o.passes.end && o.passes.start < self.passes.end
    }
}

/// Exact sums of one pixel's beauty samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelSums {
    pub sum: [i128; 3],
    pub sum_sq: [i128; 3],
    pub count: u64,
}

impl PixelSums {
    #[inline]
    pub fn add_sample(&mut self, l: Rgb) {
        for (k, v) in l.to_array().into_iter().enumerate() {
            let v = v as f64;
            self.sum[k] = self.sum[k].saturating_add(to_fixed(v));
            self.sum_sq[k] = self.sum_sq[k].saturating_add(to_fixed(v * v));
        }
        self.count += 1;
    }

    #[inline]
    pub fn add(&mut self, o: &PixelSums) {
        for k in 0..3 {
            self.sum[k] = self.sum[k].saturating_add(o.sum[k]);
            self.sum_sq[k] = self.sum_sq[k].saturating_add(o.sum_sq[k]);
        }
        self.count = self.count.saturating_add(o.count);
    }

    /// Mean per channel (zero without samples).
    pub fn mean(&self) -> [f64; 3] {
        if self.count == 0 {
            return [0.0; 3];
        }
        let n = self.count as f64;
        self.sum.map(|s| from_fixed(s) / n)
    }

    /// Variance of the mean per channel: the unbiased sample variance over n (zero for n < 2).
    pub fn variance_of_mean(&self) -> [f64; 3] {
        if self.count < 2 {
            return [0.0; 3];
        }
        let n = self.count as f64;
        let mean = self.mean();
        std::array::from_fn(|k| ((from_fixed(self.sum_sq[k]) / n - mean[k] * mean[k]) * n / (n - 1.0)).max(0.0) / n)
    }
}

/// Sums of a rectangle of pixels rendered together (a tile), to be added to a film.
#[derive(Clone, Debug)]
pub struct TileSums {
    pub rect: Rect,
    pub pixels: Vec<PixelSums>,
    /// `aov_stride` values per pixel, in the film's AOV order.
    pub aov_sums: Vec<i128>,
}

/// The image, its region and what it has accumulated; see the module doc.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    region: Rect,
    pass_spp: u32,
    spp: u32,
    aovs: Vec<Aov>,
    blocks: Vec<Block>,
    pixels: Vec<PixelSums>,
    aov_sums: Vec<i128>,
    /// Pixels that adaptive sampling has stopped.
    converged: Vec<bool>,
    filter: PixelFilter,
    /// Splat sums when `filter` splats, over the region grown by its margin.
    splat: Option<SplatBuffer>,
}

/// A film's sums, borrowed for rendering in place.
pub(crate) struct FilmSumsMut<'a> {
    pub pixels: &'a mut [PixelSums],
    pub aov_sums: &'a mut [i128],
    pub converged: &'a [bool],
    pub splat: Option<&'a mut SplatBuffer>,
}

/// Everything a film holds, for checkpoints.
pub(crate) struct FilmParts {
    pub width: u32,
    pub height: u32,
    pub region: Rect,
    pub pass_spp: u32,
    pub spp: u32,
    pub aovs: Vec<Aov>,
    pub blocks: Vec<Block>,
    pub pixels: Vec<PixelSums>,
    pub aov_sums: Vec<i128>,
    pub converged: Vec<bool>,
    pub filter: PixelFilter,
    /// Splat sums (empty unless the filter splats).
    pub splat: Vec<SplatSums>,
}

impl Film {
    /// An empty film over `region` of a `width`×`height` image. AOVs are kept in the order
    /// given, without repeats.
    pub fn new(width: u32, height: u32, region: Rect, pass_spp: u32, spp: u32, aovs: &[Aov]) -> Result<Film, String> {
        Film::with_filter(width, height, region, pass_spp, spp, aovs, PixelFilter::Box)
    }

    /// An empty film whose image is reconstructed with `filter` (splatted unless the box).
    pub fn with_filter(
        width: u32,
        height: u32,
        region: Rect,
        pass_spp: u32,
        spp: u32,
        aovs: &[Aov],
        filter: PixelFilter,
    ) -> Result<Film, String> {
        check_shape(width, height, region, pass_spp, spp, aovs)?;
        let r = filter.radius();
        if !(r > 0.0 && r <= MAX_FILTER_RADIUS) {
            return Err(format!("filter radius {r} is outside (0, {MAX_FILTER_RADIUS}]"));
        }
        let n = region.area() as usize;
        let stride: usize = aovs.iter().map(|a| a.stored_channels()).sum();
        Ok(Film {
            width,
            height,
            region,
            pass_spp,
            spp,
            aovs: aovs.to_vec(),
            blocks: Vec::new(),
            pixels: vec![PixelSums::default(); n],
            aov_sums: vec![0; n * stride],
            converged: vec![false; n],
            filter,
            splat: filter.splats().then(|| SplatBuffer::new(splat_rect(region, &filter, width, height))),
        })
    }

    pub(crate) fn from_parts(p: FilmParts) -> Result<Film, String> {
        let mut film = Film::with_filter(p.width, p.height, p.region, p.pass_spp, p.spp, &p.aovs, p.filter)?;
        if p.pixels.len() != film.pixels.len()
            || p.aov_sums.len() != film.aov_sums.len()
            || p.converged.len() != film.converged.len()
            || p.splat.len() != film.splat.as_ref().map_or(0, |s| s.sums.len())
        {
            return Err("film sums do not match its region and AOVs".into());
        }
        for (i, b) in p.blocks.iter().enumerate() {
            film.check_block(b)?;
            if let Some(o) = p.blocks[..i].iter().find(|o| o.overlaps(b)) {
                return Err(format!("film blocks overlap: {} and {}", describe(o), describe(b)));
            }
        }
        film.blocks = p.blocks;
        film.pixels = p.pixels;
        film.aov_sums = p.aov_sums;
        film.converged = p.converged;
        if let Some(s) = &mut film.splat {
            s.sums = p.splat;
        }
        Ok(film)
    }

    pub(crate) fn parts(&self) -> FilmParts {
        FilmParts {
            width: self.width,
            height: self.height,
            region: self.region,
            pass_spp: self.pass_spp,
            spp: self.spp,
            aovs: self.aovs.clone(),
            blocks: self.blocks.clone(),
            pixels: self.pixels.clone(),
            aov_sums: self.aov_sums.clone(),
            converged: self.converged.clone(),
            filter: self.filter,
            splat: self.splat.as_ref().map_or(Vec::new(), |s| s.sums.clone()),
        }
    }

    /// The reconstruction filter (the box keeps each sample in its pixel).
    pub fn filter(&self) -> PixelFilter {
        self.filter
    }

    /// Pixels that receive splats (none for the box filter).
    pub fn splat_rect(&self) -> Option<Rect> {
        self.splat.as_ref().map(|s| s.rect)
    }

    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }
    pub fn region(&self) -> Rect {
        self.region
    }
    pub fn pass_spp(&self) -> u32 {
        self.pass_spp
    }
    pub fn spp(&self) -> u32 {
        self.spp
    }
    pub fn aovs(&self) -> &[Aov] {
        &self.aovs
    }
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// Passes in a full render: `ceil(spp / pass_spp)`.
    pub fn pass_count(&self) -> u32 {
        self.spp.div_ceil(self.pass_spp)
    }

    /// Sample indices of pass `p`.
    pub fn pass_samples(&self, p: u32) -> Range<u32> {
        let start = p.saturating_mul(self.pass_spp).min(self.spp);
        start..start.saturating_add(self.pass_spp).min(self.spp)
    }

    /// Leading passes that cover the whole region: rendering resumes from here.
    pub fn passes_done(&self) -> u32 {
        let area = self.region.area();
        (0..self.pass_count())
            .find(|&p| {
                let covered: u64 = self.blocks.iter().filter(|b| b.passes.contains(&p)).map(|b| b.region.area()).sum();
                covered != area
            })
            .unwrap_or(self.pass_count())
    }

    /// Changes the target samples per pixel (resuming to a new `--spp`). Passes already in
    /// the film must stay whole passes of the same samples under the new count.
    pub fn set_spp(&mut self, spp: u32) -> Result<(), String> {
        if spp == 0 {
            return Err("samples per pixel must be positive".into());
        }
        if spp == self.spp {
            return Ok(());
        }
        let end = self.blocks.iter().map(|b| b.passes.end).max().unwrap_or(0);
        let whole = end.saturating_mul(self.pass_spp);
        let last_partial = end > 0 && (self.pass_samples(end - 1).len() as u32) < self.pass_spp;
        if last_partial || spp < whole {
            return Err(format!(
                "the film holds passes up to {end} of {} samples each; a new count must be at least {whole} (and the old one ended on a whole pass)",
                self.pass_spp
            ));
        }
        self.spp = spp;
        Ok(())
    }

    /// The parts of the region that pass `p` still lacks, as disjoint rectangles: all of
    /// it for a pass not begun, none for a pass that is in, and for a pass that a merge of
    /// scattered blocks holds in part (a render farm's checkpoint), the row strips of the
    /// grid that the blocks' edges make, joined where they line up.
    pub fn missing(&self, p: u32) -> Vec<Rect> {
        let have: Vec<Rect> = self.blocks.iter().filter(|b| b.passes.contains(&p)).map(|b| b.region).collect();
        if have.is_empty() {
            return vec![self.region];
        }
        let cuts = |ends: &dyn Fn(&Rect) -> [u32; 2]| {
            let mut v: Vec<u32> = have.iter().chain([&self.region]).flat_map(ends).collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        let (xs, ys) = (cuts(&|r| [r.x0, r.x1]), cuts(&|r| [r.y0, r.y1]));
        let mut out: Vec<Rect> = Vec::new();
        for y in ys.windows(2) {
            let mut strip: Vec<Rect> = Vec::new();
            for x in xs.windows(2) {
                let cell = Rect { x0: x[0], y0: y[0], x1: x[1], y1: y[1] };
                if have.iter().any(|r| r.contains(&cell)) {
                    continue;
                }
                match strip.last_mut() {
                    Some(last) if last.x1 == cell.x0 => last.x1 = cell.x1,
                    _ => strip.push(cell),
                }
            }
            for r in strip {
                match out.iter_mut().find(|o| o.x0 == r.x0 && o.x1 == r.x1 && o.y1 == r.y0) {
                    Some(above) => above.y1 = r.y1,
                    None => out.push(r),
                }
            }
        }
        out
    }

    /// Every pass over every pixel of the region is in.
    pub fn is_complete(&self) -> bool {
        self.passes_done() == self.pass_count()
    }

    /// Values per pixel in the AOV sums.
    pub fn aov_stride(&self) -> usize {
        self.aovs.iter().map(|a| a.stored_channels()).sum()
    }

    /// Where `aov`'s channels start among a pixel's AOV sums, if the film stores it.
    pub fn aov_offset(&self, aov: Aov) -> Option<usize> {
        let mut off = 0;
        for &a in &self.aovs {
            if a == aov {
                return (a.stored_channels() > 0).then_some(off);
            }
            off += a.stored_channels();
        }
        None
    }

    fn index(&self, x: u32, y: u32) -> usize {
        ((y - self.region.y0) * self.region.width() + (x - self.region.x0)) as usize
    }

    /// Sums of pixel (x, y) of the image, if it is in the region.
    pub fn pixel(&self, x: u32, y: u32) -> Option<&PixelSums> {
        let inside = x >= self.region.x0 && x < self.region.x1 && y >= self.region.y0 && y < self.region.y1;
        inside.then(|| &self.pixels[self.index(x, y)])
    }

    /// Whether adaptive sampling has stopped pixel (x, y) (false outside the region).
    pub fn is_converged(&self, x: u32, y: u32) -> bool {
        self.pixel(x, y).is_some() && self.converged[self.index(x, y)]
    }

    fn check_block(&self, b: &Block) -> Result<(), String> {
        if b.region.is_empty() || !self.region.contains(&b.region) {
            return Err(format!("block {} is not inside the film's region ({})", describe(b), self.region));
        }
        if b.passes.start >= b.passes.end || b.passes.end > self.pass_count() {
            return Err(format!("block {} is outside passes 0..{}", describe(b), self.pass_count()));
        }
        Ok(())
    }

    /// Whether `b` could be added: inside the film and overlapping nothing it holds.
    pub fn check_free(&self, b: &Block) -> Result<(), String> {
        self.check_block(b)?;
        match self.blocks.iter().find(|o| o.overlaps(b)) {
            Some(o) => Err(format!("film already holds {}, which overlaps {}", describe(o), describe(b))),
            None => Ok(()),
        }
    }

    /// Adds a tile's sums (the caller records the block once the whole pass is in).
    pub fn add_tile(&mut self, tile: &TileSums) {
        assert!(self.region.contains(&tile.rect), "tile {} outside the film's region {}", tile.rect, self.region);
        let stride = self.aov_stride();
        let tw = tile.rect.width() as usize;
        for (i, sums) in tile.pixels.iter().enumerate() {
            let (x, y) = (tile.rect.x0 + (i % tw) as u32, tile.rect.y0 + (i / tw) as u32);
            let j = self.index(x, y);
            self.pixels[j].add(sums);
            for c in 0..stride {
                self.aov_sums[j * stride + c] =
                    self.aov_sums[j * stride + c].saturating_add(tile.aov_sums[i * stride + c]);
            }
        }
    }

    /// Records that `b`'s samples are in.
    pub fn record_block(&mut self, b: Block) -> Result<(), String> {
        self.check_free(&b)?;
        self.blocks.push(b);
        self.coalesce_blocks();
        Ok(())
    }

    /// Marks pixel `i` of the region (row-major) converged.
    pub(crate) fn set_converged(&mut self, i: usize) {
        self.converged[i] = true;
    }

    /// The region's sums, row-major, the adaptive flags and the splat sums, for rendering
    /// in place.
    pub(crate) fn sums_mut(&mut self) -> FilmSumsMut<'_> {
        FilmSumsMut {
            pixels: &mut self.pixels,
            aov_sums: &mut self.aov_sums,
            converged: &self.converged,
            splat: self.splat.as_mut(),
        }
    }

    pub(crate) fn region_sums(&self) -> &[PixelSums] {
        &self.pixels
    }

    pub(crate) fn converged_flags(&self) -> &[bool] {
        &self.converged
    }

    /// Joins consecutive pass ranges over the same region, and same-pass regions that share
    /// a whole edge, then sorts: the list stays short and does not depend on merge order.
    fn coalesce_blocks(&mut self) {
        let mut changed = true;
        while changed {
            changed = false;
            'search: for i in 0..self.blocks.len() {
                for j in 0..self.blocks.len() {
                    if i == j {
                        continue;
                    }
                    if let Some(joined) = join(&self.blocks[i], &self.blocks[j]) {
                        self.blocks[i] = joined;
                        self.blocks.swap_remove(j);
                        changed = true;
                        break 'search;
                    }
                }
            }
        }
        self.blocks.sort_by_key(|b| (b.passes.start, b.passes.end, b.region.y0, b.region.x0, b.region.y1, b.region.x1));
    }

    /// Adds another film's samples. Both must describe the same render (size, pass size,
    /// spp, AOVs) and hold no common block; the region grows to the bounding box of both.
    pub fn merge(&mut self, other: &Film) -> Result<(), String> {
        let same = |what: &str, a: String, b: String| {
            if a == b {
                Ok(())
            } else {
                Err(format!("cannot merge films with different {what}: {a} and {b}"))
            }
        };
        same("image sizes", format!("{}x{}", self.width, self.height), format!("{}x{}", other.width, other.height))?;
        same("samples per pass", self.pass_spp.to_string(), other.pass_spp.to_string())?;
        same("samples per pixel", self.spp.to_string(), other.spp.to_string())?;
        let names = |f: &Film| f.aovs.iter().map(|a| a.name()).collect::<Vec<_>>().join(",");
        same("AOVs", format!("[{}]", names(self)), format!("[{}]", names(other)))?;
        same("filters", format!("{:?}", self.filter), format!("{:?}", other.filter))?;
        for b in &other.blocks {
            if let Some(o) = self.blocks.iter().find(|o| o.overlaps(b)) {
                return Err(format!("cannot merge films: both hold samples of {} and {}", describe(o), describe(b)));
            }
        }
        let region = self.region.bounding(&other.region);
        if region != self.region {
            let mut grown =
                Film::with_filter(self.width, self.height, region, self.pass_spp, self.spp, &self.aovs, self.filter)?;
            grown.add_film_sums(self);
            grown.blocks = std::mem::take(&mut self.blocks);
            *self = grown;
        }
        self.add_film_sums(other);
        self.blocks.extend(other.blocks.iter().cloned());
        self.coalesce_blocks();
        Ok(())
    }

    fn add_film_sums(&mut self, other: &Film) {
        let tile = TileSums { rect: other.region, pixels: other.pixels.clone(), aov_sums: other.aov_sums.clone() };
        self.add_tile(&tile);
        if let (Some(mine), Some(theirs)) = (&mut self.splat, &other.splat) {
            mine.add(theirs);
        }
        let w = other.region.width() as usize;
        for (i, &c) in other.converged.iter().enumerate() {
            if c {
                let j = self.index(other.region.x0 + (i % w) as u32, other.region.y0 + (i / w) as u32);
                self.converged[j] = true;
            }
        }
    }

    /// Visits every pixel of the full image: `f(x, y, sums, aov sums)` for those in the region.
    fn for_each_pixel(&self, mut f: impl FnMut(usize, &PixelSums, &[i128])) {
        let stride = self.aov_stride();
        let w = self.region.width() as usize;
        for (i, sums) in self.pixels.iter().enumerate() {
            let (x, y) = (self.region.x0 as usize + i % w, self.region.y0 as usize + i / w);
            f(y * self.width as usize + x, sums, &self.aov_sums[i * stride..(i + 1) * stride]);
        }
    }

    /// The mean of each pixel (with a splatting filter, its weighted mean over the splats it
    /// received); black outside the region and where nothing was sampled.
    pub fn image(&self) -> Image {
        let mut img = Image::new(self.width as usize, self.height as usize);
        let w = self.width as usize;
        self.for_each_pixel(|j, s, _| {
            let m = match &self.splat {
                Some(splat) => splat.get((j % w) as u32, (j / w) as u32).map_or([0.0; 3], |p| p.value()),
                None => s.mean(),
            };
            img.pixels[j] = Rgb { r: m[0] as f32, g: m[1] as f32, b: m[2] as f32 };
        });
        img
    }

    /// The variance of each pixel's mean, as an image.
    pub fn variance_image(&self) -> Image {
        let mut img = Image::new(self.width as usize, self.height as usize);
        self.for_each_pixel(|j, s, _| {
            let v = s.variance_of_mean();
            img.pixels[j] = Rgb { r: v[0] as f32, g: v[1] as f32, b: v[2] as f32 };
        });
        img
    }

    /// One layer; `None` for a stored layer this film does not keep (variance and spp are
    /// always available).
    pub fn aov(&self, aov: Aov) -> Option<AovImage> {
        let channels = aov.channels();
        let nc = channels.len();
        let mut data = vec![0.0f32; self.width as usize * self.height as usize * nc];
        match aov {
            Aov::Variance => self.for_each_pixel(|j, s, _| {
                for (c, v) in s.variance_of_mean().into_iter().enumerate() {
                    data[j * nc + c] = v as f32;
                }
            }),
            Aov::Spp => self.for_each_pixel(|j, s, _| data[j] = s.count as f32),
            _ => {
                let off = self.aov_offset(aov)?;
                self.for_each_pixel(|j, s, sums| {
                    if s.count > 0 {
                        for c in 0..nc {
                            data[j * nc + c] = (from_fixed(sums[off + c]) / s.count as f64) as f32;
                        }
                    }
                });
            }
        }
        Some(AovImage {
            name: aov.name().to_string(),
            channels,
            width: self.width as usize,
            height: self.height as usize,
            data,
        })
    }
}

fn check_shape(width: u32, height: u32, region: Rect, pass_spp: u32, spp: u32, aovs: &[Aov]) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("empty image ({width}x{height})"));
    }
    if region.is_empty() || !Rect::full(width, height).contains(&region) {
        return Err(format!("film region ({region}) is empty or outside the {width}x{height} image"));
    }
    if pass_spp == 0 || spp == 0 {
        return Err(format!("samples per pass ({pass_spp}) and per pixel ({spp}) must be positive"));
    }
    for (i, a) in aovs.iter().enumerate() {
        if aovs[..i].contains(a) {
            return Err(format!("AOV '{a}' listed twice"));
        }
    }
    Ok(())
}

fn describe(b: &Block) -> String {
    format!("pixels {} passes {}..{}", b.region, b.passes.start, b.passes.end)
}

/// The union of two blocks when it is itself a block.
fn join(a: &Block, b: &Block) -> Option<Block> {
    if a.region == b.region && a.passes.end == b.passes.start {
        return Some(Block { region: a.region, passes: a.passes.start..b.passes.end });
    }
    if a.passes != b.passes {
        return None;
    }
    let (r, s) = (a.region, b.region);
    let side_by_side = r.y0 == s.y0 && r.y1 == s.y1 && r.x1 == s.x0;
    let stacked = r.x0 == s.x0 && r.x1 == s.x1 && r.y1 == s.y0;
    (side_by_side || stacked).then(|| Block { region: r.bounding(&s), passes: a.passes.clone() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn to_fixed_rounds_as_f64_round_does() {
        let scaled = |x: f64| x / FIXED_SCALE;
        let mut values = vec![0.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MAX, f64::MIN_POSITIVE];
        for x in [0.5, 1.5, 2.5, 0.49999999999999994, 4_503_599_627_370_495.5, 4_503_599_627_370_496.0, 1e30, 3.0] {
            values.extend([scaled(x), scaled(-x), scaled(x.next_up()), scaled(x.next_down())]);
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..100_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            values.push(f64::from_bits(state));
            values.push((state >> 11) as f64 / (1u64 << 53) as f64 * 1e3 - 500.0);
        }
        for v in values {
            assert_eq!(to_fixed(v), (v * FIXED_SCALE).round() as i128, "{v:e}");
        }
    }

    fn film(region: Rect) -> Film {
        Film::new(8, 6, region, 2, 7, &[Aov::Albedo, Aov::Spp]).unwrap()
    }

    fn filled(region: Rect, passes: Range<u32>, value: f32) -> Film {
        let mut f = film(region);
        let n = region.area() as usize;
        let mut sums = PixelSums::default();
        sums.add_sample(Rgb::splat(value));
        let tile = TileSums { rect: region, pixels: vec![sums; n], aov_sums: vec![to_fixed(0.5); n * 3] };
        f.add_tile(&tile);
        f.record_block(Block { region, passes }).unwrap();
        f
    }

    #[test]
    fn passes_cover_spp_with_a_short_last_pass() {
        let f = film(Rect::full(8, 6));
        assert_eq!(f.pass_count(), 4);
        assert_eq!(f.pass_samples(0), 0..2);
        assert_eq!(f.pass_samples(3), 6..7);
    }

    #[test]
    fn fixed_point_saturates_and_maps_nan_to_zero() {
        assert_eq!(to_fixed(f64::NAN), 0);
        assert_eq!(to_fixed(f64::INFINITY), i128::MAX);
        assert_eq!(to_fixed(1.0), 1 << 40);
        let mut s = PixelSums { sum: [i128::MAX; 3], ..Default::default() };
        s.add_sample(Rgb::splat(1.0));
        assert_eq!(s.sum[0], i128::MAX);
    }

    #[test]
    fn merge_refuses_overlapping_blocks() {
        let mut a = filled(Rect { x0: 0, y0: 0, x1: 4, y1: 6 }, 0..2, 1.0);
        let b = filled(Rect { x0: 3, y0: 0, x1: 8, y1: 6 }, 1..3, 1.0);
        let err = a.merge(&b).unwrap_err();
        assert!(err.contains("both hold samples"), "{err}");
        // Same pixels, disjoint passes: fine. Disjoint pixels, same passes: fine.
        a.merge(&filled(Rect { x0: 0, y0: 0, x1: 4, y1: 6 }, 2..4, 1.0)).unwrap();
        a.merge(&filled(Rect { x0: 4, y0: 0, x1: 8, y1: 6 }, 0..4, 1.0)).unwrap();
        assert_eq!(a.region(), Rect::full(8, 6));
        assert!(a.is_complete());
        assert_eq!(a.blocks(), [Block { region: Rect::full(8, 6), passes: 0..4 }]);
        assert_eq!(a.pixel(1, 1).unwrap().count, 2);
        assert_eq!(a.pixel(5, 1).unwrap().count, 1);
        assert_eq!(a.aov(Aov::Albedo).unwrap().data[0], 0.5);
    }

    #[test]
    fn merge_refuses_mismatched_films() {
        let mut a = film(Rect::full(8, 6));
        let other_spp = Film::new(8, 6, Rect::full(8, 6), 2, 8, &[Aov::Albedo, Aov::Spp]).unwrap();
        assert!(a.merge(&other_spp).unwrap_err().contains("samples per pixel"));
        let other_aovs = Film::new(8, 6, Rect::full(8, 6), 2, 7, &[Aov::Depth]).unwrap();
        assert!(a.merge(&other_aovs).unwrap_err().contains("AOVs"));
        let other_size = Film::new(8, 7, Rect::full(8, 6), 2, 7, &[Aov::Albedo, Aov::Spp]).unwrap();
        assert!(a.merge(&other_size).unwrap_err().contains("image sizes"));
        let other_pass = Film::new(8, 6, Rect::full(8, 6), 3, 7, &[Aov::Albedo, Aov::Spp]).unwrap();
        assert!(a.merge(&other_pass).unwrap_err().contains("per pass"));
    }

    #[test]
    fn partial_coverage_is_not_done_and_outside_pixels_are_black() {
        let mut a = filled(Rect { x0: 0, y0: 0, x1: 4, y1: 3 }, 0..1, 2.0);
        a.merge(&filled(Rect { x0: 4, y0: 3, x1: 8, y1: 6 }, 0..1, 2.0)).unwrap();
        assert_eq!(a.region(), Rect::full(8, 6));
        assert_eq!(a.passes_done(), 0);
        let img = a.image();
        assert_eq!(img.get(0, 0), Rgb::splat(2.0));
        assert_eq!(img.get(7, 0), Rgb::BLACK);
        assert!(a.record_block(Block { region: Rect::full(8, 6), passes: 0..1 }).is_err());
    }

    #[test]
    fn missing_is_what_a_pass_lacks() {
        let corner = Rect { x0: 0, y0: 0, x1: 4, y1: 3 };
        let mut a = filled(corner, 0..2, 1.0);
        assert_eq!(a.missing(2), [corner]);
        assert!(a.missing(1).is_empty());
        a.merge(&filled(Rect { x0: 4, y0: 3, x1: 8, y1: 6 }, 0..1, 1.0)).unwrap();
        // The merged film covers the whole image; nothing has pass 2 yet.
        assert_eq!(a.missing(2), [Rect::full(8, 6)]);
        // Pass 0 lacks the other two quadrants, pass 1 three of them.
        assert_eq!(a.missing(0), [Rect { x0: 4, y0: 0, x1: 8, y1: 3 }, Rect { x0: 0, y0: 3, x1: 4, y1: 6 }]);
        assert_eq!(a.missing(1), [Rect { x0: 4, y0: 0, x1: 8, y1: 3 }, Rect { x0: 0, y0: 3, x1: 8, y1: 6 }]);
        // Filling in what is missing completes the pass, with no overlap.
        for r in a.missing(0) {
            a.merge(&filled(r, 0..1, 1.0)).unwrap();
        }
        assert!(a.missing(0).is_empty());
        assert_eq!(a.passes_done(), 1);
    }

    #[test]
    fn new_refuses_bad_shapes() {
        assert!(Film::new(8, 6, Rect { x0: 0, y0: 0, x1: 9, y1: 6 }, 1, 1, &[]).is_err());
        assert!(Film::new(8, 6, Rect::full(8, 6), 0, 1, &[]).is_err());
        assert!(Film::new(8, 6, Rect::full(8, 6), 1, 1, &[Aov::Depth, Aov::Depth]).is_err());
    }
}
