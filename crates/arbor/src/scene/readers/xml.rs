//! METU XML scene files to the element tree ([`super::tree`]), with roxmltree.
//!
//! Entity declarations (`<!ENTITY>`) are refused: no scene format uses them (no course file has a DTD),
//! and roxmltree bounds only the depth and count of references, not the text they expand to, so a 53 KB
//! file of two levels expands to gigabytes. With none declared, only the five predefined entities and
//! character references remain, each one character.
//!
//! Positions come from the document's byte ranges. roxmltree's own `text_pos_at` rescans the text
//! from the start on every call, which is quadratic on the multi-megabyte files with inline vertex data;
//! a table of line starts turns each lookup into a binary search, and the column is counted on from the
//! previous lookup, since the tree is walked in document order and a scene may be one long line.

use std::path::Path;

use super::tree::{Attr, Node};
use crate::{Error, Location, Result};

/// Parses `text` (the content of `path`) into the tree of its root element.
pub fn parse(text: &str, path: &Path) -> Result<Node> {
    let opts = roxmltree::ParsingOptions { allow_dtd: true, ..Default::default() };
    let mut lines = LineIndex::new(text);
    let syntax_error = |e: roxmltree::Error, lines: &mut LineIndex<'_>| {
        let pos = e.pos();
        let msg = e.to_string();
        // roxmltree appends the position to its message; the location already says it.
        let msg = msg.strip_suffix(&format!(" at {}:{}", pos.row, pos.col)).unwrap_or(&msg);
        // A truncated file ends where the text ends, not at the 1:1 roxmltree reports.
        let (row, col) = match e {
            roxmltree::Error::UnexpectedEndOfStream | roxmltree::Error::UnclosedRootNode => lines.pos(text.len()),
            _ => (pos.row, pos.col),
        };
        Error::input(Location::at(path, row, col), format!("XML syntax error: {msg}"))
    };
    // roxmltree recurses once per nesting level and would overflow the stack on a hostile file before
    // `convert` could refuse it, and expands entities without bound. Errors stay in document order: a
    // syntax error before the refused element or declaration is still the one reported, found by parsing
    // only the text before it.
    if let Some((at, refused)) = prescan(text) {
        // The text stops at `at`: an error there (an unclosed root, an unfinished DOCTYPE) is the cut's.
        match roxmltree::Document::parse_with_options(&text[..at], opts) {
            Err(roxmltree::Error::UnexpectedEndOfStream | roxmltree::Error::UnclosedRootNode) | Ok(_) => {}
            Err(e) if (e.pos().row, e.pos().col) == lines.pos(at) => {}
            Err(e) => return Err(syntax_error(e, &mut lines)),
        }
        return Err(match refused {
            Refused::TooDeep => nested_too_deep(path, lines.pos(at)),
            Refused::Entity => {
                let (line, col) = lines.pos(at);
                let msg = "entity declarations (<!ENTITY>) are not supported: no scene format uses them";
                Error::input(Location::at(path, line, col), msg)
            }
        });
    }
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| syntax_error(e, &mut lines))?;
    convert(doc.root_element(), &mut lines, 0, path)
}

/// Deeper than any scene needs; the tree is walked recursively, so a hostile file must not nest
/// without bound (serde_json applies a similar limit, 128, to JSON).
const MAX_DEPTH: usize = 128;

fn convert(e: roxmltree::Node<'_, '_>, lines: &mut LineIndex<'_>, depth: usize, path: &Path) -> Result<Node> {
    let (line, col) = lines.pos(e.range().start);
    if depth > MAX_DEPTH {
        return Err(nested_too_deep(path, (line, col)));
    }
    let mut node = Node::new(e.tag_name().name(), line, col);
    for a in e.attributes() {
        let (line, col) = lines.pos(a.range().start);
        node.attrs.push(Attr::new(a.name(), a.value(), line, col));
    }
    for c in e.children() {
        if c.is_element() {
            node.children.push(convert(c, lines, depth + 1, path)?);
        } else if c.is_text() {
            node.text.push_str(c.text().unwrap_or(""));
            // Text split by a child element or a comment must not fuse two numbers.
            node.text.push(' ');
        }
    }
    Ok(node)
}

fn nested_too_deep(path: &Path, (line, col): (u32, u32)) -> Error {
    Error::input(Location::at(path, line, col), format!("elements nested more than {MAX_DEPTH} deep"))
}

