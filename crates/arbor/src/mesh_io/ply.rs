//! PLY reader (Turk 1994, the Stanford polygon format): ASCII, binary little- and big-endian.
//!
//! A PLY file is a text header listing elements (`element vertex 8`) and their properties (`property
//! float x`, `property list uchar int vertex_indices`), then the element data in header order. We read
//! `vertex` (x y z; nx ny nz as normals when all three are present; u v, s t or texture_u texture_v as
//! texture coordinates), `face` (list `vertex_indices` or `vertex_index`, polygons fan-triangulated) and
//! `tristrips` (strips separated by -1, orientation alternating, the degenerate stitching triangles
//! dropped). Every other element and property is skipped, lists included.
//!
//! Before any allocation the header's counts are checked against the data that follows: each element
//! needs at least the size of its scalars and list counts in binary, and one line in ASCII. So a
//! 100-byte file claiming 10^12 vertices is an error, not an out-of-memory abort.
//!
//! Speed: the property layout is worked out once from the header. In binary files an element of
//! scalars only (the usual vertex) is a fixed-stride record read with precomputed offsets, and a face
//! element made of one index list (the usual `list uchar int`) has its own loop, monomorphised for the
//! common count and index types, so neither dispatches per property. Anything else goes through the
//! generic path, one [`Source`] call per value. Nothing is allocated per vertex or per face.

use std::marker::PhantomData;
use std::path::Path;

use super::{count_lines, fan, parse_num, shown, too_few_vertices, Lines, Tokens};
use crate::geometry::TriangleMesh;
use crate::math::{Vec2, Vec3};
use crate::{Error, Location, Result};

/// Parses a PLY file already in memory; `path` is only used in error messages.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<TriangleMesh> {
    let header = parse_header(bytes, path)?;
    check_sizes(&header, bytes, path)?;
    let (roles, nv) = plan_roles(&header, path)?;
    let faces: u64 = header
        .elements
        .iter()
        .filter(|e| e.name == "face")
        .map(|e| e.count)
        .sum();
    let mut out = Out {
        positions: Vec::with_capacity(nv as usize),
        normals: Vec::new(),
        uvs: Vec::new(),
        indices: Vec::with_capacity(faces as usize),
    };
    let plan = roles.iter().find_map(|r| match r {
        Role::Vertex(p) => Some(p),
        _ => None,
    });
    let (has_normals, has_uvs) = plan.map_or((false, false), |p| (p.normals, p.uvs));
    if has_normals {
        out.normals.reserve(nv as usize);
    }
    if has_uvs {
        out.uvs.reserve(nv as usize);
    }
    match header.format {
        Format::Ascii => {
            let mut src = Ascii::new(path, &bytes[header.body..], header.body_line);
            for (e, role) in header.elements.iter().zip(&roles) {
                read_element(&mut src, e, role, nv, &mut out)?;
            }
        }
        Format::Le => read_binary::<Le>(bytes, &header, &roles, path, nv, &mut out)?,
        Format::Be => read_binary::<Be>(bytes, &header, &roles, path, nv, &mut out)?,
    }
    Ok(TriangleMesh {
        positions: out.positions,
        indices: out.indices,
        normals: has_normals.then_some(out.normals),
        uvs: has_uvs.then_some(out.uvs),
    })
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
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
    fn parse(s: &[u8]) -> Option<Ty> {
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
    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Clone, Copy)]
enum Kind {
    Scalar(Ty),
    List { count: Ty, item: Ty },
}

struct Property {
    name: String,
    kind: Kind,
}

struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    /// Header line, for errors about the element as a whole.
    line: u32,
}

