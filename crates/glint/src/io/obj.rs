//! Wavefront OBJ (and MTL) reader. Written here rather than taken from a crate so that every
//! error names the file and line: a truncated face, an index out of range, a bad number.
//! Polygons are fan-triangulated; `v/vt/vn` triples become unique vertices; faces are
//! grouped by `usemtl` so that each group can get its own material.

use crate::math::{Rgb, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Default)]
pub struct ObjGroup {
    /// Name from `usemtl` (empty when none).
    pub material: String,
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<[u32; 3]>,
}

/// The subset of MTL that glint maps to its materials.
#[derive(Clone, Debug, Default)]
pub struct MtlMaterial {
    pub name: String,
    pub kd: Rgb,
    pub ks: Rgb,
    pub ns: f32,
    pub ke: Rgb,
    pub ni: f32,
    pub illum: u32,
    pub dissolve: f32,
}

#[derive(Clone, Debug, Default)]
pub struct ObjFile {
    pub groups: Vec<ObjGroup>,
    pub materials: Vec<MtlMaterial>,
}

fn err(path: &Path, line: usize, msg: impl std::fmt::Display) -> String {
    format!("{}:{}: {}", path.display(), line, msg)
}

fn parse_floats<const N: usize>(path: &Path, line: usize, parts: &[&str], what: &str) -> Result<[f32; N], String> {
    if parts.len() < N {
        return Err(err(path, line, format!("'{what}' needs {N} numbers, found {}", parts.len())));
    }
    let mut out = [0.0f32; N];
    for i in 0..N {
        out[i] = parts[i].parse::<f32>().map_err(|_| err(path, line, format!("'{}' is not a number", parts[i])))?;
        if !out[i].is_finite() {
            return Err(err(path, line, format!("'{}' is not a finite number", parts[i])));
        }
    }
    Ok(out)
}

/// The statements of an OBJ or MTL file: (line number, keyword, arguments), comments and
/// blank lines skipped.
fn statements(text: &str) -> impl Iterator<Item = (usize, &str, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, raw)| {
        let l = raw.split('#').next().unwrap_or("").trim();
        let mut it = l.split_whitespace();
        let key = it.next()?;
        Some((i + 1, key, it.collect()))
    })
}

pub fn read_obj(path: &Path) -> Result<ObjFile, String> {
    let data = super::read_file_bounded(path, super::MAX_MESH_FILE_BYTES)?;
    parse_obj_bytes(&data, path)
}

/// Parses an OBJ file held in memory; `path` names it in errors and locates its `mtllib`s.
pub fn parse_obj_bytes(data: &[u8], path: &Path) -> Result<ObjFile, String> {
    let text = std::str::from_utf8(data).map_err(|e| {
        let line = 1 + data[..e.valid_up_to()].iter().filter(|&&c| c == b'\n').count();
        err(path, line, "not UTF-8 text")
    })?;
    parse_obj(text, path)
}

