//! Mitsuba's `.serialized` meshes (file format versions 3 and 4, which Mitsuba 0.x and 3
//! write): a sequence of zlib-compressed meshes, each after a 4-byte header, and a dictionary
//! of their offsets at the end of the file.
//!
//! Layout (little endian): `u16` 0x041C, `u16` version; then, compressed, a `u32` of flags
//! (0x0001 normals, 0x0002 texture coordinates, 0x0008 vertex colours, 0x2000 double
//! precision), in version 4 the mesh's name (NUL-terminated), `u64` vertex count V, `u64`
//! triangle count F, 3V positions, 3V normals, 2V texture coordinates, 3V colours (each when
//! flagged; `f32`, or `f64` in double precision) and 3F `u32` vertex indices. At the end of
//! the file: the offset of each mesh (`u64` in version 4, `u32` in version 3), then the `u32`
//! number of meshes.
//!
//! Every count is bounded before anything is allocated (by `u32` indices, by what deflate can
//! expand the rest of the file to, and by [`MAX_DECOMPRESSED_BYTES`]), and buffers grow only
//! with data really decompressed, so a truncated file or one that claims billions of vertices
//! is a one-line error naming the file.

use crate::math::Vec3;
use std::io::Read;
use std::path::Path;

/// The most decompressed bytes one mesh may hold (16 GiB).
pub const MAX_DECOMPRESSED_BYTES: u64 = 16 << 30;
/// The largest expansion deflate achieves (about 1032:1); a count needing more decompressed
/// bytes than this times the compressed bytes left cannot be real.
const MAX_DEFLATE_RATIO: u64 = 1100;
/// The longest mesh name read (version 4).
const MAX_NAME_BYTES: usize = 1 << 16;

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

#[derive(Clone, Debug, Default)]
pub struct SerializedMesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<[u32; 3]>,
}

/// Reads mesh `shape_index` of a `.serialized` file.
pub fn read_serialized(path: &Path, shape_index: u32) -> Result<SerializedMesh, String> {
    let data = super::read_file_bounded(path, super::MAX_MESH_FILE_BYTES)?;
    parse_serialized(&data, shape_index).map_err(|e| format!("{}: {e}", path.display()))
}

fn u16_at(d: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(d.get(at..at.checked_add(2)?)?.try_into().ok()?))
}
fn u32_at(d: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(d.get(at..at.checked_add(4)?)?.try_into().ok()?))
}
fn u64_at(d: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(d.get(at..at.checked_add(8)?)?.try_into().ok()?))
}