impl Element {
    /// Bytes per entry when every property is a scalar.
    fn stride(&self) -> Option<usize> {
        self.props.iter().try_fold(0, |acc, p| match p.kind {
            Kind::Scalar(t) => Some(acc + t.size()),
            Kind::List { .. } => None,
        })
    }
    /// The fewest bytes one entry can take (lists empty).
    fn min_size(&self) -> u64 {
        let size = |p: &Property| match p.kind {
            Kind::Scalar(t) | Kind::List { count: t, .. } => t.size() as u64,
        };
        self.props.iter().map(size).sum()
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Le,
    Be,
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset and line number where the data starts.
    body: usize,
    body_line: u32,
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let err = |line, col, msg: String| Error::input(Location::at(path, line, col), msg);
    let mut lines = Lines::new(bytes, 1);
    if !matches!(lines.next(), Some((_, l)) if l.trim_ascii() == b"ply") {
        return Err(err(
            1,
            0,
            "not a PLY file (the first line must be `ply`)".into(),
        ));
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
                        let msg = format!("unknown format `{}` (expected ascii, binary_little_endian or binary_big_endian)", shown(f));
                        return Err(err(n, col, msg));
                    }
                });
            }
            b"element" => {
                let (Some((_, name)), Some((col, count)), None) =
                    (toks.next(), toks.next(), toks.next())
                else {
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
                return Ok(Header {
                    format,
                    elements,
                    body,
                    body_line,
                });
            }
            _ => return Err(err(n, 1, format!("unknown header keyword `{}`", shown(kw)))),
        }
    }
    Err(Error::input(
        Location::file(path),
        "header has no `end_header` line",
    ))
}

fn parse_property(mut toks: Tokens, path: &Path, n: u32) -> Result<Property> {
    let err = |col, msg: String| Error::input(Location::at(path, n, col), msg);
    let bad = || {
        err(0, "malformed property line (expected `property <type> <name>` or `property list <count type> <item type> <name>`)".into())
    };
    let ty = |(col, t): (u32, &[u8])| {
        Ty::parse(t).ok_or_else(|| err(col, format!("unknown property type `{}`", shown(t))))
    };
    let first = toks.next().ok_or_else(bad)?;
    let kind = if first.1 == b"list" {
        let (col, c) = toks.next().ok_or_else(bad)?;
        let count = ty((col, c))?;
        if !count.is_int() {
            let msg = format!(
                "list count type must be an integer type, not `{}`",
                shown(c)
            );
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
fn check_sizes(h: &Header, bytes: &[u8], path: &Path) -> Result<()> {
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
                Format::Ascii => format!(
                    "element `{}` claims {} entries but only {rest} lines are left for it",
                    e.name, e.count
                ),
                _ => format!(
                    "element `{}` claims {} entries (at least {need} {unit}) but only {rest} {unit} are left for it",
                    e.name, e.count
                ),
            };
            return Err(Error::input(Location::at(path, e.line, 0), msg));
        }
        used += need;
    }
    Ok(())
}

/// What to do with each element.
enum Role {
    Vertex(VertexPlan),
    /// Faces or triangle strips, with the index of their index list property.
    Faces(usize),
    Strips(usize),
    Skip,
}

/// Where each vertex property goes: slots 0..3 position, 3..6 normal, 6..8 uv.
struct VertexPlan {
    slots: Vec<Option<usize>>,
    normals: bool,
    uvs: bool,
}

fn plan_roles(h: &Header, path: &Path) -> Result<(Vec<Role>, u64)> {
    let mut nv = None;
    let mut roles = Vec::with_capacity(h.elements.len());
    for e in &h.elements {
        let err = |msg: String| Error::input(Location::at(path, e.line, 0), msg);
        roles.push(match e.name.as_str() {
            "vertex" => {
                if nv.replace(e.count).is_some() {
                    return Err(err("a second `vertex` element".into()));
                }
                if e.count > u64::from(u32::MAX) {
                    return Err(err(format!(
                        "{} vertices do not fit in 32-bit indices",
                        e.count
                    )));
                }
                Role::Vertex(vertex_plan(e).map_err(err)?)
            }
            "face" => Role::Faces(index_list(e).map_err(err)?),
            "tristrips" => Role::Strips(index_list(e).map_err(err)?),
            _ => Role::Skip,
        });
    }
    let nv = nv.ok_or_else(|| Error::input(Location::file(path), "no `vertex` element"))?;
    Ok((roles, nv))
}

fn vertex_plan(e: &Element) -> std::result::Result<VertexPlan, String> {
    let mut slots = vec![None; e.props.len()];
    let mut found = [false; 8];
    for (slot_of, p) in slots.iter_mut().zip(&e.props) {
        let slot = match p.name.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "nx" => 3,
            "ny" => 4,
            "nz" => 5,
            "u" | "s" | "texture_u" => 6,
            "v" | "t" | "texture_v" => 7,
            _ => continue,
        };
        if matches!(p.kind, Kind::Scalar(_)) && !found[slot] {
            found[slot] = true;
            *slot_of = Some(slot);
        }
    }
    if let Some(axis) = (0..3).find(|&s| !found[s]) {
        let name = ["x", "y", "z"][axis];
        return Err(format!("element `vertex` has no scalar property `{name}`"));
    }
    let normals = found[3..6].iter().all(|&f| f);
    let uvs = found[6] && found[7];
    Ok(VertexPlan {
        slots,
        normals,
        uvs,
    })
}

