//! The library's one error type: a message with an optional source location, shown on one
//! line as `file:line:col: message` (the parts that are known).

use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

/// Where an entity of a scene description came from. `line` and `col` are 1-based; 0 means
/// unknown (a file-level error, or a description built in code).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SourceLoc {
    pub file: PathBuf,
    pub line: u32,
    pub col: u32,
}

impl SourceLoc {
    pub fn new(file: impl Into<PathBuf>, line: u32, col: u32) -> SourceLoc {
        SourceLoc { file: file.into(), line, col }
    }
    /// A whole file, no position in it.
    pub fn file(file: &Path) -> SourceLoc {
        SourceLoc { file: file.to_path_buf(), line: 0, col: 0 }
    }
    pub fn is_known(&self) -> bool {
        !self.file.as_os_str().is_empty()
    }
}

impl fmt::Display for SourceLoc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if self.line > 0 {
            write!(f, ":{}", self.line)?;
            if self.col > 0 {
                write!(f, ":{}", self.col)?;
            }
        }
        Ok(())
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub loc: Option<SourceLoc>,
    pub message: String,
    /// Further errors found in the same run (a scene with several unsupported features
    /// reports them all), each shown on a line of its own after this one.
    pub also: Vec<Error>,
}

impl Error {
    pub fn new(message: impl Into<String>) -> Error {
        Error { loc: None, message: message.into(), also: Vec::new() }
    }
    /// The first of `errors`, with the rest as [`Error::also`]; `None` for none.
    pub fn many(errors: Vec<Error>) -> Option<Error> {
        let mut it = errors.into_iter();
        let mut first = it.next()?;
        first.also.extend(it);
        Some(first)
    }
    pub fn at(loc: &SourceLoc, message: impl Into<String>) -> Error {
        Error { loc: loc.is_known().then(|| loc.clone()), message: message.into(), also: Vec::new() }
    }
    /// Adds a location to an error that has none (an inner error gets its entity's place).
    pub fn or_at(mut self, loc: &SourceLoc) -> Error {
        if self.loc.is_none() && loc.is_known() {
            self.loc = Some(loc.clone());
        }
        self
    }
}

/// Control characters from the input are escaped so that an error is always one line.
fn one_line(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    out
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.loc {
            Some(loc) => write!(f, "{}: {}", one_line(&loc.to_string()), one_line(&self.message))?,
            None => write!(f, "{}", one_line(&self.message))?,
        }
        for e in &self.also {
            write!(f, "\n{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Error {}

/// Lower layers (mesh and image readers, the BVH) report plain strings that already name
/// their file; they become located errors at the entity that asked for them.
impl From<String> for Error {
    fn from(message: String) -> Error {
        Error::new(message)
    }
}

impl From<&str> for Error {
    fn from(message: &str) -> Error {
        Error::new(message)
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shows_the_known_parts_of_the_location() {
        let e = Error::at(&SourceLoc::new("a.json", 3, 7), "bad");
        assert_eq!(e.to_string(), "a.json:3:7: bad");
        let e = Error::at(&SourceLoc::new("a.json", 3, 0), "bad");
        assert_eq!(e.to_string(), "a.json:3: bad");
        assert_eq!(Error::new("bad").to_string(), "bad");
        assert_eq!(Error::at(&SourceLoc::default(), "bad").to_string(), "bad");
    }

    #[test]
    fn is_always_one_line() {
        let e = Error::at(&SourceLoc::new("a\nb.xml", 1, 0), "x\ny\u{1b}");
        let s = e.to_string();
        assert!(!s.contains('\n') && !s.contains('\u{1b}'), "{s}");
        assert_eq!(s, "a\\nb.xml:1: x\\ny\\u{1b}");
    }
}
