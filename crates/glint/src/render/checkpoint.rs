//! Films on disk (checkpoints), so that a render can stop and resume, or be split across
//! machines and merged.
//!
//! Format version 2, all integers little-endian (version 1, without `filter` and splat sums,
//! is still read: its films are box-filtered):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `GLINTFLM` |
//! | 4 | format version (`u32`) |
//! | 4 | header length `H` (`u32`) |
//! | H | header, UTF-8 JSON: `width`, `height`, `region`, `pass_spp`, `spp`, `aovs` (names), `blocks`, `scene_hash`, `settings`, `filter` |
//! | … | per pixel of the region, row-major: Σf (3 × `i128`), Σf² (3 × `i128`), count (`u64`), converged (`u8`) |
//! | … | per pixel of the region: the stored AOV sums (`i128` each, in the header's AOV order) |
//! | … | when the filter splats, per pixel of the splat rectangle (the region grown by the filter's margin, inside the image), row-major: Σw·f (3 × `i128`), Σw (`i128`) |
//! | 8 | FNV-1a 64 checksum of every byte before it |
//!
//! `scene_hash` and `settings` are opaque to the film: the caller fills them (a
//! [`content_hash`] of the scene and its files, the serialised render settings) and checks
//! them when resuming. The reader checks sizes against the file length before allocating.

use super::aov::Aov;
use super::film::{Block, Film, FilmParts, PixelSums, Rect};
use super::splat::{splat_rect, SplatSums};
use crate::sampling::PixelFilter;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

const MAGIC: &[u8; 8] = b"GLINTFLM";
pub const FORMAT_VERSION: u32 = 2;
const PREFIX_BYTES: usize = 16;
const CHECKSUM_BYTES: usize = 8;
const PIXEL_BYTES: usize = 6 * 16 + 8 + 1;
const SPLAT_BYTES: usize = 4 * 16;
/// Largest header accepted: blocks are few, settings are a line of JSON.
const MAX_HEADER_BYTES: usize = 64 << 20;

/// What the caller stores beside the film.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FilmMeta {
    pub scene_hash: u64,
    pub settings: String,
}

/// FNV-1a, 64 bits: stable across Rust versions and platforms (unlike `DefaultHasher`).
#[derive(Clone, Copy, Debug)]
pub struct ContentHash(u64);

impl Default for ContentHash {
    fn default() -> Self {
        ContentHash(0xcbf2_9ce4_8422_2325)
    }
}

