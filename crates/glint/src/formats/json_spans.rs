//! Where each value of a JSON document starts, by its path (`shapes/3/material`,
//! `materials/white`), read by a small scanner of the JSON grammar: errors found after
//! parsing (an unknown material, a bad value) point at the value itself, even when the same
//! text occurs elsewhere in the file. The document has already been parsed by serde_json,
//! so the scanner only needs to be right on valid JSON; on anything else it stops early.

use std::collections::HashMap;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    pub line: u32,
    pub col: u32,
}

#[derive(Default)]
pub struct Spans {
    at: HashMap<String, Position>,
    /// Keys that appear twice in one object (serde_json keeps the last one silently).
    duplicates: Vec<(String, Position)>,
}

impl Spans {
    pub fn scan(text: &str) -> Spans {
        let mut s = Scanner { bytes: text.as_bytes(), pos: 0, line: 1, line_start: 0, spans: Spans::default() };
        let mut path = String::new();
        s.skip_ws();
        // The depth bound keeps a hostile file from overflowing the stack (serde_json has
        // already refused anything nested deeper than 128).
        let _ = s.value(&mut path, 0);
        s.spans
    }

    /// The first key given twice in one object, with the place of its second value.
    pub fn first_duplicate(&self) -> Option<(&str, Position)> {
        self.duplicates.first().map(|(p, pos)| (p.as_str(), *pos))
    }

    /// The start of the value at `path`, or the nearest enclosing value that was recorded.
    pub fn get(&self, path: &str) -> Position {
        let mut p = path;
        loop {
            if let Some(pos) = self.at.get(p) {
                return *pos;
            }
            match p.rfind('/') {
                Some(i) => p = &p[..i],
                None => return self.at.get("").copied().unwrap_or(Position { line: 1, col: 1 }),
            }
        }
    }
}

struct Scanner<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: u32,
    line_start: usize,
    spans: Spans,
}

const MAX_DEPTH: usize = 256;

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.pos).copied()
    }

    fn bump(&mut self) {
        if self.peek() == Some(b'\n') {
            self.line += 1;
            self.line_start = self.pos + 1;
        }
        self.pos += 1;
    }

    fn skip_ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\r' | b'\n')) {
            self.bump();
        }
    }

    fn here(&self) -> Position {
        // Columns count characters, not bytes (as serde_json's do).
        let col = String::from_utf8_lossy(&self.bytes[self.line_start..self.pos]).chars().count() as u32 + 1;
        Position { line: self.line, col }
    }

    fn value(&mut self, path: &mut String, depth: usize) -> Option<()> {
        if depth > MAX_DEPTH {
            return None;
        }
        let here = self.here();
        if self.spans.at.insert(path.clone(), here).is_some() {
            self.spans.duplicates.push((path.clone(), here));
        }
        match self.peek()? {
            b'{' => {
                self.bump();
                self.skip_ws();
                if self.peek()? == b'}' {
                    self.bump();
                    return Some(());
                }
                loop {
                    self.skip_ws();
                    let key = self.string()?;
                    self.skip_ws();
                    if self.peek()? != b':' {
                        return None;
                    }
                    self.bump();
                    self.skip_ws();
                    let len = path.len();
                    if !path.is_empty() || depth > 0 {
                        path.push('/');
                    }
                    path.push_str(&key);
                    self.value(path, depth + 1)?;
                    path.truncate(len);
                    self.skip_ws();
                    match self.peek()? {
                        b',' => self.bump(),
                        b'}' => {
                            self.bump();
                            return Some(());
                        }
                        _ => return None,
                    }
                }
            }
            b'[' => {
                self.bump();
                self.skip_ws();
                if self.peek()? == b']' {
                    self.bump();
                    return Some(());
                }
                let mut i = 0usize;
                loop {
                    self.skip_ws();
                    let len = path.len();
                    if !path.is_empty() || depth > 0 {
                        path.push('/');
                    }
                    path.push_str(&i.to_string());
                    self.value(path, depth + 1)?;
                    path.truncate(len);
                    i += 1;
                    self.skip_ws();
                    match self.peek()? {
                        b',' => self.bump(),
                        b']' => {
                            self.bump();
                            return Some(());
                        }
                        _ => return None,
                    }
                }
            }
            b'"' => self.string().map(|_| ()),
            _ => {
                // Numbers, true, false, null: everything up to the next delimiter.
                while let Some(c) = self.peek() {
                    if matches!(c, b',' | b'}' | b']' | b' ' | b'\t' | b'\r' | b'\n') {
                        break;
                    }
                    self.bump();
                }
                Some(())
            }
        }
    }

    /// A string token; escapes are decoded only as far as keys need (`\"` and `\\`).
    fn string(&mut self) -> Option<String> {
        if self.peek()? != b'"' {
            return None;
        }
        self.bump();
        let mut out = Vec::new();
        loop {
            let c = self.peek()?;
            self.bump();
            match c {
                b'"' => return Some(String::from_utf8_lossy(&out).into_owned()),
                b'\\' => {
                    let e = self.peek()?;
                    self.bump();
                    out.push(e);
                }
                c => out.push(c),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_values_by_path() {
        let text = "{\n  \"a\": [1, {\"b\": \"x\"}],\n  \"c\": {\"d\": true}\n}";
        let s = Spans::scan(text);
        assert_eq!(s.get("a"), Position { line: 2, col: 8 });
        assert_eq!(s.get("a/1/b"), Position { line: 2, col: 18 });
        assert_eq!(s.get("c/d"), Position { line: 3, col: 14 });
        // Unknown paths fall back to the nearest recorded parent.
        assert_eq!(s.get("c/zzz"), Position { line: 3, col: 8 });
    }

    #[test]
    fn the_same_text_twice_is_told_apart() {
        let text = "{\"m\": {\"w\": 1},\n \"s\": [{\"material\": \"w\"},\n {\"material\": \"w\"}]}";
        let s = Spans::scan(text);
        assert_eq!(s.get("s/0/material").line, 2);
        assert_eq!(s.get("s/1/material").line, 3);
    }

    #[test]
    fn a_key_given_twice_is_found() {
        let s = Spans::scan("{\"m\": {\"w\": 1,\n \"w\": 2}}");
        assert_eq!(s.first_duplicate(), Some(("m/w", Position { line: 2, col: 7 })));
        assert_eq!(Spans::scan("{\"a\": [1, 2], \"b\": {\"a\": 1}}").first_duplicate(), None);
    }

    #[test]
    fn survives_garbage_and_deep_nesting() {
        let deep = "[".repeat(100_000);
        let _ = Spans::scan(&deep);
        let _ = Spans::scan("{\"a\": \"unterminated");
        let _ = Spans::scan("");
    }
}
