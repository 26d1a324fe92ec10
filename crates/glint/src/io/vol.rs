//! Mitsuba's binary volume grids (`.vol`, format version 3), read by the `gridvolume`
//! texture and the `sdfgrid` shape.
//!
//! Layout (little endian): the bytes `VOL`, a `u8` version (3), an `i32` encoding (1: `f32`,
//! the only one Mitsuba 3 reads), `i32` resolutions x, y, z, an `i32` channel count, six
//! `f32` of a bounding box (min x, y, z, max x, y, z), then x·y·z·channels `f32` values with
//! x varying fastest and the channels of one cell together:
//! `data[((z * res_y + y) * res_x + x) * channels + c]`. Bytes after the data are ignored, as
//! Mitsuba reads only what the header announces.
//!
//! Every count is checked against the file's real length before anything is allocated, so a
//! truncated file or one that claims billions of cells is a one-line error naming the file.

use std::path::Path;

/// Largest `.vol` file glint reads (4 GiB).
pub const MAX_VOL_FILE_BYTES: u64 = 4 << 30;
/// Most channels a grid may have (Mitsuba's grids have 1, 3 or a few more).
pub const MAX_VOL_CHANNELS: u32 = 64;
const HEADER_BYTES: usize = 48;
const ENCODING_F32: i32 = 1;

/// A grid of `channels` values per cell, read from a `.vol` file.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeGrid {
    /// Cells along x, y and z (each at least 1).
    pub resolution: [u32; 3],
    pub channels: u32,
    /// The bounding box the file records (min, max). Mitsuba 3 places a grid by its
    /// `to_world` transform on the unit cube and does not use it.
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
    /// `resolution[0] * resolution[1] * resolution[2] * channels` values, x fastest.
    pub data: Vec<f32>,
}

impl VolumeGrid {
    /// The value of channel `c` of cell (x, y, z); the indices must be in range.
    pub fn at(&self, x: u32, y: u32, z: u32, c: u32) -> f32 {
        let [rx, ry, _] = self.resolution;
        let cell = (z as usize * ry as usize + y as usize) * rx as usize + x as usize;
        self.data[cell * self.channels as usize + c as usize]
    }

    /// The number of cells.
    pub fn cell_count(&self) -> usize {
        self.resolution.iter().map(|&r| r as usize).product()
    }
}

/// Reads a `.vol` file.
pub fn read_vol(path: &Path) -> Result<VolumeGrid, String> {
    let data = super::read_file_bounded(path, MAX_VOL_FILE_BYTES)?;
    parse_vol(&data).map_err(|e| format!("{}: {e}", path.display()))
}

fn i32_at(d: &[u8], at: usize) -> i32 {
    i32::from_le_bytes(d[at..at + 4].try_into().expect("4 bytes"))
}
fn f32_at(d: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(d[at..at + 4].try_into().expect("4 bytes"))
}

/// Parses a `.vol` file held in memory.
pub fn parse_vol(d: &[u8]) -> Result<VolumeGrid, String> {
    if d.len() < 4 || &d[..3] != b"VOL" {
        return Err("not a Mitsuba volume grid (the file does not start with 'VOL')".into());
    }
    if d[3] != 3 {
        return Err(format!("volume grid format version {} is not supported (3 is)", d[3]));
    }
    if d.len() < HEADER_BYTES {
        return Err(format!("truncated volume grid header ({} bytes, 48 needed)", d.len()));
    }
    let encoding = i32_at(d, 4);
    if encoding != ENCODING_F32 {
        return Err(format!("volume grid encoding {encoding} is not supported (1, 32-bit float, is)"));
    }
    let mut resolution = [0u32; 3];
    for (axis, r) in resolution.iter_mut().enumerate() {
        let v = i32_at(d, 8 + 4 * axis);
        if v < 1 {
            return Err(format!("volume grid resolution {v} along {} must be at least 1", ["x", "y", "z"][axis]));
        }
        *r = v as u32;
    }
    let channels = i32_at(d, 20);
    if channels < 1 || channels as u32 > MAX_VOL_CHANNELS {
        return Err(format!("volume grid has {channels} channels (1 to {MAX_VOL_CHANNELS} are read)"));
    }
    let channels = channels as u32;
    let bbox: Vec<f32> = (0..6).map(|i| f32_at(d, 24 + 4 * i)).collect();
    let values = resolution.iter().try_fold(channels as u64, |n, &r| n.checked_mul(r as u64));
    let needed = values.and_then(|v| v.checked_mul(4)).and_then(|b| b.checked_add(HEADER_BYTES as u64));
    let available = d.len() as u64;
    match needed {
        Some(n) if n <= available => {}
        _ => {
            let [x, y, z] = resolution;
            return Err(format!(
                "truncated volume grid: {x}x{y}x{z} cells of {channels} channels need more than the {} bytes of data in the file",
                available - HEADER_BYTES as u64
            ));
        }
    }
    let count = values.expect("checked above") as usize;
    let data = d[HEADER_BYTES..HEADER_BYTES + 4 * count]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
        .collect();
    Ok(VolumeGrid {
        resolution,
        channels,
        bbox_min: [bbox[0], bbox[1], bbox[2]],
        bbox_max: [bbox[3], bbox[4], bbox[5]],
        data,
    })
}

