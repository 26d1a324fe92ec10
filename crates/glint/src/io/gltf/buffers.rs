//! A glTF file's buffers: the `.glb` container, `data:` URIs and external files.

use serde_json::Value;
use std::path::{Path, PathBuf};

const GLB_JSON: u32 = 0x4E4F_534A;
const GLB_BIN: u32 = 0x004E_4942;

fn u32_at(data: &[u8], at: usize) -> Option<u32> {
    data.get(at..at.checked_add(4)?).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// A `.glb`'s JSON chunk and its binary chunk (if any).
pub fn split_glb(data: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let version = u32_at(data, 4).ok_or("GLB header: truncated")?;
    if version != 2 {
        return Err(format!("GLB header: container version {version} (glint reads version 2)"));
    }
    let length = u32_at(data, 8).ok_or("GLB header: truncated")? as usize;
    if length > data.len() {
        return Err(format!("GLB header: length {length} is more than the file's {} bytes", data.len()));
    }
    let data = &data[..length];
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    while at < data.len() {
        let (Some(len), Some(kind)) = (u32_at(data, at), u32_at(data, at + 4)) else {
            return Err(format!("GLB chunk at byte {at}: truncated header"));
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= data.len())
            .ok_or_else(|| format!("GLB chunk at byte {at}: length {len} runs past the end of the file"))?;
        match kind {
            GLB_JSON if json.is_none() => json = Some(&data[start..end]),
            GLB_BIN if bin.is_none() && json.is_some() => bin = Some(&data[start..end]),
            // Unknown chunks are skipped, as the specification asks.
            _ => {}
        }
        at = end.div_ceil(4) * 4;
    }
    let json = json.ok_or("GLB: no JSON chunk")?;
    Ok((json, bin))
}

/// The file a relative URI names, beside `gltf`; `None` for `data:` and absolute URIs.
pub fn uri_path(gltf: &Path, uri: &str) -> Option<PathBuf> {
    if uri.starts_with("data:") || uri.contains("://") {
        return None;
    }
    let decoded = percent_decode(uri);
    let dir = gltf.parent().unwrap_or(Path::new(""));
    Some(dir.join(decoded))
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The bytes of a `data:` URI (base64 only, as glTF writes them).
pub fn data_uri(uri: &str, path: &str) -> Result<Vec<u8>, String> {
    let comma = uri.find(',').ok_or_else(|| format!("{path}: data URI without a comma"))?;
    if !uri[..comma].ends_with(";base64") {
        return Err(format!("{path}: data URI is not base64"));
    }
    base64(&uri[comma + 1..]).ok_or_else(|| format!("{path}: invalid base64 in data URI"))
}

fn base64(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in s.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Every buffer's bytes, each checked against its declared `byteLength`.
pub fn load_buffers(path: &Path, json: &Value, bin: Option<&[u8]>, external: bool) -> Result<Vec<Vec<u8>>, String> {
    let list = json.get("buffers").and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[]);
    let mut out = Vec::with_capacity(list.len());
    for (i, b) in list.iter().enumerate() {
        let p = format!("buffers[{i}]");
        let node = super::Node::new(b, &p);
        let declared = node.required_index("byteLength")?;
        let bytes = match node.string("uri")? {
            None if i == 0 => bin.ok_or_else(|| format!("{p}: no uri and the file has no GLB binary chunk"))?.to_vec(),
            None => return Err(format!("{p}: no uri (only the first buffer of a .glb may omit it)")),
            Some(uri) if uri.starts_with("data:") => data_uri(uri, &format!("{p}.uri"))?,
            Some(uri) => {
                let file = uri_path(path, uri).ok_or_else(|| format!("{p}.uri: cannot read '{uri}' (not a file)"))?;
                if !external {
                    return Err(format!("{p}.uri: external buffers are not read here"));
                }
                super::super::read_file_bounded(&file, super::MAX_GLTF_BYTES).map_err(|e| format!("{p}.uri: {e}"))?
            }
        };
        if bytes.len() < declared {
            return Err(format!("{p}: byteLength is {declared} but the data has {} bytes", bytes.len()));
        }
        out.push(bytes);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64("aGVsbG8").unwrap(), b"hello");
        assert_eq!(base64("AAECAw==").unwrap(), [0, 1, 2, 3]);
        assert!(base64("a$b").is_none());
    }

    #[test]
    fn glb_chunks_are_bounded() {
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(40u32.to_le_bytes());
        glb.extend(100u32.to_le_bytes()); // a JSON chunk claiming more bytes than there are
        glb.extend(GLB_JSON.to_le_bytes());
        glb.extend(b"{}      ");
        glb.resize(40, b' ');
        let e = split_glb(&glb).unwrap_err();
        assert!(e.contains("runs past the end"), "{e}");
    }

    #[test]
    fn uris_are_percent_decoded_beside_the_file() {
        assert_eq!(uri_path(Path::new("a/b.gltf"), "my%20tex.png"), Some(PathBuf::from("a/my tex.png")));
        assert_eq!(uri_path(Path::new("a/b.gltf"), "data:x"), None);
    }
}
