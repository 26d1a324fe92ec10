//! Where `glint bench` and `glint rays` get their triangles: a mesh file (every group of an
//! OBJ, or a PLY, flattened into one triangle soup, as Embree sees it) or a generated mesh
//! of a chosen size (`synthetic:N`) for the scaling curve.

use glint::io::{obj, ply};
use glint::math::{vec3, Vec3};
use std::path::Path;

pub struct FlatMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

/// Sizes `synthetic:N` accepts. The upper bound (about 2 GB of vertices and indices) keeps
/// a typo from exhausting memory (sizes below 8 make the smallest sphere the grid can).
pub const SYNTHETIC_TRIANGLES: std::ops::RangeInclusive<usize> = 1..=100_000_000;

pub fn load(spec: &str) -> Result<FlatMesh, String> {
    if let Some(n) = spec.strip_prefix("synthetic:") {
        let (lo, hi) = (SYNTHETIC_TRIANGLES.start(), SYNTHETIC_TRIANGLES.end());
        let range_err = || format!("'{spec}': the triangle count must be a whole number from {lo} to {hi}");
        let n: usize = n.parse().map_err(|_| range_err())?;
        if !SYNTHETIC_TRIANGLES.contains(&n) {
            return Err(range_err());
        }
        return Ok(synthetic(n));
    }
    let path = Path::new(spec);
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let mut out = FlatMesh { positions: Vec::new(), indices: Vec::new() };
    match ext.as_str() {
        "obj" => {
            for g in obj::read_obj(path)?.groups {
                let base = out.positions.len() as u32;
                out.positions.extend(g.positions);
                out.indices.extend(g.indices.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
            }
        }
        "ply" => {
            let m = ply::read_ply(path)?;
            out.positions = m.positions;
            out.indices = m.indices;
        }
        _ => return Err(format!("{spec}: expected an .obj or .ply file, or synthetic:N")),
    }
    if out.indices.is_empty() {
        return Err(format!("{spec}: no triangles"));
    }
    Ok(out)
}

/// A bumpy sphere of about `n` triangles (a latitude-longitude grid with a deterministic
/// displacement), so that larger meshes have the same shape at finer detail, like a scan.
pub fn synthetic(n: usize) -> FlatMesh {
    let n = n.max(8);
    // rows * cols * 2 = n, cols = 2 rows.
    let rows = ((n as f64 / 4.0).sqrt().round() as usize).max(2);
    let cols = (n / (2 * rows)).max(3);
    let mut positions = Vec::with_capacity((rows + 1) * cols);
    for j in 0..=rows {
        let theta = std::f32::consts::PI * j as f32 / rows as f32;
        for i in 0..cols {
            let phi = 2.0 * std::f32::consts::PI * i as f32 / cols as f32;
            let bump = 1.0 + 0.05 * (7.0 * phi).sin() * (5.0 * theta).sin() + 0.02 * (31.0 * phi + 17.0 * theta).sin();
            positions.push(vec3(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()) * bump);
        }
    }
    let mut indices = Vec::with_capacity(rows * cols * 2);
    for j in 0..rows {
        for i in 0..cols {
            let a = (j * cols + i) as u32;
            let b = (j * cols + (i + 1) % cols) as u32;
            let c = a + cols as u32;
            let d = b + cols as u32;
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    FlatMesh { positions, indices }
}

/// Writes the triangles as little-endian float32 (x, y, z) x 3 per triangle, the input of
/// the Embree harness, so both engines trace exactly the same vertices.
pub fn write_triangles(m: &FlatMesh, path: &Path) -> Result<(), String> {
    let mut bytes = Vec::with_capacity(m.indices.len() * 36);
    for t in &m.indices {
        for &v in t {
            for c in m.positions[v as usize].to_array() {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthetic_sizes_outside_the_range_are_clear_errors() {
        for spec in [
            "synthetic:99999999999",
            "synthetic:100000001",
            "synthetic:0",
            "synthetic:-5",
            "synthetic:1e9",
            "synthetic:",
        ] {
            let e = load(spec).err().unwrap_or_else(|| panic!("{spec} was accepted"));
            assert!(e.contains(spec) && e.contains("from 1 to 100000000"), "{e}");
        }
        assert!(!load("synthetic:8").unwrap().indices.is_empty());
    }
}