fn index_list(e: &Element) -> std::result::Result<usize, String> {
    let is_index = |p: &Property| p.name == "vertex_indices" || p.name == "vertex_index";
    let Some(k) = e.props.iter().position(is_index) else {
        return Err(format!("element `{}` has no `vertex_indices` list", e.name));
    };
    match e.props[k].kind {
        Kind::List { item, .. } if item.is_int() => Ok(k),
        _ => Err(format!("`{}` must be a list of integers", e.props[k].name)),
    }
}

struct Out {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
}

impl VertexPlan {
    /// Stores one vertex, or returns the slot holding a non-finite value.
    #[inline]
    fn push(&self, v: &[f32; 8], out: &mut Out) -> std::result::Result<(), usize> {
        let used = if self.uvs {
            8
        } else if self.normals {
            6
        } else {
            3
        };
        if let Some(bad) = v[..used].iter().position(|x| !x.is_finite()) {
            // Partial attributes (u without v) are read but unused: their values do not matter.
            if bad < 3 || (bad < 6 && self.normals) || (bad >= 6 && self.uvs) {
                return Err(bad);
            }
        }
        out.positions.push(Vec3::new(v[0], v[1], v[2]));
        if self.normals {
            out.normals.push(Vec3::new(v[3], v[4], v[5]));
        }
        if self.uvs {
            out.uvs.push(Vec2::new(v[6], v[7]));
        }
        Ok(())
    }

    fn non_finite(&self, e: &Element, i: u64, slot: usize, val: f32, loc: Location) -> Error {
        let k = self
            .slots
            .iter()
            .position(|&s| s == Some(slot))
            .unwrap_or(0);
        let msg = format!("vertex {i}: non-finite {} ({val})", e.props[k].name);
        Error::input(loc, msg)
    }
}

fn index_error(what: &str, i: u64, idx: i64, nv: u64, loc: Location) -> Error {
    let msg = format!("{what} {i}: vertex index {idx} out of range (the file has {nv} vertices)");
    Error::input(loc, msg)
}

fn truncated(path: &Path, pos: usize, e: &Element, i: u64, need: usize, left: usize) -> Error {
    let msg = format!(
        "unexpected end of file in {} {i} of {} (needs {need} more bytes, {left} left)",
        e.name, e.count
    );
    Error::input(Location::byte(path, pos as u64), msg)
}

/// Element data, value by value: ASCII tokens or binary bytes.
trait Source<'a> {
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
fn read_element<'a, S: Source<'a>>(
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
                (Kind::List { count, item }, Role::Faces(j) | Role::Strips(j)) if *j == k => {
                    let n = list_len(src, count)?;
                    let what = if matches!(role, Role::Faces(_)) {
                        "face"
                    } else {
                        "tristrips"
                    };
                    if what == "face" && n < 3 {
                        let msg = too_few_vertices(&format!("face {i}"), n);
                        return Err(Error::input(src.start(), msg));
                    }
                    poly.clear();
                    for _ in 0..n {
                        let idx = src.int(item)?;
                        if idx == -1 && what == "tristrips" {
                            strip(&poly, &mut out.indices);
                            poly.clear();
                        } else if idx < 0 || idx as u64 >= nv {
                            return Err(index_error(what, i, idx, nv, src.here()));
                        } else {
                            poly.push(idx as u32);
                        }
                    }
                    if what == "face" {
                        fan(&mut out.indices, &poly);
                    } else {
                        strip(&poly, &mut out.indices);
                    }
                }
                (Kind::List { count, item }, _) => {
                    for _ in 0..list_len(src, count)? {
                        src.value(item)?;
                    }
                }
            }
        }
        if let Role::Vertex(plan) = role {
            plan.push(&vals, out)
                .map_err(|s| plan.non_finite(e, i, s, vals[s], src.start()))?;
        }
        src.end()?;
    }
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
        let t = if k % 2 == 0 {
            [s[k - 2], s[k - 1], s[k]]
        } else {
            [s[k - 1], s[k - 2], s[k]]
        };
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            out.push(t);
        }
    }
}

