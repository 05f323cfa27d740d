//! JSON scene files: a JSON value tree with line and column on every value and key ([`Spanned`]), and
//! the 2025 METU JSON form turned into the same element tree as the XML ([`parse`]).
//!
//! serde_json reports positions only for syntax errors and, without its `preserve_order` feature,
//! sorts object keys, while scene files need the file order (objects are rendered and numbered in it)
//! and a line for every semantic error. So serde_json first checks the syntax (its messages are good
//! and tested), then a small scanner, which may assume well-formed input but still fails cleanly,
//! walks the text once and records positions; string escapes are decoded by serde_json.
//!
//! The METU mapping is the inverse of the course's `xml2json.sh`: a key is an element, a `_`-prefixed
//! key an attribute, `_data` the text, an array repeated elements of the same name, a scalar the text.

use std::path::Path;

use super::tree::{Attr, Node};
use crate::{Error, Location, Result};

/// A JSON value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A number, as written (so that integers stay exact and text values compare equal to XML).
    Number(String),
    /// A string, unescaped.
    Str(String),
    /// An array.
    Array(Vec<Spanned>),
    /// An object, keys in file order (duplicates kept).
    Object(Vec<Member>),
}

/// A value with the 1-based line and column where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Spanned {
    /// The value.
    pub value: Value,
    /// Line.
    pub line: u32,
    /// Column (characters).
    pub col: u32,
}

/// An object member: its key, where the key is, and the value.
#[derive(Debug, Clone, PartialEq)]
pub struct Member {
    /// Key, unescaped.
    pub key: String,
    /// Line of the key.
    pub line: u32,
    /// Column of the key.
    pub col: u32,
    /// The value.
    pub value: Spanned,
}

/// Parses a JSON document with positions; syntax errors carry serde_json's line and column.
pub fn parse_value(text: &str, path: &Path) -> Result<Spanned> {
    if let Err(e) = serde_json::from_str::<serde_json::Value>(text) {
        let msg = e.to_string();
        let suffix = format!(" at line {} column {}", e.line(), e.column());
        let msg = msg.strip_suffix(&suffix).unwrap_or(&msg);
        let loc = Location::at(path, e.line() as u32, e.column() as u32);
        return Err(Error::input(loc, format!("JSON syntax error: {msg}")));
    }
    let mut s = Scanner::new(text);
    let v = s.value().map_err(|()| Error::input(Location::at(path, s.line, s.col), "JSON value not understood"))?;
    Ok(v)
}

/// The keys of the top-level object, without validating or building anything; `None` when the text
/// does not start like a JSON object. Cheap enough to run before choosing a reader.
pub fn top_level_keys(text: &str) -> Option<Vec<String>> {
    let mut s = Scanner::new(text);
    s.ws();
    s.eat(b'{').ok()?;
    let mut keys = Vec::new();
    loop {
        s.ws();
        if s.peek() == Some(b'}') {
            return Some(keys);
        }
        keys.push(s.string().ok()?);
        s.ws();
        s.eat(b':').ok()?;
        s.value().ok()?;
        s.ws();
        match s.next()? {
            b',' => {}
            b'}' => return Some(keys),
            _ => return None,
        }
    }
}

/// Parses a METU JSON scene into the element tree of its `"Scene"` object.
pub fn parse(text: &str, path: &Path) -> Result<Node> {
    let doc = parse_value(text, path)?;
    let Value::Object(members) = &doc.value else {
        return Err(Error::input(Location::at(path, doc.line, doc.col), "expected a JSON object holding \"Scene\""));
    };
    let mut root = Node::new("", doc.line, doc.col);
    add_members(&mut root, members, path)?;
    let scene_at = root.children.iter().rposition(|c| c.name == "Scene");
    let Some(i) = scene_at else {
        return Err(Error::input(Location::at(path, doc.line, doc.col), "no top-level \"Scene\" object"));
    };
    let mut scene = root.children.remove(i);
    // Other top-level keys have no meaning; keeping them as children of Scene gets them reported
    // as ignored, with their line.
    scene.children.append(&mut root.children);
    Ok(scene)
}