/// Encodes a grid as a `.vol` file (format version 3, `f32`): what the tests and the scripts
/// that write test scenes use.
pub fn encode_vol(grid: &VolumeGrid) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_BYTES + 4 * grid.data.len());
    out.extend_from_slice(b"VOL");
    out.push(3);
    out.extend_from_slice(&ENCODING_F32.to_le_bytes());
    for r in grid.resolution {
        out.extend_from_slice(&(r as i32).to_le_bytes());
    }
    out.extend_from_slice(&(grid.channels as i32).to_le_bytes());
    for v in grid.bbox_min.iter().chain(&grid.bbox_max).chain(&grid.data) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_grid() -> VolumeGrid {
        let resolution = [3, 2, 2];
        let channels = 3;
        let data = (0..3 * 2 * 2 * 3).map(|i| i as f32 * 0.5).collect();
        VolumeGrid { resolution, channels, bbox_min: [0.0; 3], bbox_max: [1.0; 3], data }
    }

    #[test]
    fn a_grid_survives_encoding_and_indexes_x_fastest() {
        let grid = sample_grid();
        let read = parse_vol(&encode_vol(&grid)).unwrap();
        assert_eq!(read, grid);
        // Cell (x=2, y=1, z=1) is cell (1*2+1)*3+2 = 11; its channel 1 is value 34.
        assert_eq!(read.at(2, 1, 1, 1), 34.0 * 0.5);
        assert_eq!(read.cell_count(), 12);
    }

    #[test]
    fn every_truncation_is_an_error_and_trailing_bytes_are_ignored() {
        let bytes = encode_vol(&sample_grid());
        for len in 0..bytes.len() {
            assert!(parse_vol(&bytes[..len]).is_err(), "length {len} accepted");
        }
        let mut longer = bytes.clone();
        longer.extend_from_slice(&[1, 2, 3]);
        assert_eq!(parse_vol(&longer).unwrap(), sample_grid());
    }

    #[test]
    fn lying_headers_are_refused_before_allocating() {
        let mut bytes = encode_vol(&sample_grid());
        bytes[8..12].copy_from_slice(&i32::MAX.to_le_bytes());
        bytes[12..16].copy_from_slice(&i32::MAX.to_le_bytes());
        bytes[16..20].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(parse_vol(&bytes).unwrap_err().contains("truncated"));
        let mut bytes = encode_vol(&sample_grid());
        bytes[16..20].copy_from_slice(&0i32.to_le_bytes());
        assert!(parse_vol(&bytes).unwrap_err().contains("at least 1"));
        let mut bytes = encode_vol(&sample_grid());
        bytes[4..8].copy_from_slice(&2i32.to_le_bytes());
        assert!(parse_vol(&bytes).unwrap_err().contains("encoding 2"));
        let mut bytes = encode_vol(&sample_grid());
        bytes[20..24].copy_from_slice(&(-3i32).to_le_bytes());
        assert!(parse_vol(&bytes).unwrap_err().contains("channels"));
        assert!(parse_vol(b"VOX\x03").unwrap_err().contains("VOL"));
    }
}
