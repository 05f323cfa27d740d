//! Mesh file readers: bytes -> [`TriangleMesh`] or an error located in the file.
//!
//! Three formats, one reader each: PLY ([`parse_ply`]: ASCII and both binary byte orders), Wavefront OBJ
//! ([`parse_obj`]) and OFF ([`parse_off`]). [`load_mesh`] reads a regular file whole
//! ([`crate::input::load_bytes`]: never mapped, so a file truncated meanwhile is an error, not a SIGBUS)
//! and picks the reader by extension.
//!
//! Every reader validates what the renderer relies on, so that later stages never see bad data: every
//! index is in range, every coordinate is finite, polygons are fan-triangulated (`v0 v1 v2 v3` ->
//! `v0 v1 v2`, `v0 v2 v3`, which is exact for the convex polygons meshes store), and a header that claims
//! more elements than the remaining bytes or lines can hold is rejected before anything is allocated.
//! Errors name the line (and column) in text files and the byte offset in binary data.
//!
//! This module also holds the small helpers the text formats share: line iteration with 1-based line
//! numbers, whitespace tokens with 1-based columns, number parsing with located errors.

mod obj;
mod off;
mod ply;

use std::path::Path;
use std::str::FromStr;

use crate::geometry::TriangleMesh;
use crate::{Error, Location, Result};

pub use obj::parse_obj;
pub use off::parse_off;
pub use ply::parse_ply;

const SUPPORTED: &str = "supported: .ply, .obj, .off";

/// Loads a mesh file, picking the reader by extension (`ply`, `obj`, `off`, in any letter case).
///
/// An unknown or missing extension is an input error; a file that cannot be read is an I/O error.
pub fn load_mesh(path: &Path) -> Result<TriangleMesh> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let parse: fn(&[u8], &Path) -> Result<TriangleMesh> = match ext.as_deref() {
        Some("ply") => parse_ply,
        Some("obj") => parse_obj,
        Some("off") => parse_off,
        Some(other) => {
            let msg = format!("unknown mesh file extension `.{other}` ({SUPPORTED})");
            return Err(Error::input(Location::file(path), msg));
        }
        None => {
            let msg = format!("mesh file has no extension ({SUPPORTED})");
            return Err(Error::input(Location::file(path), msg));
        }
    };
    parse(&crate::input::load_bytes(path)?, path)
}

/// An empty vector with room for `n` items of a mesh read from `path`, or an I/O error saying that memory
/// ran out (the CLI's exit 4) instead of an abort: headers are checked against the file's size, but a
/// large file can still claim more than the machine has.
pub(crate) fn vec_for<T>(n: u64, what: &str, path: &Path) -> Result<Vec<T>> {
    crate::input::vec_for(n, path, |gib| format!("not enough memory for {n} {what} ({gib:.1} GiB)"))
}

/// Lines of a text file as `(1-based line number, bytes without "\n" or "\r\n")`.
///
/// Bytes rather than `str`: comments may hold any encoding, and only the tokens that are parsed as
/// numbers need to be text.
pub(crate) struct Lines<'a> {
    rest: &'a [u8],
    next_line: u32,
    done: bool,
}

impl<'a> Lines<'a> {
    /// Lines of `bytes`, the first numbered `first_line`.
    pub(crate) fn new(bytes: &'a [u8], first_line: u32) -> Self {
        Lines { rest: bytes, next_line: first_line, done: bytes.is_empty() }
    }
    /// The number the next line will get.
    pub(crate) fn next_number(&self) -> u32 {
        self.next_line
    }
    /// The bytes not yet returned.
    pub(crate) fn rest(&self) -> &'a [u8] {
        if self.done {
            &[]
        } else {
            self.rest
        }
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (u32, &'a [u8]);
    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let (line, rest) = match self.rest.iter().position(|&b| b == b'\n') {
            Some(i) => (&self.rest[..i], &self.rest[i + 1..]),
            None => (self.rest, &[][..]),
        };
        self.done = rest.is_empty();
        self.rest = rest;
        let n = self.next_line;
        self.next_line = self.next_line.saturating_add(1);
        Some((n, line.strip_suffix(b"\r").unwrap_or(line)))
    }
}

/// An upper bound on the number of lines in `bytes` (a last line without "\n" counts).
pub(crate) fn count_lines(bytes: &[u8]) -> u64 {
    let newlines = bytes.iter().filter(|&&b| b == b'\n').count() as u64;
    newlines + u64::from(!bytes.is_empty() && !bytes.ends_with(b"\n"))
}