struct Ascii<'a> {
    path: &'a Path,
    lines: Lines<'a>,
    toks: Tokens<'a>,
    line: u32,
    col: u32,
    elem: Option<(&'a Element, u64)>,
}

impl<'a> Ascii<'a> {
    fn new(path: &'a Path, body: &'a [u8], first_line: u32) -> Self {
        let (lines, toks) = (Lines::new(body, first_line), Tokens::new(&[]));
        Ascii {
            path,
            lines,
            toks,
            line: first_line,
            col: 0,
            elem: None,
        }
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
        let msg = format!(
            "unexpected value `{}` after the end of {name} {i}",
            shown(tok)
        );
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
    fn int_of(&self, tok: &[u8]) -> Result<i64> {
        parse_num(tok, self.path, self.line, self.col)
    }
}

trait Order {
    fn u16(b: [u8; 2]) -> u16;
    fn u32(b: [u8; 4]) -> u32;
    fn u64(b: [u8; 8]) -> u64;
}
struct Le;
struct Be;
impl Order for Le {
    #[inline(always)]
    fn u16(b: [u8; 2]) -> u16 {
        u16::from_le_bytes(b)
    }
    #[inline(always)]
    fn u32(b: [u8; 4]) -> u32 {
        u32::from_le_bytes(b)
    }
    #[inline(always)]
    fn u64(b: [u8; 8]) -> u64 {
        u64::from_le_bytes(b)
    }
}
impl Order for Be {
    #[inline(always)]
    fn u16(b: [u8; 2]) -> u16 {
        u16::from_be_bytes(b)
    }
    #[inline(always)]
    fn u32(b: [u8; 4]) -> u32 {
        u32::from_be_bytes(b)
    }
    #[inline(always)]
    fn u64(b: [u8; 8]) -> u64 {
        u64::from_be_bytes(b)
    }
}

/// The first `N` bytes of `b`; callers have checked the length.
#[inline(always)]
fn arr<const N: usize>(b: &[u8]) -> [u8; N] {
    let mut a = [0; N];
    a.copy_from_slice(&b[..N]);
    a
}

#[inline]
fn read_f64<E: Order>(ty: Ty, b: &[u8]) -> f64 {
    match ty {
        Ty::F32 => f64::from(f32::from_bits(E::u32(arr(b)))),
        Ty::F64 => f64::from_bits(E::u64(arr(b))),
        _ => read_int::<E>(ty, b) as f64,
    }
}

#[inline]
fn read_int<E: Order>(ty: Ty, b: &[u8]) -> i64 {
    match ty {
        Ty::I8 => i64::from(b[0] as i8),
        Ty::U8 => i64::from(b[0]),
        Ty::I16 => i64::from(E::u16(arr(b)) as i16),
        Ty::U16 => i64::from(E::u16(arr(b))),
        Ty::I32 => i64::from(E::u32(arr(b)) as i32),
        Ty::U32 => i64::from(E::u32(arr(b))),
        Ty::F32 | Ty::F64 => read_f64::<E>(ty, b) as i64,
    }
}

struct Bin<'a, E> {
    path: &'a Path,
    bytes: &'a [u8],
    pos: usize,
    last: usize,
    start: usize,
    elem: Option<(&'a Element, u64)>,
    order: PhantomData<E>,
}

impl<'a, E: Order> Bin<'a, E> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let left = self.bytes.len() - self.pos;
        if n > left {
            let (e, i) = self.elem.expect("begin() comes first");
            return Err(truncated(self.path, self.pos, e, i, n, left));
        }
        self.last = self.pos;
        self.pos += n;
        Ok(&self.bytes[self.last..self.pos])
    }
}

impl<'a, E: Order> Source<'a> for Bin<'a, E> {
    fn begin(&mut self, e: &'a Element, i: u64) -> Result<()> {
        (self.elem, self.start) = (Some((e, i)), self.pos);
        Ok(())
    }
    fn value(&mut self, ty: Ty) -> Result<f64> {
        Ok(read_f64::<E>(ty, self.take(ty.size())?))
    }
    fn int(&mut self, ty: Ty) -> Result<i64> {
        Ok(read_int::<E>(ty, self.take(ty.size())?))
    }
    fn end(&mut self) -> Result<()> {
        Ok(())
    }
    fn here(&self) -> Location {
        Location::byte(self.path, self.last as u64)
    }
    fn start(&self) -> Location {
        Location::byte(self.path, self.start as u64)
    }
}