fn add_members(node: &mut Node, members: &[Member], path: &Path) -> Result<()> {
    for m in members {
        if m.key == "_data" {
            node.text = scalar_text(&m.value, &m.key, path)?;
        } else if let Some(name) = m.key.strip_prefix('_') {
            let v = scalar_text(&m.value, &m.key, path)?;
            node.attrs.push(Attr::new(name, v, m.line, m.col));
        } else if let Value::Array(items) = &m.value.value {
            for it in items {
                node.children.push(element(&m.key, it, it.line, it.col, path)?);
            }
        } else {
            node.children.push(element(&m.key, &m.value, m.line, m.col, path)?);
        }
    }
    Ok(())
}

fn element(name: &str, v: &Spanned, line: u32, col: u32, path: &Path) -> Result<Node> {
    let mut node = Node::new(name, line, col);
    match &v.value {
        Value::Object(members) => add_members(&mut node, members, path)?,
        Value::Array(_) => {
            return Err(Error::input(
                Location::at(path, v.line, v.col),
                format!("\"{name}\": nested arrays have no meaning in a METU scene"),
            ))
        }
        _ => node.text = scalar_text(v, name, path)?,
    }
    Ok(node)
}

fn scalar_text(v: &Spanned, key: &str, path: &Path) -> Result<String> {
    Ok(match &v.value {
        Value::Null => String::new(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.clone(),
        Value::Str(s) => s.clone(),
        Value::Array(_) | Value::Object(_) => {
            return Err(Error::input(
                Location::at(path, v.line, v.col),
                format!("\"{key}\": expected a string or a number"),
            ))
        }
    })
}

/// A cursor over the text that keeps the line and column; every method returns `Err(())` at the
/// first byte it does not expect, with the cursor there.
struct Scanner<'a> {
    text: &'a str,
    pos: usize,
    line: u32,
    col: u32,
    /// Open arrays and objects: the scan is recursive and [`top_level_keys`] runs it on unchecked
    /// text, so nesting is bounded (as serde_json bounds it, at 128).
    depth: u32,
}

type Scan<T> = std::result::Result<T, ()>;