pub fn parse_obj(text: &str, path: &Path) -> Result<ObjFile, String> {
    let mut positions: Vec<Vec3> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut groups: Vec<ObjGroup> = Vec::new();
    let mut group_index: HashMap<String, usize> = HashMap::new();
    let mut maps: Vec<HashMap<(u32, u32, u32), u32>> = Vec::new();
    let mut current = usize::MAX;
    let mut materials = Vec::new();
    let mut any_normals = false;
    let mut any_uvs = false;
    // Per-group vertex attributes collected as Option so mixed faces can be detected.
    let mut group_has_missing_normal: Vec<bool> = Vec::new();
    let mut group_has_missing_uv: Vec<bool> = Vec::new();
    let mut gn: Vec<Vec<Vec3>> = Vec::new();
    let mut gt: Vec<Vec<[f32; 2]>> = Vec::new();

    for (line, key, rest) in statements(text) {
        match key {
            "v" => positions.push(Vec3::from_array(parse_floats::<3>(path, line, &rest, "v")?)),
            "vn" => normals.push(Vec3::from_array(parse_floats::<3>(path, line, &rest, "vn")?)),
            "vt" => {
                let t = if rest.len() == 1 {
                    [parse_floats::<1>(path, line, &rest, "vt")?[0], 0.0]
                } else {
                    parse_floats::<2>(path, line, &rest, "vt")?
                };
                // Images are looked up top-down (row 0 first); OBJ's v points up.
                uvs.push([t[0], 1.0 - t[1]]);
            }
            "usemtl" => {
                let name = rest.join(" ");
                current = *group_index.entry(name.clone()).or_insert_with(|| {
                    groups.push(ObjGroup { material: name.clone(), ..Default::default() });
                    maps.push(HashMap::new());
                    group_has_missing_normal.push(false);
                    group_has_missing_uv.push(false);
                    gn.push(Vec::new());
                    gt.push(Vec::new());
                    groups.len() - 1
                });
            }
            "mtllib" => {
                for name in &rest {
                    materials.extend(read_mtl(&mtl_path(path, name)).map_err(|e| err(path, line, e))?);
                }
            }
            "f" => {
                if rest.len() < 3 {
                    return Err(err(path, line, format!("a face needs at least 3 vertices, found {}", rest.len())));
                }
                if current == usize::MAX {
                    current = *group_index.entry(String::new()).or_insert_with(|| {
                        groups.push(ObjGroup::default());
                        maps.push(HashMap::new());
                        group_has_missing_normal.push(false);
                        group_has_missing_uv.push(false);
                        gn.push(Vec::new());
                        gt.push(Vec::new());
                        groups.len() - 1
                    });
                }
                let mut corner = Vec::with_capacity(rest.len());
                for token in &rest {
                    let mut fields = token.split('/');
                    let resolve = |s: Option<&str>, count: usize, what: &str| -> Result<u32, String> {
                        match s {
                            None | Some("") => Ok(u32::MAX),
                            Some(s) => {
                                let i: i64 =
                                    s.parse().map_err(|_| err(path, line, format!("bad {what} index '{s}'")))?;
                                let idx = if i > 0 { i - 1 } else { count as i64 + i };
                                if i == 0 || idx < 0 || idx >= count as i64 {
                                    return Err(err(
                                        path,
                                        line,
                                        format!("{what} index {i} is out of range (there are {count} so far)"),
                                    ));
                                }
                                Ok(idx as u32)
                            }
                        }
                    };
                    let vi = resolve(fields.next(), positions.len(), "vertex")?;
                    if vi == u32::MAX {
                        return Err(err(path, line, format!("face vertex '{token}' has no position index")));
                    }
                    let ti = resolve(fields.next(), uvs.len(), "texture coordinate")?;
                    let ni = resolve(fields.next(), normals.len(), "normal")?;
                    let g = &mut groups[current];
                    let map = &mut maps[current];
                    let id = *map.entry((vi, ti, ni)).or_insert_with(|| {
                        g.positions.push(positions[vi as usize]);
                        if ni != u32::MAX {
                            gn[current].push(normals[ni as usize]);
                            any_normals = true;
                        } else {
                            gn[current].push(Vec3::ZERO);
                            group_has_missing_normal[current] = true;
                        }
                        if ti != u32::MAX {
                            gt[current].push(uvs[ti as usize]);
                            any_uvs = true;
                        } else {
                            gt[current].push([0.0, 0.0]);
                            group_has_missing_uv[current] = true;
                        }
                        (g.positions.len() - 1) as u32
                    });
                    corner.push(id);
                }
                for k in 1..corner.len() - 1 {
                    groups[current].indices.push([corner[0], corner[k], corner[k + 1]]);
                }
            }
            // Object names, groups, smoothing groups, lines and points carry nothing glint uses.
            "o" | "g" | "s" | "l" | "p" | "vp" => {}
            _ => {} // Unknown statements are ignored, as most OBJ readers do.
        }
    }
    for (i, g) in groups.iter_mut().enumerate() {
        if any_normals && !group_has_missing_normal[i] {
            g.normals = Some(std::mem::take(&mut gn[i]));
        }
        if any_uvs && !group_has_missing_uv[i] {
            g.uvs = Some(std::mem::take(&mut gt[i]));
        }
    }
    groups.retain(|g| !g.indices.is_empty());
    if groups.is_empty() {
        return Err(format!("{}: no faces", path.display()));
    }
    Ok(ObjFile { groups, materials })
}