fn read_binary<E: Order>(
    bytes: &[u8],
    h: &Header,
    roles: &[Role],
    path: &Path,
    nv: u64,
    out: &mut Out,
) -> Result<()> {
    let mut src = Bin::<E> {
        path,
        bytes,
        pos: h.body,
        last: h.body,
        start: h.body,
        elem: None,
        order: PhantomData,
    };
    for (e, role) in h.elements.iter().zip(roles) {
        match (role, e.stride()) {
            (Role::Vertex(plan), Some(stride)) => vertices_fixed(&mut src, e, plan, stride, out)?,
            (Role::Skip, Some(stride)) => {
                let left = bytes.len() - src.pos;
                // check_sizes bounds `count * stride` by the body length, so this cannot overflow.
                let need = e.count as usize * stride;
                if need > left {
                    let i = (left / stride.max(1)) as u64;
                    let pos = src.pos + i as usize * stride;
                    return Err(truncated(path, pos, e, i, stride, left % stride.max(1)));
                }
                src.pos += need;
            }
            (Role::Faces(0), _) if e.props.len() == 1 => faces_fast(&mut src, e, nv, out)?,
            _ => read_element(&mut src, e, role, nv, out)?,
        }
    }
    Ok(())
}

/// Vertices whose properties are all scalars: fixed-stride records, fields at precomputed offsets.
fn vertices_fixed<E: Order>(
    src: &mut Bin<E>,
    e: &Element,
    plan: &VertexPlan,
    stride: usize,
    out: &mut Out,
) -> Result<()> {
    let mut fields = Vec::new();
    let mut off = 0;
    for (p, slot) in e.props.iter().zip(&plan.slots) {
        let Kind::Scalar(ty) = p.kind else {
            unreachable!("stride() is Some")
        };
        if let Some(s) = *slot {
            fields.push((off, ty, s));
        }
        off += ty.size();
    }
    let all_f32 = fields.iter().all(|f| f.1 == Ty::F32);
    let left = src.bytes.len() - src.pos;
    let need = e.count as usize * stride;
    if need > left {
        let i = left / stride;
        let pos = src.pos + i * stride;
        return Err(truncated(src.path, pos, e, i as u64, stride, left % stride));
    }
    let data = &src.bytes[src.pos..src.pos + need];
    let mut vals = [0.0f32; 8];
    for (i, rec) in data.chunks_exact(stride).enumerate() {
        if all_f32 {
            for &(off, _, s) in &fields {
                vals[s] = f32::from_bits(E::u32(arr(&rec[off..])));
            }
        } else {
            for &(off, ty, s) in &fields {
                vals[s] = read_f64::<E>(ty, &rec[off..]) as f32;
            }
        }
        plan.push(&vals, out).map_err(|s| {
            let loc = Location::byte(src.path, (src.pos + i * stride) as u64);
            plan.non_finite(e, i as u64, s, vals[s], loc)
        })?;
    }
    src.pos += need;
    Ok(())
}

/// Faces made of one index list: a loop specialised for the usual count and index types.
fn faces_fast<E: Order>(src: &mut Bin<E>, e: &Element, nv: u64, out: &mut Out) -> Result<()> {
    let Kind::List { count, item } = e.props[0].kind else {
        unreachable!("index_list checked")
    };
    match (count, item) {
        (Ty::U8, Ty::I32) => faces_loop(
            src,
            e,
            nv,
            out,
            (1, 4),
            |b| i64::from(b[0]),
            |b| i64::from(E::u32(arr(b)) as i32),
        ),
        (Ty::U8, Ty::U32) => faces_loop(
            src,
            e,
            nv,
            out,
            (1, 4),
            |b| i64::from(b[0]),
            |b| i64::from(E::u32(arr(b))),
        ),
        _ => faces_loop(
            src,
            e,
            nv,
            out,
            (count.size(), item.size()),
            |b| read_int::<E>(count, b),
            |b| read_int::<E>(item, b),
        ),
    }
}