impl<'a> Scanner<'a> {
    fn new(text: &'a str) -> Self {
        Scanner { text, pos: 0, line: 1, col: 1, depth: 0 }
    }
    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }
    fn next(&mut self) -> Option<u8> {
        let b = self.peek()?;
        self.pos += 1;
        if b == b'\n' {
            self.line += 1;
            self.col = 1;
        } else if b & 0xC0 != 0x80 {
            // Continuation bytes of a UTF-8 character do not start a new column.
            self.col += 1;
        }
        Some(b)
    }
    fn eat(&mut self, b: u8) -> Scan<()> {
        if self.peek() == Some(b) {
            self.next();
            Ok(())
        } else {
            Err(())
        }
    }
    fn ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.next();
        }
    }
    fn value(&mut self) -> Scan<Spanned> {
        self.ws();
        let (line, col) = (self.line, self.col);
        let value = match self.peek().ok_or(())? {
            b'{' | b'[' if self.depth >= 128 => return Err(()),
            b'{' => self.nested(Self::object, Value::Object)?,
            b'[' => self.nested(Self::array, Value::Array)?,
            b'"' => Value::Str(self.string()?),
            b't' => self.word("true", Value::Bool(true))?,
            b'f' => self.word("false", Value::Bool(false))?,
            b'n' => self.word("null", Value::Null)?,
            _ => Value::Number(self.number()?),
        };
        Ok(Spanned { value, line, col })
    }
    fn nested<T>(&mut self, f: fn(&mut Self) -> Scan<T>, wrap: fn(T) -> Value) -> Scan<Value> {
        self.depth += 1;
        let v = f(self)?;
        self.depth -= 1;
        Ok(wrap(v))
    }
    fn word(&mut self, w: &str, v: Value) -> Scan<Value> {
        for &b in w.as_bytes() {
            self.eat(b)?;
        }
        Ok(v)
    }
    fn number(&mut self) -> Scan<String> {
        let start = self.pos;
        while matches!(self.peek(), Some(b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E')) {
            self.next();
        }
        if self.pos == start {
            return Err(());
        }
        Ok(self.text[start..self.pos].to_string())
    }
    fn string(&mut self) -> Scan<String> {
        let start = self.pos;
        self.eat(b'"')?;
        loop {
            match self.next().ok_or(())? {
                b'\\' => {
                    self.next().ok_or(())?;
                }
                b'"' => break,
                _ => {}
            }
        }
        serde_json::from_str(&self.text[start..self.pos]).map_err(|_| ())
    }
    fn array(&mut self) -> Scan<Vec<Spanned>> {
        self.eat(b'[')?;
        let mut items = Vec::new();
        self.ws();
        if self.eat(b']').is_ok() {
            return Ok(items);
        }
        loop {
            items.push(self.value()?);
            self.ws();
            match self.next() {
                Some(b',') => {}
                Some(b']') => return Ok(items),
                _ => return Err(()),
            }
        }
    }
    fn object(&mut self) -> Scan<Vec<Member>> {
        self.eat(b'{')?;
        let mut members = Vec::new();
        self.ws();
        if self.eat(b'}').is_ok() {
            return Ok(members);
        }
        loop {
            self.ws();
            let (line, col) = (self.line, self.col);
            let key = self.string()?;
            self.ws();
            self.eat(b':')?;
            let value = self.value()?;
            members.push(Member { key, line, col, value });
            self.ws();
            match self.next() {
                Some(b',') => {}
                Some(b'}') => return Ok(members),
                _ => return Err(()),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_positions_of_keys_and_array_items() {
        let text = "{\n  \"Scene\": {\n    \"Obj\": [\n      {\"_id\": \"1\", \"_data\": \"1 2 3\"},\n      \"x\"\n    ],\n    \"N\": 4.5e1\n  }\n}";
        let scene = parse(text, Path::new("s.json")).unwrap();
        assert_eq!((scene.name.as_str(), scene.line, scene.col), ("Scene", 2, 3));
        let objs: Vec<_> = scene.children.iter().map(|c| (c.name.as_str(), c.line, c.col)).collect();
        assert_eq!(objs, [("Obj", 4, 7), ("Obj", 5, 7), ("N", 7, 5)]);
        assert_eq!(scene.children[0].text, "1 2 3");
        let id = &scene.children[0].attrs[0];
        assert_eq!((id.name.as_str(), id.value.as_str(), id.line, id.col), ("id", "1", 4, 8));
        assert_eq!(scene.children[2].text, "4.5e1");
    }

    #[test]
    fn json_syntax_error_has_line_and_column() {
        let e = parse("{\n  \"Scene\": {\n    \"A\": \"1\"\n    \"B\": 2\n  }\n}", Path::new("bad.json")).unwrap_err();
        assert_eq!(e.to_string(), "bad.json:4:5: JSON syntax error: expected `,` or `}`");
    }

    #[test]
    fn json_keeps_key_order_escapes_and_columns_after_unicode() {
        let v = parse_value("{\"b\": \"\\u00e9\\n\", \"é\": 1, \"a\": null}", Path::new("s.json")).unwrap();
        let Value::Object(m) = v.value else { panic!() };
        let keys: Vec<_> = m.iter().map(|m| (m.key.as_str(), m.col)).collect();
        assert_eq!(keys, [("b", 2), ("é", 19), ("a", 27)]);
        assert_eq!(m[0].value.value, Value::Str("é\n".into()));
    }

    #[test]
    fn json_top_level_keys_without_building() {
        let keys = top_level_keys(" {\"Camera\": {\"a\": [1, {\"b\": \"}\"}]}, \"Objects\": []}").unwrap();
        assert_eq!(keys, ["Camera", "Objects"]);
        assert_eq!(top_level_keys("[1]"), None);
        let deep = format!("{{\"a\": {}", "[".repeat(100_000));
        assert_eq!(top_level_keys(&deep), None);
    }

    #[test]
    fn json_without_scene_is_an_error() {
        let e = parse("{\"Camera\": 1}", Path::new("s.json")).unwrap_err();
        assert_eq!(e.to_string(), "s.json:1:1: no top-level \"Scene\" object");
    }
}
