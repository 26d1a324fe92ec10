//! Mitsuba XML as a tree of elements, each remembering its file and line, with `<include>`
//! expanded, `<default>` values collected and `$name` references substituted. Files written
//! for Mitsuba 0.x get the renames Mitsuba 3 itself applies (camelCase parameter names to
//! snake_case, `lookAt` to `lookat`, `srgb` to `rgb`).

use crate::error::{Error, SourceLoc};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The deepest element nesting read (deeper files are refused, not recursed into).
pub const MAX_DEPTH: usize = 256;
/// The most `<include>`s one scene may expand, in all (a file included by many files that
/// include each other grows without bound otherwise).
pub const MAX_INCLUDES: usize = 1000;

#[derive(Clone, Debug)]
pub struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub file: Arc<PathBuf>,
    pub line: usize,
    pub col: usize,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
    pub fn loc(&self) -> SourceLoc {
        SourceLoc::new(self.file.as_path(), self.line as u32, self.col as u32)
    }
    /// An error at this element ("file:line:col: message").
    pub fn err(&self, msg: impl std::fmt::Display) -> Error {
        Error::at(&self.loc(), msg.to_string())
    }
    pub fn required(&self, name: &str) -> Result<&str, Error> {
        self.attr(name).ok_or_else(|| self.err(format!("<{}> needs a '{name}' attribute", self.tag)))
    }
}

/// Where included files are read from: the file system, or a map of path to text (fuzzing,
/// scenes held in memory), in which a path that is not a key does not exist.
#[derive(Clone, Copy)]
pub enum IncludeSource<'a> {
    Disk,
    Memory(&'a HashMap<PathBuf, String>),
}

impl IncludeSource<'_> {
    fn exists(&self, path: &Path) -> bool {
        match self {
            IncludeSource::Disk => path.exists(),
            IncludeSource::Memory(files) => files.contains_key(path),
        }
    }

    /// Parses one file into its root element (no includes or substitution yet).
    fn parse(&self, path: &Path) -> Result<Element, Error> {
        match self {
            IncludeSource::Disk => parse_str(&crate::formats::read_text(path)?, path),
            IncludeSource::Memory(files) => match files.get(path) {
                Some(text) => parse_str(text, path),
                None => Err(Error::at(&SourceLoc::file(path), "file does not exist")),
            },
        }
    }
}

pub fn parse_str(text: &str, path: &Path) -> Result<Element, Error> {
    use quick_xml::events::Event;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file = Arc::new(path.to_path_buf());
    let line_starts: Vec<usize> = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
    let line_at = |pos: usize| line_starts.partition_point(|&s| s <= pos);
    let loc_at = |pos: usize| {
        let line = line_at(pos);
        let col = text.get(line_starts[line - 1]..pos.min(text.len())).map_or(0, |t| t.chars().count() + 1);
        SourceLoc::new(path, line as u32, col as u32)
    };
    let mut reader = quick_xml::Reader::from_str(text);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let before = reader.buffer_position() as usize;
        let ev = reader
            .read_event()
            .map_err(|e| Error::at(&loc_at(reader.error_position() as usize), format!("malformed XML: {e}")))?;
        // The event starts at the first '<' after the previous event. (Searched as bytes:
        // the reader's position need not be a char boundary, e.g. inside a second BOM.)
        let start = text.as_bytes().get(before..).and_then(|b| b.iter().position(|&c| c == b'<')).map_or(before, |o| before + o);
        let make = |e: &quick_xml::events::BytesStart| -> Result<Element, Error> {
            let tag = String::from_utf8_lossy(e.name().as_ref()).to_string();
            let mut attrs = Vec::new();
            for a in e.attributes() {
                let a = a.map_err(|err| Error::at(&loc_at(start), format!("malformed attribute: {err}")))?;
                let key = String::from_utf8_lossy(a.key.as_ref()).to_string();
                let value = a
                    .unescape_value()
                    .map_err(|err| Error::at(&loc_at(start), format!("malformed attribute: {err}")))?
                    .to_string();
                attrs.push((key, value));
            }
            let loc = loc_at(start);
            Ok(Element {
                tag,
                attrs,
                children: Vec::new(),
                file: file.clone(),
                line: loc.line as usize,
                col: loc.col as usize,
            })
        };
        match ev {
            Event::Start(e) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(Error::at(&loc_at(start), format!("elements nested more than {MAX_DEPTH} deep")));
                }
                stack.push(make(&e)?)
            }
            Event::Empty(e) => {
                let el = make(&e)?;
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::End(_) => {
                let Some(el) = stack.pop() else {
                    return Err(Error::at(&loc_at(start), "malformed XML: a closing tag without an opening one"));
                };
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::Eof => break,
            Event::Text(t) => {
                let s = String::from_utf8_lossy(t.as_ref()).to_string();
                if !s.trim().is_empty() {
                    // Reported where the text itself starts, not at the next tag.
                    let lead = s.len() - s.trim_start().len();
                    return Err(Error::at(&loc_at(before + lead), format!("unexpected text '{}'", s.trim())));
                }
            }
            _ => {}
        }
    }
    if let Some(open) = stack.first() {
        return Err(open.err(format!("malformed XML: <{}> is never closed", open.tag)));
    }
    root.ok_or_else(|| Error::at(&SourceLoc::file(path), "empty XML document"))
}

