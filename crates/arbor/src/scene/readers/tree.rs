//! The element tree shared by the METU XML and JSON readers, and typed access to its values.
//!
//! Both METU forms become the same [`Node`] tree ([`super::xml`] builds it from XML, [`super::json`] from
//! the 2025 JSON), so that [`super::metu`] interprets a scene once. Every node and attribute keeps its
//! line and column, and remembers whether the interpreter asked for it: whatever is never asked for is
//! reported afterwards as ignored ([`Node::unused`]), as pbrt's `ReportUnused` does, instead of being
//! dropped in silence.
//!
//! Values are whitespace-separated text with arbitrary padding; the accessors trim and split them and
//! turn every malformed value into an error that names the file, the line, the element and the text.

use std::cell::Cell;
use std::path::Path;

use crate::math::Vec3;
use crate::{Error, Location, Result};

/// An attribute (`id="1"` in XML, `"_id": "1"` in JSON).
#[derive(Debug, Clone)]
pub struct Attr {
    /// Name, without the JSON `_` prefix.
    pub name: String,
    /// Value as written.
    pub value: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub col: u32,
    used: Cell<bool>,
}

/// An element: a name, attributes, its own text and child elements, with its place in the file.
#[derive(Debug, Clone)]
pub struct Node {
    /// Element name (JSON key).
    pub name: String,
    /// Attributes, in file order.
    pub attrs: Vec<Attr>,
    /// The element's own text (XML text children joined; JSON scalar or `_data`).
    pub text: String,
    /// Child elements, in file order.
    pub children: Vec<Node>,
    /// 1-based line of the start tag (JSON: of the key).
    pub line: u32,
    /// 1-based column.
    pub col: u32,
    used: Cell<bool>,
}

/// Something the interpreter never asked for.
pub enum Unused<'a> {
    /// An element, with the name of its parent.
    Element(&'a Node, &'a str),
    /// An attribute, with the name of its element.
    Attr(&'a Attr, &'a str),
}

impl Attr {
    /// A new attribute at `line:col`.
    pub fn new(name: impl Into<String>, value: impl Into<String>, line: u32, col: u32) -> Self {
        Attr { name: name.into(), value: value.into(), line, col, used: Cell::new(false) }
    }
    /// Where the attribute is.
    pub fn loc(&self, path: &Path) -> Location {
        Location::at(path, self.line, self.col)
    }
    /// The value, trimmed.
    pub fn trimmed(&self) -> &str {
        self.value.trim()
    }
    /// The value as an integer.
    pub fn int(&self, path: &Path) -> Result<i64> {
        self.trimmed().parse().map_err(|_| {
            Error::input(self.loc(path), format!("attribute {}: malformed integer '{}'", self.name, self.trimmed()))
        })
    }
    /// The value as `true` or `false`.
    pub fn boolean(&self, path: &Path) -> Result<bool> {
        parse_bool(self.trimmed()).ok_or_else(|| {
            Error::input(
                self.loc(path),
                format!("attribute {}: expected true or false, found '{}'", self.name, self.trimmed()),
            )
        })
    }
}

fn parse_bool(s: &str) -> Option<bool> {
    match s {
        "true" | "1" => Some(true),
        "false" | "0" => Some(false),
        _ => None,
    }
}