#[inline(always)]
fn faces_loop<E: Order>(
    src: &mut Bin<E>,
    e: &Element,
    nv: u64,
    out: &mut Out,
    (cs, is): (usize, usize),
    read_count: impl Fn(&[u8]) -> i64,
    read_index: impl Fn(&[u8]) -> i64,
) -> Result<()> {
    let (bytes, path) = (src.bytes, src.path);
    let mut pos = src.pos;
    let mut poly = Vec::with_capacity(8);
    for f in 0..e.count {
        let left = bytes.len() - pos;
        if left < cs {
            return Err(truncated(path, pos, e, f, cs, left));
        }
        let n = read_count(&bytes[pos..]);
        if n < 3 {
            let msg = too_few_vertices(&format!("face {f}"), n);
            return Err(Error::input(Location::byte(path, pos as u64), msg));
        }
        pos += cs;
        let need = n as usize * is;
        let left = bytes.len() - pos;
        if need > left {
            return Err(truncated(path, pos, e, f, need, left));
        }
        poly.clear();
        for (k, b) in bytes[pos..pos + need].chunks_exact(is).enumerate() {
            let idx = read_index(b);
            if idx < 0 || idx as u64 >= nv {
                let loc = Location::byte(path, (pos + k * is) as u64);
                return Err(index_error("face", f, idx, nv, loc));
            }
            poly.push(idx as u32);
        }
        fan(&mut out.indices, &poly);
        pos += need;
    }
    src.pos = pos;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Little builder for binary PLY bodies in either byte order.
    struct W {
        le: bool,
        buf: Vec<u8>,
    }
    impl W {
        fn new(le: bool, header: &str) -> W {
            let format = if le {
                "binary_little_endian"
            } else {
                "binary_big_endian"
            };
            let head = format!("ply\nformat {format} 1.0\n{header}end_header\n");
            W {
                le,
                buf: head.into_bytes(),
            }
        }
        fn b(&mut self, le: &[u8]) -> &mut W {
            let mut v = le.to_vec();
            if !self.le {
                v.reverse();
            }
            self.buf.extend_from_slice(&v);
            self
        }
        fn f32(&mut self, v: f32) -> &mut W {
            self.b(&v.to_le_bytes())
        }
        fn f64(&mut self, v: f64) -> &mut W {
            self.b(&v.to_le_bytes())
        }
        fn i32(&mut self, v: i32) -> &mut W {
            self.b(&v.to_le_bytes())
        }
        fn u8(&mut self, v: u8) -> &mut W {
            self.b(&[v])
        }
        fn i16(&mut self, v: i16) -> &mut W {
            self.b(&v.to_le_bytes())
        }
        fn u16(&mut self, v: u16) -> &mut W {
            self.b(&v.to_le_bytes())
        }
    }

    fn parse(bytes: &[u8]) -> Result<TriangleMesh> {
        parse_ply(bytes, Path::new("m.ply"))
    }
    fn err(bytes: &[u8]) -> String {
        parse(bytes).unwrap_err().to_string()
    }

    const CUBE: &str = "ply\nformat ascii 1.0\ncomment a cube\nobj_info made by hand\n\
element vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
element face 6\nproperty list uchar int vertex_index\nend_header\n\
0 0 1\n0 1 1\n0 1 0\n0 0 0\n1 0 1\n1 1 1\n1 1 0\n1 0 0\n\
4 0 1 2 3\n4 7 6 5 4\n4 0 4 5 1\n4 1 5 6 2\n4 2 6 7 3\n4 3 7 4 0\n";

    #[test]
    fn ply_ascii_quads_fan_triangulated() {
        let m = parse(CUBE.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.positions[1], Vec3::new(0.0, 1.0, 1.0));
        assert_eq!(m.len(), 12);
        assert_eq!(&m.indices[..2], &[[0, 1, 2], [0, 2, 3]]);
        assert!(m.normals.is_none() && m.uvs.is_none());
    }

    #[test]
    fn ply_ascii_crlf_and_trailing_blank_lines() {
        let crlf = CUBE.replace('\n', "\r\n") + "\r\n\r\n";
        assert_eq!(
            parse(crlf.as_bytes()).unwrap(),
            parse(CUBE.as_bytes()).unwrap()
        );
    }

    /// Normals first, an ignored colour in the middle, uv as `s t`, indices as uint.
    fn shuffled(le: bool) -> Vec<u8> {
        let header = "element vertex 3\nproperty float nx\nproperty float ny\nproperty float nz\n\
property float x\nproperty uchar red\nproperty float y\nproperty float z\nproperty float s\n\
property float t\nelement face 1\nproperty list uchar uint vertex_indices\n";
        let mut w = W::new(le, header);
        for (i, p) in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
            .iter()
            .enumerate()
        {
            w.f32(0.0)
                .f32(0.0)
                .f32(1.0)
                .f32(p[0])
                .u8(200)
                .f32(p[1])
                .f32(p[2]);
            w.f32(i as f32 * 0.5).f32(0.25);
        }
        w.u8(3).i32(0).i32(1).i32(2);
        w.buf
    }

    #[test]
    fn ply_binary_le_reads_normals_uvs_in_any_order() {
        let m = parse(&shuffled(true)).unwrap();
        assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(m.indices, vec![[0, 1, 2]]);
        assert_eq!(m.normals, Some(vec![Vec3::Z; 3]));
        let uvs = vec![
            Vec2::new(0.0, 0.25),
            Vec2::new(0.5, 0.25),
            Vec2::new(1.0, 0.25),
        ];
        assert_eq!(m.uvs, Some(uvs));
    }

    #[test]
    fn ply_binary_be_matches_le() {
        assert_eq!(
            parse(&shuffled(false)).unwrap(),
            parse(&shuffled(true)).unwrap()
        );
    }

    /// Every scalar type, an unused element with a list before the vertices, faces with an extra
    /// property before the list (generic path) and a ushort/short list.
    fn odd_types(le: bool) -> Vec<u8> {
        let header = "element material 2\nproperty list uchar float weights\nproperty int8 id\n\
element vertex 4\nproperty float64 x\nproperty int16 y\nproperty uint8 z\nproperty char c\n\
property ushort d\nproperty uint e\nproperty int32 f\n\
element face 1\nproperty uchar flags\nproperty list ushort short vertex_indices\n";
        let mut w = W::new(le, header);
        w.u8(2).f32(1.0).f32(2.0).u8(1).u8(0).u8(2);
        for (x, y, z) in [(0.5, 0, 0), (1.0, 0, 0), (1.0, 1, 0), (0.0, -1, 3)] {
            w.f64(x).i16(y).u8(z);
            w.u8(0xff).u16(7).b(&9u32.to_le_bytes()).i32(-3);
        }
        w.u8(1).u16(4).i16(0).i16(1).i16(2).i16(3);
        w.buf
    }

    #[test]
    fn ply_all_scalar_types_and_skipped_lists() {
        for le in [true, false] {
            let m = parse(&odd_types(le)).unwrap();
            let want = [
                [0.5, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, -1.0, 3.0],
            ];
            assert_eq!(m.positions, want.map(Vec3::from_array).to_vec());
            assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        }
    }

    #[test]
    fn ply_ascii_faces_before_vertices_and_tristrips() {
        let src =
            "ply\nformat ascii 1.0\nelement tristrips 1\nproperty list int int vertex_indices\n\
element vertex 5\nproperty float x\nproperty float y\nproperty float z\nend_header\n\
8 0 1 2 3 -1 2 2 4\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 2 0\n";
        let m = parse(src.as_bytes()).unwrap();
        // 0 1 2 3 gives (0 1 2) and (2 1 3); the strip `2 2 4` is degenerate.
        assert_eq!(m.indices, vec![[0, 1, 2], [2, 1, 3]]);
    }

    #[test]
    fn ply_binary_truncated_faces_name_byte_offset() {
        let mut bytes = shuffled(true);
        bytes.truncate(bytes.len() - 6);
        // The header check only knows the minimum (1 byte per face): the face loop finds it.
        assert_eq!(
            err(&bytes),
            format!(
                "m.ply: byte {}: unexpected end of file in face 0 of 1 (needs 12 more bytes, 6 left)",
                bytes.len() - 6
            )
        );
    }

    #[test]
    fn ply_binary_truncated_vertices_name_byte_offset() {
        // A list longer than its minimum size eats the bytes the vertex needs.
        let header = "element material 1\nproperty list uchar float w\n\
element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
        let mut w = W::new(true, header);
        let head = w.buf.len();
        w.u8(2).f32(1.0).f32(2.0).f32(0.0);
        assert_eq!(
            err(&w.buf),
            format!(
                "m.ply: byte {}: unexpected end of file in vertex 0 of 1 (needs 12 more bytes, 4 left)",
                head + 9
            )
        );
        // The same through the generic path (a list in the vertex element).
        let header = "element vertex 1\nproperty list uchar float w\nproperty float x\n\
property float y\nproperty float z\n";
        let mut w = W::new(false, header);
        let head = w.buf.len();
        w.u8(2).f32(1.0).f32(2.0).f32(0.0);
        assert_eq!(
            err(&w.buf),
            format!(
                "m.ply: byte {}: unexpected end of file in vertex 0 of 1 (needs 4 more bytes, 0 left)",
                head + 13
            )
        );
    }

    #[test]
    fn ply_header_claiming_too_many_elements_is_rejected() {
        let mut w = W::new(
            true,
            "element vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\n",
        );
        w.f32(0.0);
        assert_eq!(
            err(&w.buf),
            "m.ply:3: element `vertex` claims 1000000000000 entries (at least 12000000000000 bytes) but only 4 bytes are left for it"
        );
        let ascii = CUBE.replace("element face 6", "element face 7");
        assert_eq!(
            err(ascii.as_bytes()),
            "m.ply:9: element `face` claims 7 entries but only 6 lines are left for it"
        );
    }

    #[test]
    fn ply_index_out_of_range() {
        let ascii = CUBE.replace("4 2 6 7 3", "4 2 6 8 3");
        assert_eq!(
            err(ascii.as_bytes()),
            "m.ply:24:7: face 4: vertex index 8 out of range (the file has 8 vertices)"
        );
        let mut bytes = shuffled(false);
        let n = bytes.len();
        bytes[n - 4..].copy_from_slice(&3u32.to_be_bytes());
        assert_eq!(
            err(&bytes),
            format!(
                "m.ply: byte {}: face 0: vertex index 3 out of range (the file has 3 vertices)",
                n - 4
            )
        );
    }

    #[test]
    fn ply_nan_vertex() {
        let ascii = CUBE.replace("1 1 1\n", "1 nan 1\n");
        assert_eq!(
            err(ascii.as_bytes()),
            "m.ply:17: vertex 5: non-finite y (NaN)"
        );
        let mut w = W::new(
            true,
            "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n",
        );
        w.f32(0.0)
            .f32(0.0)
            .f32(0.0)
            .f32(1.0)
            .f32(f32::INFINITY)
            .f32(0.0);
        let at = w.buf.len() - 12;
        assert_eq!(
            err(&w.buf),
            format!("m.ply: byte {at}: vertex 1: non-finite y (inf)")
        );
    }

    #[test]
    fn ply_face_with_two_vertices() {
        let ascii = CUBE.replace("4 0 4 5 1", "2 0 4");
        assert_eq!(
            err(ascii.as_bytes()),
            "m.ply:22: face 2 has 2 vertices (a face needs at least 3)"
        );
        let mut bytes = shuffled(true);
        let n = bytes.len();
        bytes[n - 13] = 2;
        assert_eq!(
            err(&bytes),
            format!(
                "m.ply: byte {}: face 0 has 2 vertices (a face needs at least 3)",
                n - 13
            )
        );
    }

    #[test]
    fn ply_malformed_ascii_number() {
        let ascii = CUBE.replace("0 1 0\n", "0 1x 0\n");
        assert_eq!(err(ascii.as_bytes()), "m.ply:14:3: malformed number `1x`");
    }

    #[test]
    fn ply_header_errors() {
        assert_eq!(
            err(b"PLY\n"),
            "m.ply:1: not a PLY file (the first line must be `ply`)"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 0\n"),
            "m.ply: header has no `end_header` line"
        );
        assert_eq!(
            err(b"ply\nformat text 1.0\nend_header\n"),
            "m.ply:2:8: unknown format `text` (expected ascii, binary_little_endian or binary_big_endian)"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex\nend_header\n"),
            "m.ply:3: malformed element line (expected `element <name> <count>`)"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty real x\nend_header\n"),
            "m.ply:4:10: unknown property type `real`"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
            "m.ply:3: property before any element"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nend_header\n"),
            "m.ply:3: element `vertex` has no scalar property `z`"
        );
        assert_eq!(
            err(b"ply\nelement vertex 0\nend_header\n"),
            "m.ply:3: no `format` line before `end_header`"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement face 0\nproperty list float int vertex_indices\nend_header\n"),
            "m.ply:4:15: list count type must be an integer type, not `float`"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nend_header\n"),
            "m.ply: no `vertex` element"
        );
    }

    #[test]
    fn ply_ascii_extra_value_is_an_error() {
        let ascii = CUBE.replace("0 1 0\n", "0 1 0 7\n");
        assert_eq!(
            err(ascii.as_bytes()),
            "m.ply:14:7: unexpected value `7` after the end of vertex 2"
        );
    }
}
