//! The generic element reader, one value at a time from a [`Source`]: the ASCII data, and binary
//! layouts without a fast path (lists in the vertex element, faces with extra properties, tristrips).

use std::path::Path;

use super::{index_error, Element, Kind, Out, Role, Ty};
use crate::mesh_io::{fan, parse_num, shown, too_few_vertices, Lines, Tokens};
use crate::{Error, Location, Result};

/// Element data, value by value: ASCII tokens or binary bytes.
pub(super) trait Source<'a> {
    /// Starts entry `i` of `e`.
    fn begin(&mut self, e: &'a Element, i: u64) -> Result<()>;
    fn value(&mut self, ty: Ty) -> Result<f64>;
    fn int(&mut self, ty: Ty) -> Result<i64>;
    fn end(&mut self) -> Result<()>;
    /// Where the last value was.
    fn here(&self) -> Location;
    /// Where the current entry starts.
    fn start(&self) -> Location;
}

/// The generic path: any element, any layout, one value at a time.
pub(super) fn read_element<'a, S: Source<'a>>(
    src: &mut S,
    e: &'a Element,
    role: &Role,
    nv: u64,
    out: &mut Out,
) -> Result<()> {
    let mut vals = [0.0f32; 8];
    let mut poly = Vec::new();
    for i in 0..e.count {
        src.begin(e, i)?;
        for (k, p) in e.props.iter().enumerate() {
            match (p.kind, role) {
                (Kind::Scalar(ty), Role::Vertex(plan)) => {
                    let v = src.value(ty)?;
                    if let Some(slot) = plan.slots[k] {
                        vals[slot] = v as f32;
                    }
                }
                (Kind::Scalar(ty), _) => {
                    src.value(ty)?;
                }
                (Kind::List { count, item }, Role::Faces(j)) if *j == k => {
                    read_polygon(src, (count, item), i, nv, &mut poly)?;
                    fan(&mut out.indices, &poly);
                }
                (Kind::List { count, item }, Role::Strips(j)) if *j == k => {
                    read_strips(src, (count, item), i, nv, &mut poly, &mut out.indices)?;
                }
                (Kind::List { count, item }, _) => {
                    for _ in 0..list_len(src, count)? {
                        src.value(item)?;
                    }
                }
            }
        }
        if let Role::Vertex(plan) = role {
            plan.push(&vals, out).map_err(|s| plan.non_finite(e, i, s, vals[s], src.start()))?;
        }
        src.end()?;
    }
    Ok(())
}

/// Face `i`'s index list into `poly`.
fn read_polygon<'a, S: Source<'a>>(
    src: &mut S,
    (count, item): (Ty, Ty),
    i: u64,
    nv: u64,
    poly: &mut Vec<u32>,
) -> Result<()> {
    let n = list_len(src, count)?;
    if n < 3 {
        let msg = too_few_vertices(&format!("face {i}"), n);
        return Err(Error::input(src.start(), msg));
    }
    poly.clear();
    for _ in 0..n {
        let idx = src.int(item)?;
        if idx < 0 || idx as u64 >= nv {
            return Err(index_error("face", i, idx, nv, src.here()));
        }
        poly.push(idx as u32);
    }
    Ok(())
}

/// Entry `i` of a `tristrips` element: strips separated by -1.
fn read_strips<'a, S: Source<'a>>(
    src: &mut S,
    (count, item): (Ty, Ty),
    i: u64,
    nv: u64,
    strip_buf: &mut Vec<u32>,
    out: &mut Vec<[u32; 3]>,
) -> Result<()> {
    strip_buf.clear();
    for _ in 0..list_len(src, count)? {
        match src.int(item)? {
            -1 => {
                strip(strip_buf, out);
                strip_buf.clear();
            }
            idx if idx < 0 || idx as u64 >= nv => {
                return Err(index_error("tristrips", i, idx, nv, src.here()));
            }
            idx => strip_buf.push(idx as u32),
        }
    }
    strip(strip_buf, out);
    Ok(())
}