/// A scene file's tree and the files it included.
#[derive(Debug)]
pub struct SceneTree {
    pub root: Element,
    pub included: Vec<PathBuf>,
}

/// Loads a scene file: parses it, expands includes, applies version upgrades, collects
/// defaults (overridden by `defines`) and substitutes `$name` references.
pub fn load_tree(path: &Path, defines: &[(String, String)]) -> Result<SceneTree, Error> {
    load_tree_from(IncludeSource::Disk.parse(path)?, defines, IncludeSource::Disk)
}

/// [`load_tree`] for a scene given as text (`path` names it, and includes resolve next to it,
/// read from `source`).
pub fn load_tree_str(
    text: &str,
    path: &Path,
    defines: &[(String, String)],
    source: IncludeSource<'_>,
) -> Result<SceneTree, Error> {
    load_tree_from(parse_str(text, path)?, defines, source)
}

fn load_tree_from(mut root: Element, defines: &[(String, String)], source: IncludeSource<'_>) -> Result<SceneTree, Error> {
    let mut included = Includes::default();
    if root.tag != "scene" {
        return Err(root.err(format!("the root element is <{}>, expected <scene>", root.tag)));
    }
    let version = root.attr("version").unwrap_or("3.0.0").to_string();
    let major: u32 = version
        .split('.')
        .next()
        .and_then(|m| m.parse().ok())
        .ok_or_else(|| root.err(format!("version '{version}' is not a version number")))?;
    if major > 3 {
        return Err(root.err(format!("scene version {version} is newer than the 3.x that glint reads")));
    }
    expand_includes(&mut root, 0, &mut included, source)?;
    if major < 2 {
        upgrade_from_v0(&mut root);
    }
    let mut values: HashMap<String, String> = HashMap::new();
    root.children.retain(|c| {
        if c.tag == "default" {
            if let (Some(n), Some(v)) = (c.attr("name"), c.attr("value")) {
                values.entry(n.to_string()).or_insert_with(|| v.to_string());
            }
            false
        } else {
            true
        }
    });
    for (k, v) in defines {
        values.insert(k.clone(), v.clone());
    }
    substitute(&mut root, &values)?;
    Ok(SceneTree { root, included: included.files })
}

/// The files included so far, and how many `<include>`s were expanded in all.
#[derive(Default)]
struct Includes {
    files: Vec<PathBuf>,
    expanded: usize,
}

fn expand_includes(el: &mut Element, depth: usize, included: &mut Includes, source: IncludeSource<'_>) -> Result<(), Error> {
    if depth > 16 {
        return Err(el.err("includes nested more than 16 deep (a cycle?)"));
    }
    let mut out = Vec::with_capacity(el.children.len());
    for mut c in std::mem::take(&mut el.children) {
        if c.tag == "include" {
            included.expanded += 1;
            if included.expanded > MAX_INCLUDES {
                return Err(c.err(format!("more than {MAX_INCLUDES} <include>s in one scene")));
            }
            let name = c.required("filename")?;
            let path = c.file.parent().unwrap_or(Path::new(".")).join(name);
            if !source.exists(&path) {
                return Err(c.err(format!("included file '{}' does not exist", path.display())));
            }
            let mut inc = source.parse(&path)?;
            if !included.files.contains(&path) {
                included.files.push(path.clone());
            }
            expand_includes(&mut inc, depth + 1, included, source)?;
            if inc.tag == "scene" {
                out.extend(inc.children);
            } else {
                out.push(inc);
            }
        } else {
            expand_includes(&mut c, depth, included, source)?;
            out.push(c);
        }
    }
    el.children = out;
    Ok(())
}

