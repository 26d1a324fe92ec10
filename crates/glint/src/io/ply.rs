//! PLY reader (ASCII, binary little- and big-endian): vertex positions, optional normals
//! and texture coordinates, and faces as lists (fan-triangulated). Errors name the file and,
//! for the header and ASCII bodies, the line.

use super::ply_attributes::{attribute_layout, AttributeReader};
use crate::geometry::{AttributeScope, MeshAttribute};
use crate::math::Vec3;
use std::path::Path;

/// Most entries one element may declare: vertex and face numbers are `u32`. Counts are
/// further bounded by the bytes left in the file before anything is allocated.
pub const MAX_ELEMENT_COUNT: usize = u32::MAX as usize;

#[derive(Clone, Debug, Default)]
pub struct PlyMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex and per-face attributes, named as Mitsuba names them (`vertex_color`, ...);
    /// a face attribute has one value per triangle (a polygon's value repeated).
    pub attributes: Vec<MeshAttribute>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    ty: Scalar,
    /// Some(count type) for list properties.
    list: Option<Scalar>,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
    format: Format,
    /// ASCII tokens of the body with their line numbers.
    tokens: Vec<(&'a str, usize)>,
    tok: usize,
}

impl Reader<'_> {
    /// Items the body still holds, in the units that [`Reader::min_len`] measures: tokens
    /// for ASCII, bytes for binary.
    fn remaining(&self) -> usize {
        match self.format {
            Format::Ascii => self.tokens.len() - self.tok,
            _ => self.data.len() - self.pos,
        }
    }

    /// The least room one value of `ty` takes in the body.
    fn min_len(&self, ty: Scalar) -> usize {
        match self.format {
            Format::Ascii => 1,
            _ => ty.size(),
        }
    }

    /// Reads a list length and checks that the body can hold that many values of `ty`,
    /// so that a corrupt length can neither allocate nor loop beyond the file.
    fn read_count(&mut self, ct: Scalar, ty: Scalar, path: &Path) -> Result<usize, String> {
        let v = self.read(ct, path)?;
        // Negative, fractional and NaN lengths are all rejected by this one test.
        if !(v >= 0.0 && v.fract() == 0.0) {
            return Err(format!("{}: list length {v} is not a count", path.display()));
        }
        let n = v as usize;
        if n.saturating_mul(self.min_len(ty)) > self.remaining() {
            return Err(format!(
                "{}: list of {n} values is longer than the rest of the file (truncated or corrupt)",
                path.display()
            ));
        }
        Ok(n)
    }

    fn read(&mut self, ty: Scalar, path: &Path) -> Result<f64, String> {
        match self.format {
            Format::Ascii => {
                let Some(&(t, line)) = self.tokens.get(self.tok) else {
                    return Err(format!("{}: file ends early (truncated body)", path.display()));
                };
                self.tok += 1;
                t.parse::<f64>().map_err(|_| format!("{}:{}: '{}' is not a number", path.display(), line, t))
            }
            _ => {
                let n = ty.size();
                if self.pos + n > self.data.len() {
                    return Err(format!("{}: file ends early (truncated binary body)", path.display()));
                }
                let b = &self.data[self.pos..self.pos + n];
                self.pos += n;
                let le = self.format == Format::BinaryLe;
                macro_rules! get {
                    ($t:ty) => {{
                        let arr: [u8; std::mem::size_of::<$t>()] = b.try_into().unwrap();
                        if le {
                            <$t>::from_le_bytes(arr) as f64
                        } else {
                            <$t>::from_be_bytes(arr) as f64
                        }
                    }};
                }
                Ok(match ty {
                    Scalar::I8 => b[0] as i8 as f64,
                    Scalar::U8 => b[0] as f64,
                    Scalar::I16 => get!(i16),
                    Scalar::U16 => get!(u16),
                    Scalar::I32 => get!(i32),
                    Scalar::U32 => get!(u32),
                    Scalar::F32 => get!(f32),
                    Scalar::F64 => get!(f64),
                })
            }
        }
    }
}

/// Stands in for list properties among an element's property names: never an attribute.
const LIST: &str = "\0list";

fn prop_names(el: &Element) -> Vec<&str> {
    el.props.iter().map(|pr| if pr.list.is_some() { LIST } else { pr.name.as_str() }).collect()
}

pub fn read_ply(path: &Path) -> Result<PlyMesh, String> {
    let data = super::read_file_bounded(path, super::MAX_MESH_FILE_BYTES)?;
    parse_ply(&data, path)
}

