//! Mesh primitives: vertex attributes and triangles (lists, strips and fans).

use super::{read_accessor, read_indices, Accessor, GltfFile, Node};
use crate::math::{vec3, Vec3};

/// What a primitive draws (its `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrimitiveMode {
    Triangles,
    Strip,
    Fan,
    /// Points and lines: nothing a path tracer can hit.
    PointsOrLines,
}

/// The `mode` of primitive `path`.
pub fn triangle_mode(p: &Node) -> Result<PrimitiveMode, String> {
    Ok(match p.index("mode")?.unwrap_or(4) {
        0..=3 => PrimitiveMode::PointsOrLines,
        4 => PrimitiveMode::Triangles,
        5 => PrimitiveMode::Strip,
        6 => PrimitiveMode::Fan,
        m => return Err(format!("{}.mode: unknown primitive mode {m}", p.path)),
    })
}

/// A triangle primitive's vertices and triangles, as the file stores them (object space;
/// uv (0, 0) at the image's top-left corner, as glint's textures).
#[derive(Clone, Debug, Default)]
pub struct PrimitiveData {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uv0: Option<Vec<[f32; 2]>>,
    pub uv1: Option<Vec<[f32; 2]>>,
    /// `COLOR_0` as RGBA (alpha 1 for a VEC3 accessor).
    pub colors: Option<Vec<[f32; 4]>>,
    /// `TANGENT`: xyz and the bitangent's sign w.
    pub tangents: Option<Vec<[f32; 4]>>,
    pub indices: Vec<[u32; 3]>,
}

fn attribute(
    f: &GltfFile,
    p: &Node,
    name: &str,
    comps: &[usize],
    count: Option<usize>,
) -> Result<Option<Accessor>, String> {
    let attrs = p.get("attributes").ok_or_else(|| format!("{}.attributes: missing", p.path))?;
    let Some(v) = attrs.get(name) else { return Ok(None) };
    let path = format!("{}.attributes.{name}", p.path);
    let index = v.as_u64().ok_or_else(|| format!("{path}: expected an accessor index, found {v}"))? as usize;
    let a = read_accessor(f, index, &path)?;
    if !comps.contains(&a.comps) {
        return Err(format!("{path}: accessor {index} has {} components per element (expected {comps:?})", a.comps));
    }
    if let Some(n) = count {
        if a.count != n {
            return Err(format!("{path}: accessor {index} has {} elements, POSITION has {n}", a.count));
        }
    }
    Ok(Some(a))
}

/// Reads primitive `prim` of mesh `mesh` (which must draw triangles, strips or fans).
pub fn read_primitive(f: &GltfFile, mesh: usize, prim: usize) -> Result<PrimitiveData, String> {
    let mpath = format!("meshes[{mesh}]");
    let m = f.item("meshes", mesh, &mpath)?;
    let ppath = format!("meshes[{mesh}].primitives[{prim}]");
    let pv = m
        .get("primitives")
        .and_then(|p| p.as_array())
        .and_then(|a| a.get(prim))
        .ok_or_else(|| format!("{ppath}: does not exist"))?;
    let p = Node::new(pv, &ppath);
    let mode = triangle_mode(&p)?;
    let pos =
        attribute(f, &p, "POSITION", &[3], None)?.ok_or_else(|| format!("{ppath}.attributes.POSITION: missing"))?;
    let n = pos.count;
    let v3 =
        |a: &Accessor| (0..a.count).map(|i| vec3(a.values[3 * i], a.values[3 * i + 1], a.values[3 * i + 2])).collect();
    let v2 = |a: &Accessor| (0..a.count).map(|i| [a.values[2 * i], a.values[2 * i + 1]]).collect();
    let mut out = PrimitiveData { positions: v3(&pos), ..Default::default() };
    out.normals = attribute(f, &p, "NORMAL", &[3], Some(n))?.as_ref().map(v3);
    out.uv0 = attribute(f, &p, "TEXCOORD_0", &[2], Some(n))?.as_ref().map(v2);
    out.uv1 = attribute(f, &p, "TEXCOORD_1", &[2], Some(n))?.as_ref().map(v2);
    out.colors = attribute(f, &p, "COLOR_0", &[3, 4], Some(n))?.map(|a| {
        (0..a.count)
            .map(|i| {
                let e = a.get(i);
                [e[0], e[1], e[2], if a.comps == 4 { e[3] } else { 1.0 }]
            })
            .collect()
    });
    out.tangents = attribute(f, &p, "TANGENT", &[4], Some(n))?
        .map(|a| (0..a.count).map(|i| [a.get(i)[0], a.get(i)[1], a.get(i)[2], a.get(i)[3]]).collect());
    let list: Vec<u32> = match p.index("indices")? {
        Some(i) => {
            let idx = read_indices(f, i, &format!("{ppath}.indices"))?;
            if let Some(bad) = idx.iter().find(|&&v| v as usize >= n) {
                return Err(format!("{ppath}.indices: vertex index {bad} is past the {n} vertices of POSITION"));
            }
            idx
        }
        None => {
            if n > u32::MAX as usize {
                return Err(format!("{ppath}.attributes.POSITION: too many vertices"));
            }
            (0..n as u32).collect()
        }
    };
    out.indices = assemble_triangles(&list, mode);
    Ok(out)
}

/// The triangles a list, strip or fan of vertex indices draws (the specification's order:
/// strip triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}), fan triangle i is
/// (v_{i+1}, v_{i+2}, v_0)); none for points and lines.
pub fn assemble_triangles(v: &[u32], mode: PrimitiveMode) -> Vec<[u32; 3]> {
    match mode {
        PrimitiveMode::Triangles => v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        PrimitiveMode::Strip => {
            (0..v.len().saturating_sub(2)).map(|i| [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]]).collect()
        }
        PrimitiveMode::Fan => (0..v.len().saturating_sub(2)).map(|i| [v[i + 1], v[i + 2], v[0]]).collect(),
        PrimitiveMode::PointsOrLines => Vec::new(),
    }
}