/// `sampleCount` to `sample_count`, `intIOR` to `int_ior`: a run of capitals is one word.
fn snake_case(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 4);
    let mut prev_lower = false;
    for ch in s.chars() {
        if ch.is_ascii_uppercase() {
            if prev_lower {
                out.push('_');
            }
            out.push(ch.to_ascii_lowercase());
            prev_lower = false;
        } else {
            out.push(ch);
            prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn old_parameter_names_become_snake_case() {
        assert_eq!(snake_case("intIOR"), "int_ior");
        assert_eq!(snake_case("sampleCount"), "sample_count");
        assert_eq!(snake_case("specularReflectance"), "specular_reflectance");
        assert_eq!(snake_case("fov"), "fov");
    }

    #[test]
    fn version_0_6_scene_is_upgraded() {
        let text = r#"<scene version="0.6.0"><default name="d" value="3"/>
            <shape type="sphere"><transform name="toWorld"><lookAt origin="0,0,1" target="0,0,0" up="0,1,0"/></transform>
            <float name="radius" value="$d"/></shape></scene>"#;
        let dir = std::env::temp_dir().join(format!("glint-xml-v06-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("old.xml");
        std::fs::write(&p, text).unwrap();
        let root = load_tree(&p, &[]).unwrap().root;
        let shape = &root.children[0];
        assert_eq!(shape.children[0].attr("name"), Some("to_world"));
        assert_eq!(shape.children[0].children[0].tag, "lookat");
        assert_eq!(shape.children[1].attr("value"), Some("3"));
    }

    #[test]
    fn includes_are_read_from_memory_and_nothing_else() {
        let main = Path::new("/in-memory/scene.xml");
        let mut files = HashMap::new();
        files.insert(
            PathBuf::from("/in-memory/parts/a.xml"),
            r#"<scene version="3.0.0"><include filename="b.xml"/><bsdf type="diffuse" id="x"/></scene>"#.to_string(),
        );
        files.insert(PathBuf::from("/in-memory/parts/b.xml"), r#"<bsdf type="diffuse" id="y"/>"#.to_string());
        let text = r#"<scene version="3.0.0"><include filename="parts/a.xml"/></scene>"#;
        let tree = load_tree_str(text, main, &[], IncludeSource::Memory(&files)).unwrap();
        let ids: Vec<_> = tree.root.children.iter().filter_map(|c| c.attr("id")).collect();
        assert_eq!(ids, ["y", "x"]);
        assert_eq!(tree.included.len(), 2);
        // A file on disk is not visible through a memory source.
        let disk = std::env::temp_dir().join(format!("glint-xml-mem-{}.xml", std::process::id()));
        std::fs::write(&disk, "<bsdf type=\"diffuse\"/>").unwrap();
        let text = format!(r#"<scene version="3.0.0"><include filename="{}"/></scene>"#, disk.display());
        let err = load_tree_str(&text, main, &[], IncludeSource::Memory(&files)).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
        std::fs::remove_file(&disk).ok();
    }
}

fn upgrade_from_v0(el: &mut Element) {
    match el.tag.as_str() {
        "lookAt" => el.tag = "lookat".into(),
        "srgb" => el.tag = "rgb".into(),
        _ => {}
    }
    for (k, v) in el.attrs.iter_mut() {
        if k == "name" {
            *v = match v.as_str() {
                "toWorld" => "to_world".to_string(),
                "toUV" => "to_uv".to_string(),
                other => snake_case(other),
            };
        }
    }
    for c in el.children.iter_mut() {
        upgrade_from_v0(c);
    }
}

/// Replaces each `$name` by its value, once: the output is not scanned again, so a value
/// that mentions `$name` (or a default defined as itself) cannot loop.
fn substitute(el: &mut Element, values: &HashMap<String, String>) -> Result<(), Error> {
    let loc = el.loc();
    for (_, v) in el.attrs.iter_mut() {
        if !v.contains('$') {
            continue;
        }
        let mut out = String::with_capacity(v.len());
        let mut rest = v.as_str();
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(after.len());
            let name = &after[..len];
            if name.is_empty() {
                out.push('$');
            } else {
                let value = values
                    .get(name)
                    .ok_or_else(|| Error::at(&loc, format!("${name} has no <default> and no -D {name}=...")))?;
                out.push_str(value);
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        *v = out;
    }
    for c in el.children.iter_mut() {
        substitute(c, values)?;
    }
    Ok(())
}