/// A PLY header: the body's format, its elements in order, where the body starts and the
/// header's last line number (ASCII body lines count on from it).
struct Header {
    format: Format,
    elements: Vec<Element>,
    body_start: usize,
    line_no: usize,
}

/// Parses a PLY file held in memory; `path` only names it in errors.
pub fn parse_ply(data: &[u8], path: &Path) -> Result<PlyMesh, String> {
    let p = path.display();
    let Header { format, elements, body_start, line_no } = parse_header(data, path)?;
    let body = &data[body_start..];
    let tokens = if format == Format::Ascii {
        let text = std::str::from_utf8(body).map_err(|_| format!("{p}: ASCII body is not text"))?;
        text.lines().enumerate().flat_map(|(i, l)| l.split_whitespace().map(move |t| (t, line_no + 1 + i))).collect()
    } else {
        Vec::new()
    };
    let mut r = Reader { data: body, pos: 0, format, tokens, tok: 0 };

    let mut mesh = PlyMesh::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for el in &elements {
        // An element of no properties takes no room, whatever its count claims.
        if el.props.is_empty() {
            continue;
        }
        // Each entry takes at least one value per property: a count that the rest of the
        // file cannot hold is corrupt, and is refused before it drives any loop or allocation.
        let min_entry: usize = el.props.iter().map(|pr| r.min_len(pr.list.unwrap_or(pr.ty))).sum();
        if el.count.saturating_mul(min_entry) > r.remaining() {
            return Err(format!(
                "{p}: element '{}' claims {} entries, more than the rest of the file can hold (truncated or corrupt)",
                el.name, el.count
            ));
        }
        match el.name.as_str() {
            "vertex" => read_vertices(el, &mut r, path, &mut mesh, &mut normals, &mut uvs)?,
            "face" => read_faces(el, &mut r, path, &mut mesh)?,
            _ => skip_element(el, &mut r, path)?,
        }
    }
    if mesh.indices.is_empty() {
        return Err(format!("{p}: no faces"));
    }
    if !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    if !uvs.is_empty() {
        mesh.uvs = Some(uvs);
    }
    Ok(mesh)
}

/// Reads the header: lines up to "end_header".
fn parse_header(data: &[u8], path: &Path) -> Result<Header, String> {
    let p = path.display();
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut first = true;
    loop {
        let end = data[pos..]
            .iter()
            .position(|&c| c == b'\n')
            .ok_or_else(|| format!("{p}: header has no 'end_header' (truncated or not a PLY file)"))?;
        let line = String::from_utf8_lossy(&data[pos..pos + end]).trim().to_string();
        pos += end + 1;
        line_no += 1;
        if first {
            if line != "ply" {
                return Err(format!("{p}:1: not a PLY file (first line is not 'ply')"));
            }
            first = false;
            continue;
        }
        let parts: Vec<&str> = line.split_whitespace().collect();
        match parts.first().copied() {
            Some("format") => {
                format = Some(match parts.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::BinaryLe,
                    Some("binary_big_endian") => Format::BinaryBe,
                    other => return Err(format!("{p}:{line_no}: unknown PLY format {:?}", other.unwrap_or(""))),
                })
            }
            Some("element") => elements.push(element_line(&parts, path, line_no)?),
            Some("property") => {
                let el = elements.last_mut().ok_or_else(|| format!("{p}:{line_no}: property before any element"))?;
                el.props.push(property_line(&parts, path, line_no)?);
            }
            Some("end_header") => break,
            Some("comment") | Some("obj_info") | None => {}
            Some(other) => return Err(format!("{p}:{line_no}: unexpected header keyword '{other}'")),
        }
    }
    let format = format.ok_or_else(|| format!("{p}: header has no 'format' line"))?;
    Ok(Header { format, elements, body_start: pos, line_no })
}

/// `element NAME COUNT`, the count bounded by [`MAX_ELEMENT_COUNT`].
fn element_line(parts: &[&str], path: &Path, line_no: usize) -> Result<Element, String> {
    let p = path.display();
    let (Some(name), Some(count)) = (parts.get(1), parts.get(2).and_then(|c| c.parse::<usize>().ok())) else {
        return Err(format!("{p}:{line_no}: malformed element line (the count must be a whole number)"));
    };
    if count > MAX_ELEMENT_COUNT {
        return Err(format!(
            "{p}:{line_no}: element '{name}' has {count} entries, more than the {MAX_ELEMENT_COUNT} allowed"
        ));
    }
    Ok(Element { name: name.to_string(), count, props: Vec::new() })
}