impl Node {
    /// An empty element at `line:col`.
    pub fn new(name: impl Into<String>, line: u32, col: u32) -> Self {
        Node {
            name: name.into(),
            attrs: Vec::new(),
            text: String::new(),
            children: Vec::new(),
            line,
            col,
            used: Cell::new(false),
        }
    }
    /// Where the element is.
    pub fn loc(&self, path: &Path) -> Location {
        Location::at(path, self.line, self.col)
    }
    /// Marks the element as read, so that it is not reported as ignored.
    pub fn mark_used(&self) {
        self.used.set(true);
    }
    /// The children called `name`, in file order; all of them count as read.
    pub fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.children.iter().filter(move |c| c.name == name).inspect(|c| c.mark_used())
    }
    /// The last child called `name` (the last one wins, as in the official parsers), with every child of
    /// that name counted as read. Duplicates are the caller's to report ([`Node::duplicates`]).
    pub fn child(&self, name: &str) -> Option<&Node> {
        let mut last = None;
        for c in self.children.iter().filter(|c| c.name == name) {
            c.mark_used();
            last = Some(c);
        }
        last
    }
    /// The child called `name`, or an error naming this element and the missing one.
    pub fn required(&self, name: &str, path: &Path) -> Result<&Node> {
        self.child(name).ok_or_else(|| Error::input(self.loc(path), format!("<{}>: missing <{name}>", self.name)))
    }
    /// Children called `name` beyond the first, for a "duplicate, the last one wins" warning.
    pub fn duplicates<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.children.iter().filter(move |c| c.name == name).skip(1)
    }
    /// The attribute called `name`, counted as read.
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        let a = self.attrs.iter().rev().find(|a| a.name == name)?;
        a.used.set(true);
        Some(a)
    }
    /// The text, trimmed.
    pub fn trimmed(&self) -> &str {
        self.text.trim()
    }
    /// Every whitespace-separated number of the text.
    pub fn floats(&self, path: &Path) -> Result<Vec<f32>> {
        self.trimmed()
            .split_whitespace()
            .map(|tok| parse_f32(tok).map_err(|what| self.malformed(what, tok, path)))
            .collect()
    }
    /// Exactly `n` numbers; with `extra_ok`, more are tolerated and the first `n` kept.
    pub fn floats_n(&self, n: usize, extra_ok: bool, path: &Path) -> Result<Vec<f32>> {
        let mut v = self.floats(path)?;
        if v.len() < n || (v.len() > n && !extra_ok) {
            return Err(Error::input(
                self.loc(path),
                format!("<{}>: expected {n} numbers, found {}", self.name, v.len()),
            ));
        }
        v.truncate(n);
        Ok(v)
    }
    /// One number.
    pub fn float(&self, path: &Path) -> Result<f32> {
        Ok(self.floats_n(1, false, path)?[0])
    }
    /// Three numbers (a point, a direction or a colour).
    pub fn vec3(&self, path: &Path) -> Result<Vec3> {
        let v = self.floats_n(3, false, path)?;
        Ok(Vec3::new(v[0], v[1], v[2]))
    }
    /// Every whitespace-separated integer of the text (indices may be negative before an offset).
    pub fn ints(&self, path: &Path) -> Result<Vec<i64>> {
        self.trimmed()
            .split_whitespace()
            .map(|tok| tok.parse().map_err(|_| self.malformed("malformed integer", tok, path)))
            .collect()
    }
    /// One non-negative integer.
    pub fn uint(&self, path: &Path) -> Result<u32> {
        let tok = self.trimmed();
        tok.parse().map_err(|_| self.malformed("malformed integer", tok, path))
    }
    /// `true` or `false`.
    pub fn boolean(&self, path: &Path) -> Result<bool> {
        parse_bool(self.trimmed()).ok_or_else(|| {
            Error::input(self.loc(path), format!("<{}>: expected true or false, found '{}'", self.name, self.trimmed()))
        })
    }
    fn malformed(&self, what: &str, tok: &str, path: &Path) -> Error {
        Error::input(self.loc(path), format!("<{}>: {what} '{tok}'", self.name))
    }
    /// Everything below this element that was never read, outermost first: an ignored element is
    /// reported once, not with each of its descendants.
    pub fn unused(&self) -> Vec<Unused<'_>> {
        let mut out = Vec::new();
        self.collect_unused(&mut out);
        out
    }
    fn collect_unused<'a>(&'a self, out: &mut Vec<Unused<'a>>) {
        for a in &self.attrs {
            if !a.used.get() {
                out.push(Unused::Attr(a, &self.name));
            }
        }
        for c in &self.children {
            if c.used.get() {
                c.collect_unused(out);
            } else {
                out.push(Unused::Element(c, &self.name));
            }
        }
    }
}

/// A finite `f32`, or what is wrong with `tok`: Rust's parser also accepts `inf` and `nan`, which no
/// scene means, and turns numbers beyond `f32` (`1e39`) into infinities.
fn parse_f32(tok: &str) -> std::result::Result<f32, &'static str> {
    match tok.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) if v.is_nan() || tok.to_ascii_lowercase().contains("inf") => Err("non-finite number"),
        Ok(_) => Err("out-of-range number"),
        Err(_) => Err("malformed number"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(name: &str, text: &str) -> Node {
        let mut n = Node::new(name, 12, 13);
        n.text = text.to_string();
        n
    }

    #[test]
    fn tree_floats_trims_padding() {
        let n = node("Position", "\n  0 -1.5\t 2e1  ");
        assert_eq!(n.vec3(Path::new("s.xml")).unwrap(), Vec3::new(0.0, -1.5, 20.0));
    }

    #[test]
    fn tree_malformed_number_names_element_and_text() {
        let e = node("Radius", " abc ").float(Path::new("scene.xml")).unwrap_err();
        assert_eq!(e.to_string(), "scene.xml:12:13: <Radius>: malformed number 'abc'");
        let e = node("Radius", "nan").float(Path::new("s.xml")).unwrap_err();
        assert_eq!(e.to_string(), "s.xml:12:13: <Radius>: non-finite number 'nan'");
        let e = node("Radius", "-inf").float(Path::new("s.xml")).unwrap_err();
        assert_eq!(e.to_string(), "s.xml:12:13: <Radius>: non-finite number '-inf'");
        let e = node("Radius", "1e39").float(Path::new("s.xml")).unwrap_err();
        assert_eq!(e.to_string(), "s.xml:12:13: <Radius>: out-of-range number '1e39'");
    }

    #[test]
    fn tree_floats_n_counts_and_tolerates_extra_when_asked() {
        let p = Path::new("s.xml");
        let n = node("NearPlane", "-1 1 -1 1 10");
        assert_eq!(n.floats_n(4, true, p).unwrap(), vec![-1.0, 1.0, -1.0, 1.0]);
        let e = n.floats_n(4, false, p).unwrap_err();
        assert_eq!(e.to_string(), "s.xml:12:13: <NearPlane>: expected 4 numbers, found 5");
    }

    #[test]
    fn tree_unused_reports_unread_elements_and_attributes_once() {
        let mut root = node("Scene", "");
        let mut cam = node("Camera", "");
        cam.attrs.push(Attr::new("id", "1", 3, 5));
        cam.attrs.push(Attr::new("odd", "x", 3, 12));
        cam.children.push(node("Position", "0 0 0"));
        root.children.push(cam);
        let mut junk = node("Junk", "");
        junk.children.push(node("Inner", ""));
        root.children.push(junk);
        let c = root.child("Camera").unwrap();
        c.attr("id");
        let names: Vec<String> = root
            .unused()
            .iter()
            .map(|u| match u {
                Unused::Element(n, p) => format!("{p}/{}", n.name),
                Unused::Attr(a, p) => format!("{p}@{}", a.name),
            })
            .collect();
        assert_eq!(names, ["Camera@odd", "Camera/Position", "Scene/Junk"]);
    }
}