/// The line up to its first `#` (OBJ and OFF comments).
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Whitespace-separated tokens of one line as `(1-based column, bytes)`.
#[derive(Clone)]
pub(crate) struct Tokens<'a> {
    line: &'a [u8],
    pos: usize,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(line: &'a [u8]) -> Self {
        Tokens { line, pos: 0 }
    }
    /// The 1-based column just after the last token returned (where a missing one would be).
    pub(crate) fn end_col(&self) -> u32 {
        col(self.pos)
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = (u32, &'a [u8]);
    fn next(&mut self) -> Option<Self::Item> {
        let is_space = |b: &u8| b.is_ascii_whitespace() || *b == 0x0b;
        let start = self.pos + self.line[self.pos..].iter().position(|b| !is_space(b))?;
        let len = self.line[start..].iter().position(is_space).unwrap_or(self.line.len() - start);
        self.pos = start + len;
        Some((col(start), &self.line[start..self.pos]))
    }
}

fn col(pos: usize) -> u32 {
    u32::try_from(pos + 1).unwrap_or(u32::MAX)
}

/// A token as text for a message, shortened so a garbage line does not flood the terminal.
pub(crate) fn shown(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    match s.char_indices().nth(32) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.into_owned(),
    }
}

/// Parses a number token, or says where and what it is.
pub(crate) fn parse_num<T: FromStr>(tok: &[u8], path: &Path, line: u32, col: u32) -> Result<T> {
    std::str::from_utf8(tok).ok().and_then(|s| s.parse().ok()).ok_or_else(|| {
        let msg = format!("malformed number `{}`", shown(tok));
        Error::input(Location::at(path, line, col), msg)
    })
}

/// Parses a coordinate: a number that must also be finite (`nan`, `inf` and overflowing values like
/// `1e99` in single precision would poison the acceleration structures' bounds).
pub(crate) fn parse_coord(tok: &[u8], path: &Path, line: u32, col: u32) -> Result<f32> {
    let v: f32 = parse_num(tok, path, line, col)?;
    if !v.is_finite() {
        let msg = format!("non-finite coordinate `{}`", shown(tok));
        return Err(Error::input(Location::at(path, line, col), msg));
    }
    Ok(v)
}

/// Appends the fan triangulation of the polygon `poly` (at least 3 vertices) to `out`.
#[inline]
pub(crate) fn fan(out: &mut Vec<[u32; 3]>, poly: &[u32]) {
    for w in poly[1..].windows(2) {
        out.push([poly[0], w[0], w[1]]);
    }
}

/// The message for a polygon with fewer than 3 corners (`face` is "face" or "face 7").
pub(crate) fn too_few_vertices(face: &str, n: impl std::fmt::Display) -> String {
    format!("{face} has {n} vertices (a face needs at least 3)")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_numbers_and_strips_crlf() {
        let got: Vec<_> = Lines::new(b"a\r\nb\n\nc", 1).collect();
        let want: Vec<(u32, &[u8])> = vec![(1, b"a"), (2, b"b"), (3, b""), (4, b"c")];
        assert_eq!(got, want);
        assert_eq!(Lines::new(b"a\n", 1).count(), 1);
        assert_eq!(count_lines(b"a\nb"), 2);
        assert_eq!(count_lines(b"a\nb\n"), 2);
    }

    #[test]
    fn tokens_report_columns() {
        let got: Vec<_> = Tokens::new(b"  v 1.5\t-2 ").collect();
        let want: Vec<(u32, &[u8])> = vec![(3, b"v"), (5, b"1.5"), (9, b"-2")];
        assert_eq!(got, want);
    }

    #[test]
    fn fan_triangulates_pentagon() {
        let mut out = Vec::new();
        fan(&mut out, &[0, 1, 2, 3, 4]);
        assert_eq!(out, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }

    #[test]
    fn parse_coord_rejects_nan_and_overflow() {
        let p = Path::new("m.obj");
        let e = parse_coord(b"nan", p, 3, 4).unwrap_err();
        assert_eq!(e.to_string(), "m.obj:3:4: non-finite coordinate `nan`");
        let e = parse_coord(b"1e99", p, 1, 1).unwrap_err();
        assert_eq!(e.to_string(), "m.obj:1:1: non-finite coordinate `1e99`");
        let e = parse_coord(b"1x", p, 2, 5).unwrap_err();
        assert_eq!(e.to_string(), "m.obj:2:5: malformed number `1x`");
    }

    #[test]
    fn load_mesh_reads_regular_files_only() {
        let dir = tempfile::tempdir().unwrap();
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                    element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let path = dir.path().join("tri.ply");
        std::fs::write(&path, text).unwrap();
        assert_eq!(load_mesh(&path).unwrap(), parse_ply(text.as_bytes(), &path).unwrap());
        let empty = dir.path().join("empty.ply");
        std::fs::write(&empty, "").unwrap();
        assert_eq!(load_mesh(&empty).unwrap_err().to_string(), parse_ply(b"", &empty).unwrap_err().to_string());
        let folder = dir.path().join("folder.ply");
        std::fs::create_dir(&folder).unwrap();
        let e = load_mesh(&folder).unwrap_err();
        assert_eq!(e.to_string(), format!("{}: not a regular file (a directory)", folder.display()));
    }

    #[test]
    fn load_mesh_rejects_unknown_extension() {
        let e = load_mesh(Path::new("scene/model.stl")).unwrap_err();
        assert_eq!(e.to_string(), "scene/model.stl: unknown mesh file extension `.stl` (supported: .ply, .obj, .off)");
        let e = load_mesh(Path::new("model")).unwrap_err();
        assert_eq!(e.to_string(), "model: mesh file has no extension (supported: .ply, .obj, .off)");
    }
}