fn list_len<'a, S: Source<'a>>(src: &mut S, ty: Ty) -> Result<u64> {
    let n = src.int(ty)?;
    u64::try_from(n).map_err(|_| Error::input(src.here(), format!("negative list length {n}")))
}

/// Appends the triangles of one strip: orientation alternates, and the degenerate triangles that
/// stitch strips together are dropped.
fn strip(s: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 2..s.len() {
        let t = if k % 2 == 0 { [s[k - 2], s[k - 1], s[k]] } else { [s[k - 1], s[k - 2], s[k]] };
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            out.push(t);
        }
    }
}

pub(super) struct Ascii<'a> {
    path: &'a Path,
    lines: Lines<'a>,
    toks: Tokens<'a>,
    line: u32,
    col: u32,
    elem: Option<(&'a Element, u64)>,
}

impl<'a> Ascii<'a> {
    pub(super) fn new(path: &'a Path, body: &'a [u8], first_line: u32) -> Self {
        let (lines, toks) = (Lines::new(body, first_line), Tokens::new(&[]));
        Ascii { path, lines, toks, line: first_line, col: 0, elem: None }
    }
    fn token(&mut self) -> Result<&'a [u8]> {
        match self.toks.next() {
            Some((col, tok)) => {
                self.col = col;
                Ok(tok)
            }
            None => {
                let (name, i) = self.elem.map_or(("", 0), |(e, i)| (e.name.as_str(), i));
                let loc = Location::at(self.path, self.line, self.toks.end_col());
                Err(Error::input(loc, format!("line ends inside {name} {i}")))
            }
        }
    }
}

impl<'a> Source<'a> for Ascii<'a> {
    fn begin(&mut self, e: &'a Element, i: u64) -> Result<()> {
        self.elem = Some((e, i));
        for (n, line) in self.lines.by_ref() {
            let mut toks = Tokens::new(line);
            if toks.next().is_some() {
                (self.line, self.toks) = (n, Tokens::new(line));
                return Ok(());
            }
        }
        let msg = format!("file ends before {} {i} of {}", e.name, e.count);
        Err(Error::input(Location::file(self.path), msg))
    }
    fn value(&mut self, ty: Ty) -> Result<f64> {
        let tok = self.token()?;
        match ty {
            Ty::F32 => parse_num::<f32>(tok, self.path, self.line, self.col).map(f64::from),
            Ty::F64 => parse_num(tok, self.path, self.line, self.col),
            _ => self.int_of(tok).map(|v| v as f64),
        }
    }
    fn int(&mut self, _ty: Ty) -> Result<i64> {
        let tok = self.token()?;
        self.int_of(tok)
    }
    fn end(&mut self) -> Result<()> {
        let Some((col, tok)) = self.toks.next() else {
            return Ok(());
        };
        let (name, i) = self.elem.map_or(("", 0), |(e, i)| (e.name.as_str(), i));
        let msg = format!("unexpected value `{}` after the end of {name} {i}", shown(tok));
        Err(Error::input(Location::at(self.path, self.line, col), msg))
    }
    fn here(&self) -> Location {
        Location::at(self.path, self.line, self.col)
    }
    fn start(&self) -> Location {
        Location::at(self.path, self.line, 0)
    }
}

impl Ascii<'_> {
    /// Checks that nothing but blank lines follows the last element: more data means a header count
    /// is too small, and the rest of the file would be dropped without a word.
    pub(super) fn finish(&mut self) -> Result<()> {
        for (n, line) in self.lines.by_ref() {
            if let Some((col, tok)) = Tokens::new(line).next() {
                let msg = format!("unexpected `{}` after the data of the last element", shown(tok));
                return Err(Error::input(Location::at(self.path, n, col), msg));
            }
        }
        Ok(())
    }

    fn int_of(&self, tok: &[u8]) -> Result<i64> {
        parse_num(tok, self.path, self.line, self.col)
    }
}
