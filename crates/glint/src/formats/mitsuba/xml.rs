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
    /// For an element of an included file: the folders that file's `<include>` and `<path>`
    /// elements searched (see [`SceneTree::resolve`]); `None` in the scene file itself.
    pub search: Option<Arc<Vec<PathBuf>>>,
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
    /// Whether a file exists (in memory: is a key).
    pub fn exists(&self, path: &Path) -> bool {
        match self {
            IncludeSource::Disk => path.is_file(),
            IncludeSource::Memory(files) => files.contains_key(&normalize(path)),
        }
    }

    /// Whether a folder exists (in memory: some key lies under it).
    pub fn dir_exists(&self, path: &Path) -> bool {
        match self {
            IncludeSource::Disk => path.is_dir(),
            IncludeSource::Memory(files) => {
                let path = normalize(path);
                files.keys().any(|k| k.starts_with(&path) && *k != path)
            }
        }
    }

    /// Parses one file into its root element (no includes or substitution yet).
    fn parse(&self, path: &Path) -> Result<Element, Error> {
        match self {
            IncludeSource::Disk => parse_str(&crate::formats::read_text(path)?, path),
            IncludeSource::Memory(files) => match files.get(&normalize(path)) {
                Some(text) => parse_str(text, path),
                None => Err(Error::at(&SourceLoc::file(path), "file does not exist")),
            },
        }
    }
}

/// `a/./b/../c` as `a/c`, without the file system (for paths in memory).
fn normalize(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
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
        let start = text
            .as_bytes()
            .get(before..)
            .and_then(|b| b.iter().position(|&c| c == b'<'))
            .map_or(before, |o| before + o);
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
                search: None,
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
    /// Mitsuba's search path for the files that plugins name (meshes, textures, ...): the
    /// scene file's `<path>` folders, the last one first, then the scene file's own folder.
    pub search: Vec<PathBuf>,
    /// What was read but had no effect (a `-D` name with no `<default>`), one line each.
    pub warnings: Vec<String>,
}