impl ContentHash {
    pub fn new() -> ContentHash {
        ContentHash::default()
    }
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// FNV-1a 64 of `bytes` in one call.
pub fn content_hash(bytes: &[u8]) -> u64 {
    let mut h = ContentHash::new();
    h.update(bytes);
    h.finish()
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    width: u32,
    height: u32,
    region: Rect,
    pass_spp: u32,
    spp: u32,
    aovs: Vec<Aov>,
    blocks: Vec<Block>,
    scene_hash: u64,
    settings: String,
    #[serde(default)]
    filter: PixelFilter,
}

/// The whole file as bytes.
pub fn encode_film(film: &Film, meta: &FilmMeta) -> Vec<u8> {
    let p = film.parts();
    let header = Header {
        width: p.width,
        height: p.height,
        region: p.region,
        pass_spp: p.pass_spp,
        spp: p.spp,
        aovs: p.aovs,
        blocks: p.blocks,
        scene_hash: meta.scene_hash,
        settings: meta.settings.clone(),
        filter: p.filter,
    };
    let json = serde_json::to_vec(&header).expect("the header serialises");
    let mut out =
        Vec::with_capacity(PREFIX_BYTES + json.len() + p.pixels.len() * PIXEL_BYTES + p.aov_sums.len() * 16 + 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    for (s, &c) in p.pixels.iter().zip(&p.converged) {
        for v in s.sum.iter().chain(&s.sum_sq) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&s.count.to_le_bytes());
        out.push(c as u8);
    }
    for v in &p.aov_sums {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for s in &p.splat {
        for v in s.sum.iter().chain([&s.weight]) {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    let sum = content_hash(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// Writes atomically: a temporary file in the same folder, renamed over `path` once complete.
pub fn write_film(path: &Path, film: &Film, meta: &FilmMeta) -> Result<(), String> {
    let bytes = encode_film(film, meta);
    let name = path.file_name().ok_or_else(|| format!("{}: not a file path", path.display()))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".{}.tmp", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(&bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: cannot write film: {e}", path.display())
    })
}

pub fn read_film(path: &Path) -> Result<(Film, FilmMeta), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    decode_film(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Parses a film from the bytes of a file; every size is checked against `bytes.len()`.
pub fn decode_film(bytes: &[u8]) -> Result<(Film, FilmMeta), String> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err("not a glint film (wrong magic bytes)".into());
    }
    if bytes.len() < PREFIX_BYTES + CHECKSUM_BYTES {
        return Err(format!("truncated glint film ({} bytes)", bytes.len()));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version > FORMAT_VERSION {
        return Err(format!("film format version {version} is newer than this glint reads ({FORMAT_VERSION})"));
    }
    if version == 0 {
        return Err("unsupported film format version 0".into());
    }
    let header_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    if header_len > MAX_HEADER_BYTES || PREFIX_BYTES + header_len + CHECKSUM_BYTES > bytes.len() {
        return Err(format!("truncated glint film (header of {header_len} bytes in a {}-byte file)", bytes.len()));
    }
    let checksum_ok = || {
        let (body, tail) = bytes.split_at(bytes.len() - CHECKSUM_BYTES);
        content_hash(body) == u64::from_le_bytes(tail.try_into().unwrap())
    };
    let header: Header = serde_json::from_slice(&bytes[PREFIX_BYTES..PREFIX_BYTES + header_len]).map_err(|e| {
        if checksum_ok() {
            format!("invalid film header: {e}")
        } else {
            "corrupted glint film (bad checksum)".to_string()
        }
    })?;
    let region = header.region;
    if region.x1 > header.width || region.y1 > header.height || region.is_empty() {
        return Err(format!("inconsistent film: region {region} outside the {}x{} image", header.width, header.height));
    }
    let stride: usize = header.aovs.iter().map(|a| a.stored_channels()).sum();
    // The region fits in the image (u32 sides), so these products fit in u128 and are
    // compared to the file length before anything is allocated.
    let pixels = region.area() as u128;
    let splats =
        if header.filter.splats() { splat_rect(region, &header.filter, header.width, header.height).area() } else { 0 };
    let expected = (PREFIX_BYTES + header_len + CHECKSUM_BYTES) as u128
        + pixels * (PIXEL_BYTES + 16 * stride) as u128
        + splats as u128 * SPLAT_BYTES as u128;
    if (bytes.len() as u128) < expected {
        return Err(format!("truncated glint film ({} bytes, its header needs {expected})", bytes.len()));
    }
    if (bytes.len() as u128) > expected {
        return Err(format!("inconsistent glint film ({} bytes, its header describes {expected})", bytes.len()));
    }
    if !checksum_ok() {
        return Err("corrupted glint film (bad checksum)".into());
    }
    let n = pixels as usize;
    let mut at = PREFIX_BYTES + header_len;
    let mut take = |len: usize| {
        let s = &bytes[at..at + len];
        at += len;
        s
    };
    let i128_at = |s: &[u8], k: usize| i128::from_le_bytes(s[k * 16..k * 16 + 16].try_into().unwrap());
    let mut sums = Vec::with_capacity(n);
    let mut converged = Vec::with_capacity(n);
    for _ in 0..n {
        let s = take(PIXEL_BYTES);
        sums.push(PixelSums {
            sum: [i128_at(s, 0), i128_at(s, 1), i128_at(s, 2)],
            sum_sq: [i128_at(s, 3), i128_at(s, 4), i128_at(s, 5)],
            count: u64::from_le_bytes(s[96..104].try_into().unwrap()),
        });
        converged.push(match s[104] {
            0 => false,
            1 => true,
            v => return Err(format!("invalid film: converged flag {v}")),
        });
    }
    let aov_bytes = take(n * stride * 16);
    let aov_sums = (0..n * stride).map(|k| i128_at(aov_bytes, k)).collect();
    let splat_bytes = take(splats as usize * SPLAT_BYTES);
    let splat = (0..splats as usize)
        .map(|k| SplatSums {
            sum: [i128_at(splat_bytes, 4 * k), i128_at(splat_bytes, 4 * k + 1), i128_at(splat_bytes, 4 * k + 2)],
            weight: i128_at(splat_bytes, 4 * k + 3),
        })
        .collect();
    let film = Film::from_parts(FilmParts {
        width: header.width,
        height: header.height,
        region,
        pass_spp: header.pass_spp,
        spp: header.spp,
        aovs: header.aovs,
        blocks: header.blocks,
        pixels: sums,
        aov_sums,
        converged,
        filter: header.filter,
        splat,
    })
    .map_err(|e| format!("inconsistent film: {e}"))?;
    Ok((film, FilmMeta { scene_hash: header.scene_hash, settings: header.settings }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rgb;
    use crate::render::film::{to_fixed, TileSums};

    fn sample_film() -> Film {
        let region = Rect { x0: 1, y0: 2, x1: 5, y1: 4 };
        let mut f = Film::new(6, 5, region, 4, 10, &[Aov::Depth, Aov::Variance, Aov::Normal]).unwrap();
        let pixels = (0..8)
            .map(|i| {
                let mut s = PixelSums::default();
                s.add_sample(Rgb { r: i as f32, g: 0.25, b: -1e-7 });
                s.add_sample(Rgb::splat(1e9));
                s
            })
            .collect();
        let aov_sums = (0..8 * 4).map(|k| to_fixed(k as f64 * 0.37 - 3.0)).collect();
        f.add_tile(&TileSums { rect: region, pixels, aov_sums });
        f.record_block(Block { region, passes: 0..2 }).unwrap();
        f.set_converged(3);
        f
    }

    fn meta() -> FilmMeta {
        FilmMeta { scene_hash: 0xdead_beef_0123_4567, settings: "{\"spp\":10}".into() }
    }

    #[test]
    fn round_trip_through_a_file() {
        let dir = crate::scratch::ScratchDir::new("checkpoint");
        let path = dir.join("film.glf");
        let film = sample_film();
        write_film(&path, &film, &meta()).unwrap();
        let (back, m) = read_film(&path).unwrap();
        assert_eq!(back, film);
        assert_eq!(m, meta());
        // Only the film itself is left in the folder (the temporary file was renamed).
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    }

    #[test]
    fn a_splatting_film_round_trips_and_a_missing_splat_byte_is_an_error() {
        let region = Rect { x0: 1, y0: 1, x1: 4, y1: 3 };
        let filter = PixelFilter::Gaussian { stddev: 0.5 };
        let mut f = Film::with_filter(6, 5, region, 1, 2, &[], filter).unwrap();
        let splat = f.sums_mut().splat.unwrap();
        assert_eq!(splat.rect, Rect { x0: 0, y0: 0, x1: 6, y1: 5 });
        splat.splat(&filter, 2.3, 1.7, Rgb { r: 1.0, g: 2.0, b: 3.0 });
        splat.splat(&filter, 3.9, 2.1, Rgb::splat(0.5));
        f.record_block(Block { region, passes: 0..1 }).unwrap();
        let bytes = encode_film(&f, &meta());
        let (back, _) = decode_film(&bytes).unwrap();
        assert_eq!(back, f);
        assert_eq!(back.image().pixels, f.image().pixels);
        // One splat pixel fewer than the header implies.
        let mut short = bytes[..bytes.len() - 8 - 64].to_vec();
        short.extend_from_slice(&content_hash(&short).to_le_bytes());
        assert!(decode_film(&short).unwrap_err().contains("truncated"));
    }

    #[test]
    fn every_corrupted_byte_is_an_error() {
        let bytes = encode_film(&sample_film(), &meta());
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(decode_film(&b).is_err(), "flipping byte {i} went unnoticed");
        }
        let mut b = bytes.clone();
        let last = b.len() - 100;
        b[last] ^= 1;
        assert!(decode_film(&b).unwrap_err().contains("checksum"));
    }

    #[test]
    fn truncation_version_and_magic_errors() {
        let bytes = encode_film(&sample_film(), &meta());
        for len in [0, 5, 20, 100, bytes.len() - 1] {
            let err = decode_film(&bytes[..len]).unwrap_err();
            assert!(err.contains("truncated") || err.contains("not a glint film"), "{len}: {err}");
        }
        let mut future = bytes.clone();
        future[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
        assert!(decode_film(&future).unwrap_err().contains("newer"));
        assert!(decode_film(b"P6\n1 1\n255\n....................").unwrap_err().contains("not a glint film"));
    }

    #[test]
    fn a_huge_header_in_a_small_file_is_an_error_not_an_allocation() {
        // The header is written by hand: a real film of that size would itself be huge.
        let header = r#"{"width":65536,"height":65536,"region":{"x0":0,"y0":0,"x1":65536,"y1":65536},"pass_spp":1,"spp":1,"aovs":[],"blocks":[],"scene_hash":0,"settings":""}"#;
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&1u32.to_le_bytes());
        b.extend_from_slice(&(header.len() as u32).to_le_bytes());
        b.extend_from_slice(header.as_bytes());
        b.resize(1024, 0);
        assert!(decode_film(&b).unwrap_err().contains("truncated"));
    }

    #[test]
    fn content_hash_is_fnv1a_and_incremental() {
        // Published FNV-1a 64 test vectors.
        assert_eq!(content_hash(b""), 0xcbf29ce484222325);
        assert_eq!(content_hash(b"a"), 0xaf63dc4c8601ec8c);
        let mut h = ContentHash::new();
        h.update(b"foo");
        h.update(b"bar");
        assert_eq!(h.finish(), content_hash(b"foobar"));
        assert_eq!(content_hash(b"foobar"), 0x85944171f73967e8);
    }
}
