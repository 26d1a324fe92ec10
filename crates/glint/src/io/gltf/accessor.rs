//! Accessors: typed views of buffer bytes (every component type, `normalized`, strides and
//! sparse substitution), each checked against the bytes there are before it is read.

use super::{GltfFile, Node};

/// An accessor's elements as floats: `count` elements of `comps` components.
#[derive(Clone, Debug, PartialEq)]
pub struct Accessor {
    pub count: usize,
    pub comps: usize,
    pub values: Vec<f32>,
}

impl Accessor {
    /// Element `i` (its `comps` components).
    pub fn get(&self, i: usize) -> &[f32] {
        &self.values[i * self.comps..(i + 1) * self.comps]
    }
}

/// The most elements an accessor without a bufferView (zeros, perhaps with sparse values)
/// may have times its components: nothing bounds it by the file's size.
const MAX_UNBACKED_COMPONENTS: usize = 1 << 24;

fn type_comps(t: &str) -> Option<usize> {
    Some(match t {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

fn component_size(ct: u64) -> Option<usize> {
    Some(match ct {
        5120 | 5121 => 1,
        5122 | 5123 => 2,
        5125 | 5126 => 4,
        _ => return None,
    })
}

/// One component at the start of `b` as a float; integer components are divided to
/// [0, 1] or [-1, 1] when `normalized` (the specification's formulas).
fn component(b: &[u8], ct: u64, normalized: bool) -> f32 {
    match ct {
        5120 => {
            let v = b[0] as i8 as f32;
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        5121 => {
            let v = b[0] as f32;
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        5122 => {
            let v = i16::from_le_bytes([b[0], b[1]]) as f32;
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        5123 => {
            let v = u16::from_le_bytes([b[0], b[1]]) as f32;
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
        5125 => {
            let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64;
            (if normalized { v / u32::MAX as f64 } else { v }) as f32
        }
        _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

fn unsigned(b: &[u8], ct: u64) -> u32 {
    match ct {
        5121 => b[0] as u32,
        5123 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// The bytes a bufferView spans, checked against its buffer.
fn view_bytes<'a>(f: &'a GltfFile, view: usize, path: &str) -> Result<(&'a [u8], Option<usize>), String> {
    let v = f.item("bufferViews", view, path)?;
    let vp = format!("bufferViews[{view}]");
    let n = Node::new(v, &vp);
    let buffer = n.required_index("buffer")?;
    let data = f.buffers.get(buffer).ok_or_else(|| format!("{vp}.buffer: buffers[{buffer}] does not exist"))?;
    let offset = n.index("byteOffset")?.unwrap_or(0);
    let length = n.required_index("byteLength")?;
    let end = offset.checked_add(length).filter(|&e| e <= data.len()).ok_or_else(|| {
        format!(
            "{path}: bufferView {view} reads past the end of buffer {buffer} ({offset} + {length} > {} bytes)",
            data.len()
        )
    })?;
    let stride = n.index("byteStride")?;
    Ok((&data[offset..end], stride))
}

struct Layout {
    count: usize,
    comps: usize,
    ct: u64,
    normalized: bool,
}

fn layout(n: &Node) -> Result<Layout, String> {
    let count = n.required_index("count")?;
    let t = n.string("type")?.ok_or_else(|| format!("{}.type: missing", n.path))?;
    let comps = type_comps(t).ok_or_else(|| format!("{}.type: unknown accessor type '{t}'", n.path))?;
    let ct = n.required_index("componentType")? as u64;
    component_size(ct).ok_or_else(|| format!("{}.componentType: unknown component type {ct}", n.path))?;
    let normalized = n.get("normalized").and_then(|v| v.as_bool()).unwrap_or(false);
    Ok(Layout { count, comps, ct, normalized })
}

/// Calls `each(i, bytes)` for the `count` elements of `elem` bytes at `offset` in a view
/// with `stride`, after checking that they all lie inside it.
fn elements<'a>(
    view: &'a [u8],
    offset: usize,
    stride: usize,
    elem: usize,
    count: usize,
    what: &dyn Fn() -> String,
) -> Result<impl Iterator<Item = &'a [u8]> + 'a, String> {
    if count > 0 {
        let last =
            (count - 1).checked_mul(stride).and_then(|x| x.checked_add(offset)).and_then(|x| x.checked_add(elem));
        if last.is_none_or(|e| e > view.len()) {
            return Err(what());
        }
    }
    Ok((0..count).map(move |i| &view[offset + i * stride..offset + i * stride + elem]))
}

/// Reads accessor `index` as floats; `path` is the JSON path that refers to it (for errors).
pub fn read_accessor(f: &GltfFile, index: usize, path: &str) -> Result<Accessor, String> {
    let a = f.item("accessors", index, path)?;
    let ap = format!("accessors[{index}]");
    let n = Node::new(a, &ap);
    let l = layout(&n)?;
    let size = component_size(l.ct).unwrap_or(4);
    let elem = size * l.comps;
    let mut values;
    match n.index("bufferView")? {
        Some(view) => {
            let (bytes, stride) = view_bytes(f, view, path)?;
            let stride = stride.unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "{path}: accessor {index}'s byteStride {stride} is less than its element size {elem}"
                ));
            }
            let offset = n.index("byteOffset")?.unwrap_or(0);
            let buffer = f.array("bufferViews")[view].get("buffer").and_then(|b| b.as_u64()).unwrap_or(0);
            let what = || format!("{path}: accessor {index} reads past the end of buffer {buffer} (bufferView {view})");
            let it = elements(bytes, offset, stride, elem, l.count, &what)?;
            values = Vec::with_capacity(l.count * l.comps);
            for e in it {
                for c in 0..l.comps {
                    values.push(component(&e[c * size..], l.ct, l.normalized));
                }
            }
        }
        None => {
            if l.count.checked_mul(l.comps).is_none_or(|c| c > MAX_UNBACKED_COMPONENTS) {
                return Err(format!(
                    "{path}: accessor {index} has no bufferView and {} elements (at most {} components)",
                    l.count, MAX_UNBACKED_COMPONENTS
                ));
            }
            values = vec![0.0; l.count * l.comps];
        }
    }
    if let Some(sparse) = n.get("sparse") {
        apply_sparse(f, Node::new(sparse, &format!("{ap}.sparse")), &l, &mut values, path)?;
    }
    Ok(Accessor { count: l.count, comps: l.comps, values })
}

fn apply_sparse(f: &GltfFile, s: Node, l: &Layout, values: &mut [f32], path: &str) -> Result<(), String> {
    let sp = s.path.to_string();
    let count = s.required_index("count")?;
    if count > l.count {
        return Err(format!("{sp}.count: {count} substitutions in an accessor of {} elements", l.count));
    }
    let ip = format!("{sp}.indices");
    let idx = Node::new(s.get("indices").ok_or_else(|| format!("{ip}: missing"))?, &ip);
    let ict = idx.required_index("componentType")? as u64;
    if !matches!(ict, 5121 | 5123 | 5125) {
        return Err(format!("{ip}.componentType: {ict} is not an unsigned integer type"));
    }
    let isize = component_size(ict).unwrap_or(4);
    let (ibytes, _) = view_bytes(f, idx.required_index("bufferView")?, path)?;
    let what = || format!("{path}: {ip} reads past the end of its bufferView");
    let indices: Vec<usize> = elements(ibytes, idx.index("byteOffset")?.unwrap_or(0), isize, isize, count, &what)?
        .map(|b| unsigned(b, ict) as usize)
        .collect();
    let vp = format!("{sp}.values");
    let val = Node::new(s.get("values").ok_or_else(|| format!("{vp}: missing"))?, &vp);
    let size = component_size(l.ct).unwrap_or(4);
    let elem = size * l.comps;
    let (vbytes, _) = view_bytes(f, val.required_index("bufferView")?, path)?;
    let what = || format!("{path}: {vp} reads past the end of its bufferView");
    let it = elements(vbytes, val.index("byteOffset")?.unwrap_or(0), elem, elem, count, &what)?;
    for (&i, e) in indices.iter().zip(it) {
        if i >= l.count {
            return Err(format!("{path}: {ip}: index {i} is past the accessor's {} elements", l.count));
        }
        for c in 0..l.comps {
            values[i * l.comps + c] = component(&e[c * size..], l.ct, l.normalized);
        }
    }
    Ok(())
}

/// Reads accessor `index` as vertex indices (an unsigned integer scalar accessor).
pub fn read_indices(f: &GltfFile, index: usize, path: &str) -> Result<Vec<u32>, String> {
    let a = f.item("accessors", index, path)?;
    let ap = format!("accessors[{index}]");
    let l = layout(&Node::new(a, &ap))?;
    if l.comps != 1 || !matches!(l.ct, 5121 | 5123 | 5125) {
        return Err(format!("{path}: accessor {index} is not a scalar of unsigned integers"));
    }
    if a.get("sparse").is_some() || a.get("bufferView").is_none() {
        // Rare for indices; read through the float path, exact below 2^24.
        let acc = read_accessor(f, index, path)?;
        return Ok(acc.values.iter().map(|&v| v as u32).collect());
    }
    let n = Node::new(a, &ap);
    let view = n.required_index("bufferView")?;
    let (bytes, stride) = view_bytes(f, view, path)?;
    let size = component_size(l.ct).unwrap_or(4);
    let buffer = f.array("bufferViews")[view].get("buffer").and_then(|b| b.as_u64()).unwrap_or(0);
    let what = || format!("{path}: accessor {index} reads past the end of buffer {buffer} (bufferView {view})");
    let it =
        elements(bytes, n.index("byteOffset")?.unwrap_or(0), stride.unwrap_or(size).max(size), size, l.count, &what)?;
    Ok(it.map(|b| unsigned(b, l.ct)).collect())
}