impl SceneTree {
    /// The file that a plugin's relative `filename` names, found as Mitsuba finds it: in the
    /// scene's search path ([`SceneTree::search`], wherever in the scene file the `<path>`
    /// elements stand), and, for an element of an included file, failing that, in the folders
    /// that included file searched (its own `<path>`s, its folder, the folders of the files
    /// that included it: glint's addition, where Mitsuba would find nothing). A name found
    /// nowhere is taken relative to the element's own file, for the error that follows.
    pub fn resolve(&self, el: &Element, name: &str, source: IncludeSource<'_>) -> PathBuf {
        let name = Path::new(name);
        if name.is_absolute() {
            return name.to_path_buf();
        }
        let scoped = el.search.as_deref().map_or(&[][..], |v| v.as_slice());
        self.search
            .iter()
            .chain(scoped)
            .map(|d| d.join(name))
            .find(|p| source.exists(p))
            .unwrap_or_else(|| el.file.parent().unwrap_or(Path::new(".")).join(name))
    }
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

fn load_tree_from(
    mut root: Element,
    defines: &[(String, String)],
    source: IncludeSource<'_>,
) -> Result<SceneTree, Error> {
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
    let mut search = vec![root.file.parent().unwrap_or(Path::new(".")).to_path_buf()];
    expand_includes(&mut root, 0, true, &mut search, &mut included, source)?;
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
    let mut warnings = Vec::new();
    for (k, v) in defines {
        // As Mitsuba: a define still substitutes `$name`, but one the scene gives no default
        // is most often a typo, so it is said.
        if !values.contains_key(k) {
            warnings.push(format!("{}: -D {k}: the scene has no <default name=\"{k}\">", root.file.display()));
        }
        values.insert(k.clone(), v.clone());
    }
    substitute(&mut root, &values)?;
    Ok(SceneTree { root, included: included.files, search, warnings })
}

/// The files included so far, and how many `<include>`s were expanded in all.
#[derive(Default)]
struct Includes {
    files: Vec<PathBuf>,
    expanded: usize,
}

/// Expands the `<include>`s under `el` and applies its `<path>`s, as Mitsuba's parser does:
/// `search` is the search path in effect (most recent folder first). A `<path>` (allowed only
/// as a child of a file's root, `at_root`) adds its folder in front, found relative to its
/// file or else through the search path; an `<include>` is looked for in the including file's
/// folder, then through the search path, and is expanded with a copy of the search path that
/// starts with that folder, so that what the included file adds stays within it.
fn expand_includes(
    el: &mut Element,
    depth: usize,
    at_root: bool,
    search: &mut Vec<PathBuf>,
    included: &mut Includes,
    source: IncludeSource<'_>,
) -> Result<(), Error> {
    if depth > 16 {
        return Err(el.err("includes nested more than 16 deep (a cycle?)"));
    }
    let mut out = Vec::with_capacity(el.children.len());
    for mut c in std::mem::take(&mut el.children) {
        let dir = c.file.parent().unwrap_or(Path::new(".")).to_path_buf();
        if c.tag == "path" {
            if !at_root {
                return Err(c.err("<path> may only be a child of the root <scene>"));
            }
            let value = c.required("value")?;
            let given = Path::new(value);
            let folder = if given.is_absolute() {
                Some(given.to_path_buf())
            } else {
                std::iter::once(&dir).chain(search.iter()).map(|d| d.join(given)).find(|p| source.dir_exists(p))
            };
            match folder {
                Some(f) if source.dir_exists(&f) => search.insert(0, f),
                _ => return Err(c.err(format!("<path>: folder '{}' not found", dir.join(given).display()))),
            }
            if search.len() > MAX_INCLUDES {
                return Err(c.err(format!("more than {MAX_INCLUDES} folders in the search path")));
            }
        } else if c.tag == "include" {
            included.expanded += 1;
            if included.expanded > MAX_INCLUDES {
                return Err(c.err(format!("more than {MAX_INCLUDES} <include>s in one scene")));
            }
            let name = Path::new(c.required("filename")?);
            let mut inner: Vec<PathBuf> = std::iter::once(dir.clone()).chain(search.iter().cloned()).collect();
            let path = if name.is_absolute() {
                name.to_path_buf()
            } else {
                inner.iter().map(|d| d.join(name)).find(|p| source.exists(p)).unwrap_or_else(|| dir.join(name))
            };
            if !source.exists(&path) {
                return Err(c.err(format!("included file '{}' does not exist", path.display())));
            }
            let mut inc = source.parse(&path)?;
            if !included.files.contains(&path) {
                included.files.push(path.clone());
            }
            // The included file's folder comes first within it.
            inner.insert(0, path.parent().unwrap_or(Path::new(".")).to_path_buf());
            expand_includes(&mut inc, depth + 1, true, &mut inner, included, source)?;
            let scope = Arc::new(inner);
            set_search(&mut inc, &scope);
            if inc.tag == "scene" {
                out.extend(inc.children);
            } else {
                out.push(inc);
            }
        } else {
            expand_includes(&mut c, depth, false, search, included, source)?;
            out.push(c);
        }
    }
    el.children = out;
    Ok(())
}

/// Gives the elements of one included file (not those of files it included in turn, which
/// have theirs already) the search path that file ended with.
fn set_search(el: &mut Element, scope: &Arc<Vec<PathBuf>>) {
    if el.search.is_none() {
        el.search = Some(scope.clone());
        for c in el.children.iter_mut() {
            set_search(c, scope);
        }
    }
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
        let dir = crate::scratch::ScratchDir::new("xml-v06");
        let p = dir.join("old.xml");
        std::fs::write(&p, text).unwrap();
        let root = load_tree(&p, &[]).unwrap().root;
        let shape = &root.children[0];
        assert_eq!(shape.children[0].attr("name"), Some("to_world"));
        assert_eq!(shape.children[0].children[0].tag, "lookat");
        assert_eq!(shape.children[1].attr("value"), Some("3"));
    }

    /// Files in memory under /m/, for the search-path tests.
    fn memory(files: &[(&str, &str)]) -> HashMap<PathBuf, String> {
        files.iter().map(|(k, v)| (PathBuf::from(format!("/m/{k}")), v.to_string())).collect()
    }

    fn shape_file(tree: &SceneTree, files: &HashMap<PathBuf, String>, i: usize) -> PathBuf {
        let el = &tree.root.children[i];
        let name = el.children.iter().find(|c| c.attr("name") == Some("filename")).unwrap().attr("value").unwrap();
        normalize(&tree.resolve(el, name, IncludeSource::Memory(files)))
    }

    const OBJ: &str = "v 0 0 0";

