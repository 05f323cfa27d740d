//! The PLY header: `ply`, `format`, `element`, `property`, `comment`/`obj_info`, `end_header`, and the
//! check of the counts it claims against the data that follows.

use std::path::Path;

use crate::mesh_io::{count_lines, parse_num, shown, Lines, Tokens};
use crate::{Error, Location, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    pub(super) fn parse(s: &[u8]) -> Option<Ty> {
        Some(match s {
            b"char" | b"int8" => Ty::I8,
            b"uchar" | b"uint8" => Ty::U8,
            b"short" | b"int16" => Ty::I16,
            b"ushort" | b"uint16" => Ty::U16,
            b"int" | b"int32" => Ty::I32,
            b"uint" | b"uint32" => Ty::U32,
            b"float" | b"float32" => Ty::F32,
            b"double" | b"float64" => Ty::F64,
            _ => return None,
        })
    }
    pub(super) fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
    pub(super) fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Clone, Copy)]
pub(super) enum Kind {
    Scalar(Ty),
    List { count: Ty, item: Ty },
}

pub(super) struct Property {
    pub(super) name: String,
    pub(super) kind: Kind,
}

pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
    /// Header line, for errors about the element as a whole.
    pub(super) line: u32,
}

impl Element {
    /// Bytes per entry when every property is a scalar.
    pub(super) fn stride(&self) -> Option<usize> {
        self.props.iter().try_fold(0, |acc, p| match p.kind {
            Kind::Scalar(t) => Some(acc + t.size()),
            Kind::List { .. } => None,
        })
    }
    /// The fewest bytes one entry can take (lists empty).
    pub(super) fn min_size(&self) -> u64 {
        let size = |p: &Property| match p.kind {
            Kind::Scalar(t) | Kind::List { count: t, .. } => t.size() as u64,
        };
        self.props.iter().map(size).sum()
    }
}

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Format {
    Ascii,
    Le,
    Be,
}

pub(super) struct Header {
    pub(super) format: Format,
    pub(super) elements: Vec<Element>,
    /// Byte offset and line number where the data starts.
    pub(super) body: usize,
    pub(super) body_line: u32,
}
const FORMATS: &str = "expected ascii, binary_little_endian or binary_big_endian";

pub(super) fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let err = |line, col, msg: String| Error::input(Location::at(path, line, col), msg);
    let mut lines = Lines::new(bytes, 1);
    if !matches!(lines.next(), Some((_, l)) if l.trim_ascii() == b"ply") {
        return Err(err(1, 0, "not a PLY file (the first line must be `ply`)".into()));
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    while let Some((n, line)) = lines.next() {
        let mut toks = Tokens::new(line);
        let Some((_, kw)) = toks.next() else { continue };
        match kw {
            b"comment" | b"obj_info" => {}
            b"format" => {
                let (col, f) = toks.next().unwrap_or((toks.end_col(), b""));
                format = Some(match f {
                    b"ascii" => Format::Ascii,
                    b"binary_little_endian" => Format::Le,
                    b"binary_big_endian" => Format::Be,
                    _ => {
                        let msg = format!("unknown format `{}` ({FORMATS})", shown(f));
                        return Err(err(n, col, msg));
                    }
                });
            }
            b"element" => {
                let (Some((_, name)), Some((col, count)), None) = (toks.next(), toks.next(), toks.next()) else {
                    let msg = "malformed element line (expected `element <name> <count>`)";
                    return Err(err(n, 0, msg.into()));
                };
                elements.push(Element {
                    name: String::from_utf8_lossy(name).into_owned(),
                    count: parse_num(count, path, n, col)?,
                    props: Vec::new(),
                    line: n,
                });
            }
            b"property" => {
                let Some(elem) = elements.last_mut() else {
                    return Err(err(n, 0, "property before any element".into()));
                };
                elem.props.push(parse_property(toks, path, n)?);
            }
            b"end_header" => {
                let Some(format) = format else {
                    return Err(err(n, 0, "no `format` line before `end_header`".into()));
                };
                let body = bytes.len() - lines.rest().len();
                let body_line = lines.next_number();
                return Ok(Header { format, elements, body, body_line });
            }
            _ => return Err(err(n, 1, format!("unknown header keyword `{}`", shown(kw)))),
        }
    }
    Err(Error::input(Location::file(path), "header has no `end_header` line"))
}

fn parse_property(mut toks: Tokens, path: &Path, n: u32) -> Result<Property> {
    let err = |col, msg: String| Error::input(Location::at(path, n, col), msg);
    let bad = || {
        let msg = "malformed property line (expected `property <type> <name>` \
                   or `property list <count type> <item type> <name>`)";
        err(0, msg.into())
    };
    let ty =
        |(col, t): (u32, &[u8])| Ty::parse(t).ok_or_else(|| err(col, format!("unknown property type `{}`", shown(t))));
    let first = toks.next().ok_or_else(bad)?;
    let kind = if first.1 == b"list" {
        let (col, c) = toks.next().ok_or_else(bad)?;
        let count = ty((col, c))?;
        if !count.is_int() {
            let msg = format!("list count type must be an integer type, not `{}`", shown(c));
            return Err(err(col, msg));
        }
        let item = ty(toks.next().ok_or_else(bad)?)?;
        Kind::List { count, item }
    } else {
        Kind::Scalar(ty(first)?)
    };
    let (_, name) = toks.next().ok_or_else(bad)?;
    if toks.next().is_some() {
        return Err(bad());
    }
    let name = String::from_utf8_lossy(name).into_owned();
    Ok(Property { name, kind })
}

/// Rejects counts the data cannot hold, before anything is allocated for them.
pub(super) fn check_sizes(h: &Header, bytes: &[u8], path: &Path) -> Result<()> {
    let body = &bytes[h.body..];
    let (left, unit) = match h.format {
        Format::Ascii => (u128::from(count_lines(body)), "lines"),
        _ => (body.len() as u128, "bytes"),
    };
    let mut used = 0u128;
    for e in &h.elements {
        let need = match h.format {
            Format::Ascii => u128::from(e.count),
            _ => u128::from(e.count) * u128::from(e.min_size()),
        };
        if used + need > left {
            let rest = left - used;
            let msg = match h.format {
                Format::Ascii => {
                    format!("element `{}` claims {} entries but only {rest} lines are left for it", e.name, e.count)
                }
                _ => format!(
                    "element `{}` claims {} entries (at least {need} {unit}) \
                     but only {rest} {unit} are left for it",
                    e.name, e.count
                ),
            };
            return Err(Error::input(Location::at(path, e.line, 0), msg));
        }
        used += need;
    }
    Ok(())
}