/// `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME`.
fn property_line(parts: &[&str], path: &Path, line_no: usize) -> Result<Property, String> {
    let bad = || format!("{}:{line_no}: malformed property line", path.display());
    if parts.get(1) == Some(&"list") {
        let ct = parts.get(2).and_then(|s| Scalar::parse(s)).ok_or_else(bad)?;
        let ty = parts.get(3).and_then(|s| Scalar::parse(s)).ok_or_else(bad)?;
        let name = parts.get(4).ok_or_else(bad)?;
        Ok(Property { name: name.to_string(), ty, list: Some(ct) })
    } else {
        let ty = parts.get(1).and_then(|s| Scalar::parse(s)).ok_or_else(bad)?;
        let name = parts.get(2).ok_or_else(bad)?;
        Ok(Property { name: name.to_string(), ty, list: None })
    }
}

/// Skips one list property's values.
fn skip_list(r: &mut Reader, ct: Scalar, ty: Scalar, path: &Path) -> Result<(), String> {
    let n = r.read_count(ct, ty, path)?;
    for _ in 0..n {
        r.read(ty, path)?;
    }
    Ok(())
}

/// The vertex element: positions, normals and texture coordinates where declared, the other
/// scalar properties as `vertex_` attributes.
fn read_vertices(
    el: &Element,
    r: &mut Reader,
    path: &Path,
    mesh: &mut PlyMesh,
    normals: &mut Vec<Vec3>,
    uvs: &mut Vec<[f32; 2]>,
) -> Result<(), String> {
    let idx = |n: &[&str]| el.props.iter().position(|pr| n.contains(&pr.name.as_str()));
    let (x, y, z) = (idx(&["x"]), idx(&["y"]), idx(&["z"]));
    let (Some(x), Some(y), Some(z)) = (x, y, z) else {
        return Err(format!("{}: vertex element lacks x, y or z", path.display()));
    };
    let (nx, ny, nz) = (idx(&["nx"]), idx(&["ny"]), idx(&["nz"]));
    let (u, v) = (idx(&["u", "s", "texture_u", "texture_s"]), idx(&["v", "t", "texture_v", "texture_t"]));
    let mut reserved = vec!["x", "y", "z", "nx", "ny", "nz", LIST];
    for k in [u, v].into_iter().flatten() {
        reserved.push(el.props[k].name.as_str());
    }
    let mut attrs =
        AttributeReader::new(attribute_layout(&prop_names(el), &reserved, "vertex_"), AttributeScope::Vertex);
    let mut attr_vals = vec![0.0f32; el.props.len()];
    let mut vals = vec![0.0f64; el.props.len()];
    for _ in 0..el.count {
        for (k, pr) in el.props.iter().enumerate() {
            if let Some(ct) = pr.list {
                skip_list(r, ct, pr.ty, path)?;
            } else {
                vals[k] = r.read(pr.ty, path)?;
                attr_vals[k] = vals[k] as f32;
            }
        }
        attrs.push(&attr_vals, 1);
        mesh.positions.push(Vec3 { x: vals[x] as f32, y: vals[y] as f32, z: vals[z] as f32 });
        if let (Some(a), Some(b), Some(c)) = (nx, ny, nz) {
            normals.push(Vec3 { x: vals[a] as f32, y: vals[b] as f32, z: vals[c] as f32 });
        }
        if let (Some(a), Some(b)) = (u, v) {
            // Images are looked up top-down; PLY's v points up.
            uvs.push([vals[a] as f32, 1.0 - vals[b] as f32]);
        }
    }
    mesh.attributes.extend(attrs.finish());
    Ok(())
}

/// The face element: `vertex_indices` fan-triangulated, the other scalar properties as
/// `face_` attributes (a polygon's value repeated for each of its triangles).
fn read_faces(el: &Element, r: &mut Reader, path: &Path, mesh: &mut PlyMesh) -> Result<(), String> {
    let p = path.display();
    let list = el
        .props
        .iter()
        .position(|pr| pr.list.is_some() && (pr.name == "vertex_indices" || pr.name == "vertex_index"))
        .ok_or_else(|| format!("{p}: face element has no vertex_indices list"))?;
    let mut attrs = AttributeReader::new(attribute_layout(&prop_names(el), &[LIST], "face_"), AttributeScope::Face);
    let mut attr_vals = vec![0.0f32; el.props.len()];
    for f in 0..el.count {
        let triangles_before = mesh.indices.len();
        for (k, pr) in el.props.iter().enumerate() {
            match pr.list {
                Some(ct) if k == list => read_polygon(r, ct, pr.ty, path, f, mesh)?,
                Some(ct) => skip_list(r, ct, pr.ty, path)?,
                None => attr_vals[k] = r.read(pr.ty, path)? as f32,
            }
        }
        attrs.push(&attr_vals, mesh.indices.len() - triangles_before);
    }
    mesh.attributes.extend(attrs.finish());
    Ok(())
}