    /// As Mitsuba 3.9.1 resolves them (each case checked there): the scene file's <path>s,
    /// wherever they stand and the last one first, then its folder; a <path> in an included
    /// file is relative to that file (or found through the search path) and serves that file.
    #[test]
    fn path_adds_folders_to_the_search_path() {
        let shape = |f: &str| format!(r#"<shape type="obj"><string name="filename" value="{f}"/></shape>"#);
        // A <path> after the shape that uses it still applies; the last <path> wins.
        let files = memory(&[("a/m.obj", OBJ), ("b/m.obj", OBJ), ("m.obj", OBJ), ("c/only.obj", OBJ)]);
        let text = format!(
            r#"<scene version="3.0.0">{}{}<path value="a"/><path value="/m/b"/><path value="c"/></scene>"#,
            shape("m.obj"),
            shape("only.obj")
        );
        let tree = load_tree_str(&text, Path::new("/m/scene.xml"), &[], IncludeSource::Memory(&files)).unwrap();
        assert_eq!(tree.root.children.len(), 2, "the <path>s are not elements of the scene");
        assert_eq!(shape_file(&tree, &files, 0), Path::new("/m/b/m.obj"));
        assert_eq!(shape_file(&tree, &files, 1), Path::new("/m/c/only.obj"));
        // Without <path>, the scene's folder.
        let text = format!(r#"<scene version="3.0.0">{}</scene>"#, shape("m.obj"));
        let tree = load_tree_str(&text, Path::new("/m/scene.xml"), &[], IncludeSource::Memory(&files)).unwrap();
        assert_eq!(shape_file(&tree, &files, 0), Path::new("/m/m.obj"));
    }

    #[test]
    fn path_in_an_included_file_is_relative_to_it() {
        let shape = |f: &str| format!(r#"<shape type="obj"><string name="filename" value="{f}"/></shape>"#);
        let files = memory(&[
            // ../../common does not exist next to include/, but does through the search path
            // (the scene's folder): Mitsuba's documentation scenes rely on this.
            (
                "docs/scenes/include/part.xml",
                r#"<scene version="3.0.0"><path value="../../common"/><include filename="inner.xml"/></scene>"#,
            ),
            ("common/inner.xml", &format!(r#"<scene version="3.0.0">{}</scene>"#, shape("mesh.obj"))),
            ("common/mesh.obj", OBJ),
            ("docs/common/.keep", ""),
            // A <path> relative to the included file, used by the file it includes.
            (
                "docs/scenes/sub/a.xml",
                r#"<scene version="3.0.0"><path value="assets"/><include filename="d.xml"/></scene>"#,
            ),
            ("docs/scenes/sub/assets/d.xml", &format!(r#"<scene version="3.0.0">{}</scene>"#, shape("here.obj"))),
            ("docs/scenes/sub/assets/here.obj", OBJ),
        ]);
        let text =
            r#"<scene version="3.0.0"><include filename="include/part.xml"/><include filename="sub/a.xml"/></scene>"#;
        let main = Path::new("/m/docs/scenes/main.xml");
        let err = load_tree_str(text, main, &[], IncludeSource::Memory(&files)).unwrap_err();
        // /m/docs/common exists, so ../../common relative to include/ is that folder, in which
        // inner.xml is not.
        assert!(err.to_string().contains("inner.xml") && err.to_string().contains("does not exist"), "{err}");
        let mut files = files;
        files.remove(Path::new("/m/docs/common/.keep"));
        let tree = load_tree_str(text, main, &[], IncludeSource::Memory(&files)).unwrap();
        // Found through the included files' own search paths (Mitsuba finds neither: it looks
        // for plugins' files in the scene file's search path only, which comes first here).
        assert_eq!(shape_file(&tree, &files, 0), Path::new("/m/common/mesh.obj"));
        assert_eq!(shape_file(&tree, &files, 1), Path::new("/m/docs/scenes/sub/assets/here.obj"));
        // The scene file's search path comes first.
        files.insert(PathBuf::from("/m/docs/scenes/here.obj"), OBJ.into());
        let tree = load_tree_str(text, main, &[], IncludeSource::Memory(&files)).unwrap();
        assert_eq!(shape_file(&tree, &files, 1), Path::new("/m/docs/scenes/here.obj"));
        // An include found through the scene's <path>.
        let text = r#"<scene version="3.0.0"><path value="sub"/><include filename="a.xml"/></scene>"#;
        let tree = load_tree_str(text, main, &[], IncludeSource::Memory(&files)).unwrap();
        assert_eq!(normalize(&tree.included[0]), Path::new("/m/docs/scenes/sub/a.xml"));
    }

    #[test]
    fn path_errors() {
        let files = memory(&[("x/y.obj", OBJ)]);
        let load = |t: &str| load_tree_str(t, Path::new("/m/s.xml"), &[], IncludeSource::Memory(&files));
        let e = load("<scene version=\"3.0.0\">\n<path value=\"nowhere\"/></scene>").unwrap_err().to_string();
        assert!(e.contains("s.xml:2:") && e.contains("nowhere") && e.contains("not found"), "{e}");
        let e = load("<scene version=\"3.0.0\"><shape type=\"obj\">\n<path value=\"x\"/></shape></scene>")
            .unwrap_err()
            .to_string();
        assert!(e.contains("s.xml:2:") && e.contains("child of the root"), "{e}");
        let e = load("<scene version=\"3.0.0\"><path/></scene>").unwrap_err().to_string();
        assert!(e.contains("'value'"), "{e}");
        assert!(load("<scene version=\"3.0.0\"><path value=\"x\"/></scene>").is_ok());
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
        let dir = crate::scratch::ScratchDir::new("xml-mem");
        let disk = dir.join("disk.xml");
        std::fs::write(&disk, "<bsdf type=\"diffuse\"/>").unwrap();
        let text = format!(r#"<scene version="3.0.0"><include filename="{}"/></scene>"#, disk.display());
        let err = load_tree_str(&text, main, &[], IncludeSource::Memory(&files)).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
    }
}