/// Parses mesh `shape_index` of a `.serialized` file held in memory.
pub fn parse_serialized(data: &[u8], shape_index: u32) -> Result<SerializedMesh, String> {
    let (magic, version) = match (u16_at(data, 0), u16_at(data, 2)) {
        (Some(m), Some(v)) => (m, v),
        _ => return Err("too short for a serialized mesh".into()),
    };
    if magic != MAGIC {
        return Err(format!("not a serialized mesh (format identifier {magic:#06x}, expected 0x041c)"));
    }
    if version != 3 && version != 4 {
        return Err(format!("serialized format version {version} is not supported (3 and 4 are)"));
    }
    let start = if shape_index == 0 {
        0
    } else {
        let count = data.len().checked_sub(4).and_then(|at| u32_at(data, at)).ok_or("no mesh dictionary")?;
        if shape_index >= count {
            return Err(format!("shape_index {shape_index} is out of range: the file holds {count} meshes"));
        }
        let back = count - shape_index; // entries from this one to the end of the dictionary
        let offset = if version == 4 {
            (back as usize).checked_mul(8).and_then(|b| data.len().checked_sub(4 + b)).and_then(|at| u64_at(data, at))
        } else {
            (back as usize)
                .checked_mul(4)
                .and_then(|b| data.len().checked_sub(4 + b))
                .and_then(|at| u32_at(data, at).map(u64::from))
        };
        let offset = offset.ok_or_else(|| format!("the mesh dictionary ({count} meshes) does not fit in the file"))?;
        if offset > data.len() as u64 {
            return Err(format!("mesh {shape_index} starts at byte {offset}, past the end of the file"));
        }
        offset as usize
    };
    if u16_at(data, start) != Some(MAGIC) || u16_at(data, start + 2) != Some(version) {
        return Err(format!("mesh {shape_index} (at byte {start}) has no serialized-mesh header"));
    }
    let compressed = &data[start + 4..];
    let mut z = flate2::read::ZlibDecoder::new(compressed);
    let corrupt = |what: &str, e: std::io::Error| format!("mesh {shape_index}: {what}: {e}");
    let mut word = [0u8; 8];
    z.read_exact(&mut word[..4]).map_err(|e| corrupt("reading the flags", e))?;
    let flags = u32::from_le_bytes(word[..4].try_into().unwrap());
    let mut name = Vec::new();
    if version == 4 {
        let mut b = [0u8; 1];
        loop {
            z.read_exact(&mut b).map_err(|e| corrupt("reading the name", e))?;
            if b[0] == 0 {
                break;
            }
            if name.len() >= MAX_NAME_BYTES {
                return Err(format!("mesh {shape_index}: name longer than {MAX_NAME_BYTES} bytes"));
            }
            name.push(b[0]);
        }
    }
    z.read_exact(&mut word).map_err(|e| corrupt("reading the vertex count", e))?;
    let vertices = u64::from_le_bytes(word);
    z.read_exact(&mut word).map_err(|e| corrupt("reading the triangle count", e))?;
    let triangles = u64::from_le_bytes(word);
    if vertices > u32::MAX as u64 || triangles > u32::MAX as u64 {
        return Err(format!(
            "mesh {shape_index}: {vertices} vertices and {triangles} triangles, more than the {} (u32 indices) allowed",
            u32::MAX
        ));
    }
    let scalar = if flags & DOUBLE_PRECISION != 0 { 8u64 } else { 4 };
    let lanes = 3
        + if flags & HAS_NORMALS != 0 { 3 } else { 0 }
        + if flags & HAS_TEXCOORDS != 0 { 2 } else { 0 }
        + if flags & HAS_COLORS != 0 { 3 } else { 0 };
    // At most 4e9 * 11 * 8 + 4e9 * 12 bytes: no u64 overflow.
    let vertex_bytes = vertices * lanes * scalar;
    let needed = vertex_bytes + triangles * 12;
    let bound = MAX_DECOMPRESSED_BYTES.min((compressed.len() as u64).saturating_mul(MAX_DEFLATE_RATIO));
    if needed > bound {
        return Err(format!(
            "mesh {shape_index}: {vertices} vertices and {triangles} triangles need {needed} bytes, more than the {bound} that the file can hold"
        ));
    }
    // Grows with the data as it is decompressed (never allocated from the counts alone).
    let mut body = Vec::new();
    (&mut z).take(needed).read_to_end(&mut body).map_err(|e| corrupt("decompressing", e))?;
    if (body.len() as u64) < needed {
        return Err(format!(
            "mesh {shape_index}: truncated: {vertices} vertices and {triangles} triangles need {needed} bytes, the data holds {}",
            body.len()
        ));
    }
    let (v, f) = (vertices as usize, triangles as usize);
    let mut at = 0usize;
    let mut floats = |n: usize| -> Vec<f32> {
        let out: Vec<f32> = if scalar == 8 {
            body[at..at + n * 8].chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap()) as f32).collect()
        } else {
            body[at..at + n * 4].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
        };
        at += n * scalar as usize;
        out
    };
    let vec3s = |f: Vec<f32>| f.chunks_exact(3).map(|c| Vec3 { x: c[0], y: c[1], z: c[2] }).collect::<Vec<_>>();
    let positions = vec3s(floats(3 * v));
    let normals = (flags & HAS_NORMALS != 0).then(|| vec3s(floats(3 * v)));
    let uvs = (flags & HAS_TEXCOORDS != 0).then(|| floats(2 * v).chunks_exact(2).map(|c| [c[0], c[1]]).collect());
    if flags & HAS_COLORS != 0 {
        let _ = floats(3 * v);
    }
    let mut indices = Vec::with_capacity(f);
    for (i, c) in body[at..at + 12 * f].chunks_exact(12).enumerate() {
        let t = [0, 4, 8].map(|o| u32::from_le_bytes(c[o..o + 4].try_into().unwrap()));
        if let Some(&bad) = t.iter().find(|&&x| x as u64 >= vertices) {
            return Err(format!("mesh {shape_index}: triangle {i} uses vertex {bad} of {vertices}"));
        }
        indices.push(t);
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("mesh {shape_index}: vertex {i} is not finite"));
    }
    Ok(SerializedMesh { name: String::from_utf8_lossy(&name).into_owned(), positions, normals, uvs, indices })
}

/// Vertex normals as Mitsuba computes them for a mesh that stores none (unless it is to be
/// rendered with face normals): each triangle's unit normal added to its corners, weighted
/// by the corner's angle (Thürmer and Wüthrich 1998), normalised; a vertex no valid triangle
/// touches gets (1, 0, 0), as in Mitsuba.
pub fn angle_weighted_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in indices {
        let p = t.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let len2 = n.length_squared();
        if !(len2 > 0.0) {
            continue;
        }
        let n = n * (1.0 / len2.sqrt());
        for k in 0..3 {
            let a = (p[(k + 1) % 3] - p[k]).normalize();
            let b = (p[(k + 2) % 3] - p[k]).normalize();
            let angle = a.dot(b).clamp(-1.0, 1.0).acos();
            if angle.is_finite() {
                acc[t[k] as usize] += n * angle;
            }
        }
    }
    acc.into_iter().map(|n| if n.length_squared() > 0.0 { n.normalize() } else { Vec3::X }).collect()
}