/// Where an `mtllib` name of the OBJ file `obj` points: beside it.
fn mtl_path(obj: &Path, name: &str) -> PathBuf {
    obj.parent().unwrap_or(Path::new(".")).join(name)
}

/// The material files that the `mtllib` lines of an OBJ file held in memory name, each once:
/// what reading the OBJ at `path` reads besides it (a render farm ships them with it). Text
/// that is not UTF-8 names none (reading it fails anyway).
pub fn mtllib_files(data: &[u8], path: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = Vec::new();
    let Ok(text) = std::str::from_utf8(data) else { return out };
    for (_, key, rest) in statements(text) {
        if key == "mtllib" {
            for name in rest {
                let p = mtl_path(path, name);
                if !out.contains(&p) {
                    out.push(p);
                }
            }
        }
    }
    out
}

pub fn read_mtl(path: &Path) -> Result<Vec<MtlMaterial>, String> {
    // Bounded: an `mtllib` line may name anything, /dev/zero included.
    let data = super::read_file_bounded(path, super::MAX_MESH_FILE_BYTES)?;
    let text = std::str::from_utf8(&data).map_err(|_| format!("{}: not UTF-8 text", path.display()))?;
    let mut out: Vec<MtlMaterial> = Vec::new();
    for (line, key, rest) in statements(text) {
        if key == "newmtl" {
            out.push(MtlMaterial { name: rest.join(" "), ni: 1.5, dissolve: 1.0, ..Default::default() });
            continue;
        }
        let Some(m) = out.last_mut() else {
            if matches!(key, "Kd" | "Ks" | "Ke" | "Ns" | "Ni" | "illum" | "d") {
                return Err(err(path, line, format!("'{key}' before any 'newmtl'")));
            }
            continue;
        };
        match key {
            "Kd" => m.kd = Rgb::from_array(parse_floats::<3>(path, line, &rest, key)?),
            "Ks" => m.ks = Rgb::from_array(parse_floats::<3>(path, line, &rest, key)?),
            "Ke" => m.ke = Rgb::from_array(parse_floats::<3>(path, line, &rest, key)?),
            "Ns" => m.ns = parse_floats::<1>(path, line, &rest, key)?[0],
            "Ni" => m.ni = parse_floats::<1>(path, line, &rest, key)?[0],
            "d" => m.dissolve = parse_floats::<1>(path, line, &rest, key)?[0],
            "illum" => {
                m.illum = rest
                    .first()
                    .and_then(|s| s.parse().ok())
                    .ok_or_else(|| err(path, line, "'illum' needs an integer"))?
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_are_triangulated_and_negative_indices_resolve() {
        let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n";
        let f = parse_obj(obj, Path::new("q.obj")).unwrap();
        assert_eq!(f.groups[0].indices, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn errors_name_file_and_line() {
        let e = parse_obj("v 0 0 0\nv 1 0 0\nf 1 2 3\n", Path::new("m.obj")).unwrap_err();
        assert!(e.starts_with("m.obj:3:"), "{e}");
        assert!(e.contains("out of range"), "{e}");
        let e = parse_obj("v 0 0\n", Path::new("m.obj")).unwrap_err();
        assert!(e.starts_with("m.obj:1:"), "{e}");
        let e = parse_obj("v 0 0 zero\n", Path::new("m.obj")).unwrap_err();
        assert!(e.contains("not a number"), "{e}");
    }

    #[test]
    fn mtllib_files_are_the_ones_the_reader_opens() {
        let obj = "mtllib a.mtl  b.mtl # comment\nv 0 0 0\nmtllib a.mtl\n# mtllib c.mtl\n";
        let files = mtllib_files(obj.as_bytes(), Path::new("models/m.obj"));
        assert_eq!(files, [PathBuf::from("models/a.mtl"), PathBuf::from("models/b.mtl")]);
        let e = parse_obj(obj, Path::new("models/m.obj")).unwrap_err();
        assert!(e.contains("models/a.mtl"), "{e}");
        assert!(mtllib_files(b"mtllib \xff.mtl", Path::new("m.obj")).is_empty());
    }

    #[test]
    fn materials_split_groups() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\n";
        let f = parse_obj(obj, Path::new("g.obj")).unwrap();
        assert_eq!(f.groups.len(), 2);
        assert_eq!(f.groups[1].material, "b");
    }
}