/// One face's vertex list, checked against the vertices read so far and fan-triangulated.
fn read_polygon(
    r: &mut Reader,
    ct: Scalar,
    ty: Scalar,
    path: &Path,
    f: usize,
    mesh: &mut PlyMesh,
) -> Result<(), String> {
    let p = path.display();
    let n = r.read_count(ct, ty, path)?;
    let mut ids = Vec::with_capacity(n);
    for _ in 0..n {
        ids.push(r.read(ty, path)?);
    }
    if n < 3 {
        return Err(format!("{p}: face {f} has {n} vertices (needs 3 or more)"));
    }
    let nv = mesh.positions.len();
    for &i in &ids {
        // Also rejects NaN and fractional indices.
        if !(i >= 0.0 && i.fract() == 0.0 && i < nv as f64) {
            return Err(format!("{p}: face {f} uses vertex {i} but there are {nv} vertices"));
        }
    }
    for t in 1..n - 1 {
        mesh.indices.push([ids[0] as u32, ids[t] as u32, ids[t + 1] as u32]);
    }
    Ok(())
}

/// An element glint does not use: its values are read past.
fn skip_element(el: &Element, r: &mut Reader, path: &Path) -> Result<(), String> {
    for _ in 0..el.count {
        for pr in &el.props {
            match pr.list {
                Some(ct) => skip_list(r, ct, pr.ty, path)?,
                None => {
                    r.read(pr.ty, path)?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad() {
        let m = parse_ply(ASCII.as_bytes(), Path::new("a.ply")).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn binary_matches_ascii() {
        let mut data = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in v {
                data.extend_from_slice(&c.to_le_bytes());
            }
        }
        data.push(3);
        for i in [0u32, 1, 2] {
            data.extend_from_slice(&i.to_le_bytes());
        }
        let m = parse_ply(&data, Path::new("b.ply")).unwrap();
        assert_eq!(m.positions[1].x, 1.0);
        assert_eq!(m.indices, vec![[0, 1, 2]]);
        // Truncated: drop the last index.
        let e = parse_ply(&data[..data.len() - 2], Path::new("b.ply")).unwrap_err();
        assert!(e.contains("b.ply") && e.contains("truncated"), "{e}");
    }

    #[test]
    fn colours_become_mitsubas_attributes() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nproperty uchar r\nproperty uchar g\nproperty uchar b\nend_header\n0 0 0 0.1 0.2 128 0 255\n1 0 0 0.3 0.4 10 20 30\n0 1 0 0.5 0.6 1 2 3\n3 0 1 2 128 64 255\n";
        let m = parse_ply(text.as_bytes(), Path::new("c.ply")).unwrap();
        let get = |n: &str| m.attributes.iter().find(|a| a.name == n).unwrap();
        // As Mitsuba 3.9.1 stores them (read back with mi.traverse): integers unscaled.
        assert_eq!(get("vertex_color").values, vec![128.0, 0.0, 255.0, 10.0, 20.0, 30.0, 1.0, 2.0, 3.0]);
        assert_eq!(get("face_color").values, vec![128.0, 64.0, 255.0]);
        assert_eq!(get("face_color").scope, AttributeScope::Face);
        // A quad's face attribute covers both its triangles.
        let quad = ASCII
            .replace(
                "property list uchar int vertex_indices",
                "property list uchar int vertex_indices\nproperty float w_x",
            )
            .replace("4 0 1 2 3", "4 0 1 2 3 0.5");
        let m = parse_ply(quad.as_bytes(), Path::new("q.ply")).unwrap();
        assert_eq!(m.attributes[0].name, "face_w");
        assert_eq!(m.attributes[0].values, vec![0.5, 0.5]);
    }

    #[test]
    fn out_of_range_index_is_reported() {
        let bad = ASCII.replace("4 0 1 2 3", "3 0 1 9");
        let e = parse_ply(bad.as_bytes(), Path::new("a.ply")).unwrap_err();
        assert!(e.contains("vertex 9"), "{e}");
    }
}