/// What the scan before parsing refuses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Refused {
    /// An element with more than [`MAX_DEPTH`] open ancestors.
    TooDeep,
    /// An entity declaration in the DOCTYPE.
    Entity,
}

/// The byte offset of the first element with more than [`MAX_DEPTH`] open ancestors or of the first
/// entity declaration, found by a forward scan that tokenizes only as far as roxmltree's nesting goes.
/// Where the scan gives up (an unterminated comment, an unknown declaration), roxmltree stops with a
/// syntax error at the same place, so nothing deeper is ever parsed and no entity declared.
fn prescan(text: &str) -> Option<(usize, Refused)> {
    let b = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while let Some(lt) = text.get(i..)?.find('<') {
        let at = i + lt;
        let rest = &b[at..];
        i = if rest.starts_with(b"<!--") {
            after(text, at + 4, "-->")?
        } else if rest.starts_with(b"<![CDATA[") {
            after(text, at + 9, "]]>")?
        } else if rest.starts_with(b"<?") {
            after(text, at + 2, "?>")?
        } else if rest.starts_with(b"<!DOCTYPE") {
            match doctype(text, at + 9)? {
                Ok(end) => end,
                Err(entity) => return Some((entity, Refused::Entity)),
            }
        } else if rest.starts_with(b"<!") {
            return None;
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            after(text, at + 2, ">")?
        } else {
            if depth > MAX_DEPTH {
                return Some((at, Refused::TooDeep));
            }
            let end = tag_end(text, at + 1)?;
            if b[end - 2] != b'/' {
                depth += 1;
            }
            end
        };
    }
    None
}

/// The offset just past the first `end` at or after `from`.
fn after(text: &str, from: usize, end: &str) -> Option<usize> {
    Some(from + text.get(from..)?.find(end)? + end.len())
}

/// The offset just past the quoted literal whose opening quote (`"` or `'`) is at `at`.
fn after_quoted(text: &str, at: usize) -> Option<usize> {
    after(text, at + 1, if text.as_bytes()[at] == b'"' { "\"" } else { "'" })
}

/// The offset just past the `>` closing a tag, skipping quoted attribute values (which may hold `>`).
fn tag_end(text: &str, mut i: usize) -> Option<usize> {
    loop {
        let at = i + text.get(i..)?.find(['>', '"', '\''])?;
        match text.as_bytes()[at] {
            b'>' => return Some(at + 1),
            _ => i = after_quoted(text, at)?,
        }
    }
}

/// The end of a DOCTYPE whose name starts at `i` (`Ok`), or the offset of its first entity declaration
/// (`Err`). Follows roxmltree's grammar: quoted literals in the external ID, other declarations up to the
/// first `>` whatever their quotes.
fn doctype(text: &str, mut i: usize) -> Option<Result<usize, usize>> {
    let b = text.as_bytes();
    loop {
        let at = i + text.get(i..)?.find(['>', '[', '"', '\''])?;
        match b[at] {
            b'>' => return Some(Ok(at + 1)),
            b'[' => {
                i = at + 1;
                break;
            }
            _ => i = after_quoted(text, at)?,
        }
    }
    loop {
        let at = i + text.get(i..)?.find(|c: char| !c.is_ascii_whitespace())?;
        let rest = &b[at..];
        if rest.starts_with(b"<!ENTITY") {
            return Some(Err(at));
        }
        i = if rest.starts_with(b"<!--") {
            after(text, at + 4, "-->")?
        } else if rest.starts_with(b"<?") {
            after(text, at + 2, "?>")?
        } else if rest.starts_with(b"<!") {
            after(text, at + 2, ">")?
        } else if rest.starts_with(b"]") {
            return Some(Ok(after(text, at + 1, ">")?));
        } else {
            return None;
        };
    }
}

/// Byte offset to 1-based line and column (in characters).
struct LineIndex<'a> {
    text: &'a str,
    starts: Vec<usize>,
    /// The last offset looked up and its column (0-based): a later offset on the same line counts
    /// only the characters in between.
    last: (usize, usize),
    /// Bytes counted over, so that a test can hold the walk to linear work.
    #[cfg(test)]
    scanned: usize,
}

impl<'a> LineIndex<'a> {
    fn new(text: &'a str) -> Self {
        let starts = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
        LineIndex {
            text,
            starts,
            last: (0, 0),
            #[cfg(test)]
            scanned: 0,
        }
    }
    fn pos(&mut self, byte: usize) -> (u32, u32) {
        let line = self.starts.partition_point(|&s| s <= byte).max(1) - 1;
        let start = self.starts[line];
        let (from, before) = match self.last {
            (b, col) if (start..=byte).contains(&b) => (b, col),
            _ => (start, 0),
        };
        let col = match self.text.get(from..byte) {
            Some(s) => {
                #[cfg(test)]
                {
                    self.scanned += s.len();
                }
                let col = before + s.chars().count();
                self.last = (byte, col);
                col
            }
            None => 0,
        };
        (line as u32 + 1, col as u32 + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xml_positions_of_elements_and_attributes() {
        let text = "<Scene>\n  <Camera id=\"1\">\n    <Position> 0 0 1 </Position>\n  </Camera>\n</Scene>";
        let root = parse(text, Path::new("s.xml")).unwrap();
        assert_eq!((root.name.as_str(), root.line, root.col), ("Scene", 1, 1));
        let cam = &root.children[0];
        assert_eq!((cam.line, cam.col), (2, 3));
        assert_eq!((cam.attrs[0].line, cam.attrs[0].col), (2, 11));
        let pos = &cam.children[0];
        assert_eq!((pos.line, pos.col, pos.trimmed()), (3, 5, "0 0 1"));
    }

    #[test]
    fn xml_syntax_error_has_line_and_column() {
        let e = parse("<Scene>\n  <A>1</B>\n</Scene>", Path::new("bad.xml")).unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("bad.xml:2:"), "{s}");
        assert!(s.contains("XML syntax error"), "{s}");
    }

    #[test]
    fn xml_truncated_file_is_located_at_its_end() {
        let e = parse("<Scene>\n  <A>1</A>\n  <B", Path::new("cut.xml")).unwrap_err();
        assert_eq!(e.to_string(), "cut.xml:3:5: XML syntax error: the root node was opened but never closed");
        let e = parse("<Scene>\n  <A x=\"1", Path::new("cut.xml")).unwrap_err();
        assert_eq!(e.to_string(), "cut.xml:2:10: XML syntax error: unexpected end of stream");
        let e = parse("<Scene>\n  <A>1</A>\n", Path::new("cut.xml")).unwrap_err();
        assert_eq!(e.to_string(), "cut.xml:3:1: XML syntax error: the root node was opened but never closed");
    }

    #[test]
    fn xml_deep_nesting_is_an_error_not_a_stack_overflow() {
        let text = format!("{}{}", "<a>".repeat(1000), "</a>".repeat(1000));
        let e = parse(&text, Path::new("deep.xml")).unwrap_err();
        assert_eq!(e.to_string(), "deep.xml:1:388: elements nested more than 128 deep");
    }

    #[test]
    fn xml_positions_on_a_long_line_count_characters_in_any_order() {
        let line = "<Sphere id=\"ö\"> <Radius>é 1</Radius> </Sphere> ".repeat(50);
        let text = format!("<Scene>\n{line}\n{line}</Scene>");
        let direct = |byte: usize| {
            let start = text[..byte].rfind('\n').map_or(0, |i| i + 1);
            let line = text[..byte].matches('\n').count() + 1;
            (line as u32, text[start..byte].chars().count() as u32 + 1)
        };
        let starts: Vec<usize> = text.match_indices('<').map(|(i, _)| i).collect();
        let mut lines = LineIndex::new(&text);
        // Document order, then backwards, then jumping between lines.
        let order = starts.iter().chain(starts.iter().rev()).chain(starts.iter().step_by(7).rev().step_by(3));
        for &byte in order.chain([&text.len(), &0]) {
            assert_eq!(lines.pos(byte), direct(byte), "byte {byte}");
        }
    }

    #[test]
    fn xml_positions_in_document_order_scan_the_text_once() {
        let text = format!("<Scene>{}</Scene>", "<Sphere id=\"ö\"><Radius>1</Radius></Sphere>".repeat(1000));
        let mut lines = LineIndex::new(&text);
        for (byte, _) in text.match_indices('<') {
            lines.pos(byte);
        }
        assert!(lines.scanned <= text.len(), "{} bytes scanned for {}", lines.scanned, text.len());
    }

    #[test]
    fn xml_nesting_too_deep_for_the_parser_is_refused_before_parsing() {
        let n = 20_000;
        let text = format!("{}{}", "<a>".repeat(n), "</a>".repeat(n));
        let e = parse(&text, Path::new("deep.xml")).unwrap_err();
        assert_eq!(e.to_string(), "deep.xml:1:388: elements nested more than 128 deep");
        let text = format!("<Scene>\n  <Cameras/>\n  {}{}\n</Scene>\n", "<Foo>".repeat(n), "</Foo>".repeat(n));
        let e = parse(&text, Path::new("scene.xml")).unwrap_err();
        assert_eq!(e.to_string(), "scene.xml:3:643: elements nested more than 128 deep");
    }

    #[test]
    fn xml_depth_scan_skips_what_is_not_an_element() {
        // A root and 128 levels below it are allowed; no `<` below that which is not an element counts.
        let inner = "<!-- <a> --><![CDATA[<a>]]><?pi <a>?><b x=\"a>\" y='/>'/>";
        let text = format!(
            "<?xml version=\"1.0\"?><!DOCTYPE a [<!-- <a> <!ENTITY e 'x'> --><!ELEMENT a ANY>]>{}{inner}{}",
            "<a>".repeat(128),
            "</a>".repeat(128)
        );
        assert_eq!(prescan(&text), None);
        parse(&text, Path::new("s.xml")).unwrap();
        let text = text.replacen("]><a>", "]><a><a>", 1);
        let e = parse(&text, Path::new("s.xml")).unwrap_err();
        assert!(e.to_string().ends_with(": elements nested more than 128 deep"), "{e}");
    }

    #[test]
    fn xml_entity_declarations_are_refused_before_parsing() {
        // Two levels, about 12 GB of text once expanded (roxmltree allows 255 references per reference).
        let big = "x".repeat(20_000);
        let text = format!(
            "<?xml version=\"1.0\"?>\n<!DOCTYPE Scene [\n  <!ELEMENT Scene ANY>\n  <!ENTITY a \"{big}\">\n  \
             <!ENTITY b \"{}\">\n]>\n<Scene>{}</Scene>\n",
            "&a;".repeat(255),
            "&b;".repeat(2400)
        );
        let e = parse(&text, Path::new("bomb.xml")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "bomb.xml:4:3: entity declarations (<!ENTITY>) are not supported: no scene format uses them"
        );
        // Parameter and external entities too, and one inside a deep value is found before the depth.
        let deep = format!("{}{}", "<a>".repeat(20_000), "</a>".repeat(20_000));
        for decl in ["<!ENTITY % p 'x'>", "<!ENTITY e SYSTEM \"file:///etc/passwd\">", &format!("<!ENTITY e '{deep}'>")]
        {
            let text = format!("<!DOCTYPE r [\n<!ELEMENT r ANY> {decl}\n]>\n<r/>");
            let e = parse(&text, Path::new("ent.xml")).unwrap_err();
            assert!(e.to_string().starts_with("ent.xml:2:18: entity declarations"), "{e}");
        }
        // The five predefined entities and character references still read.
        let root = parse("<!DOCTYPE r><r a=\"&lt;&#65;\">&amp;&gt;&quot;&apos;&#x42;</r>", Path::new("s.xml")).unwrap();
        assert_eq!((root.attrs[0].value.as_str(), root.trimmed()), ("<A", "&>\"'B"));
    }

    #[test]
    fn xml_syntax_error_before_an_entity_declaration_is_reported_first() {
        let e = parse("<!DOCTYPE 1r [\n<!ENTITY e 'x'>\n]>\n<r>&e;</r>", Path::new("bad.xml")).unwrap_err();
        assert!(e.to_string().starts_with("bad.xml:1:11: XML syntax error"), "{e}");
    }

    #[test]
    fn xml_syntax_error_before_deep_nesting_is_reported_first() {
        let text = format!("<r><b x=1/>{}{}</r>", "<a>".repeat(20_000), "</a>".repeat(20_000));
        let e = parse(&text, Path::new("bad.xml")).unwrap_err();
        assert!(e.to_string().starts_with("bad.xml:1:9: XML syntax error: expected a quote"), "{e}");
    }

    #[test]
    fn xml_text_around_comments_keeps_numbers_apart() {
        let root = parse("<V>1 2<!-- c -->3</V>", Path::new("s.xml")).unwrap();
        assert_eq!(root.trimmed().split_whitespace().count(), 3);
    }
}
