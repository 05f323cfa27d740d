//! OFF (Object File Format) reader: a header, `nv nf ne` counts, `nv` vertex lines, `nf` face lines.
//!
//! Accepted: the `OFF` keyword with the usual prefixes (`COFF`, `NOFF`, `STOFF`, `CNOFF`...; their extra
//! vertex columns, colours or normals, are ignored), counts on the keyword's line or the next one, `#`
//! comments and blank lines anywhere, faces `n i0 i1 ... i(n-1)` with 0-based indices and optional
//! trailing colour values, fan-triangulated. The edge count is read and ignored. Not accepted: 4-D
//! and n-D variants (`4OFF`, `nOFF`), and the binary form (`OFF BINARY`).
//!
//! The counts are checked against the number of lines left before anything is allocated, since each
//! vertex and each face takes at least one line. Cost: one pass over the bytes.

use std::path::Path;

use super::{count_lines, fan, parse_coord, parse_num, shown, strip_comment, too_few_vertices};
use super::{Lines, Tokens};
use crate::geometry::TriangleMesh;
use crate::math::Vec3;
use crate::{Error, Location, Result};

/// Parses an OFF file already in memory; `path` is only used in error messages.
pub fn parse_off(bytes: &[u8], path: &Path) -> Result<TriangleMesh> {
    let mut r = Reader { path, lines: Lines::new(bytes, 1) };
    let (nv, nf) = r.header()?;
    let mut mesh = TriangleMesh {
        positions: super::vec_for(nv, "vertices", path)?,
        indices: super::vec_for(nf, "faces", path)?,
        ..Default::default()
    };
    for i in 0..nv {
        let (line, text) = r.next().ok_or_else(|| r.eof("vertices", i, nv))?;
        mesh.positions.push(r.vertex(i, line, text)?);
    }
    let mut poly = Vec::new();
    for i in 0..nf {
        let (line, text) = r.next().ok_or_else(|| r.eof("faces", i, nf))?;
        r.face(i, nv, line, text, &mut poly)?;
        fan(&mut mesh.indices, &poly);
    }
    // More lines mean a count too small: the rest of the file would be dropped without a word.
    if let Some((line, text)) = r.next() {
        let col = Tokens::new(text).next().map_or(1, |(col, _)| col);
        return Err(r.err(line, col, format!("unexpected line after the last of {nf} faces")));
    }
    Ok(mesh)
}

struct Reader<'a> {
    path: &'a Path,
    lines: Lines<'a>,
}

impl<'a> Reader<'a> {
    /// The next line that holds something once comments are gone.
    fn next(&mut self) -> Option<(u32, &'a [u8])> {
        self.lines.find_map(|(n, raw)| {
            let line = strip_comment(raw);
            Tokens::new(line).next().is_some().then_some((n, line))
        })
    }

    fn err(&self, line: u32, col: u32, msg: impl Into<String>) -> Error {
        Error::input(Location::at(self.path, line, col), msg)
    }

    fn eof(&self, what: &str, i: u64, n: u64) -> Error {
        let msg = format!("file ends after {i} of {n} {what}");
        Error::input(Location::file(self.path), msg)
    }

    /// The keyword and the counts `(vertices, faces)`, checked against the lines left.
    fn header(&mut self) -> Result<(u64, u64)> {
        let Some((hline, header)) = self.next() else {
            return Err(Error::input(Location::file(self.path), "empty file (expected `OFF`)"));
        };
        let mut toks = Tokens::new(header);
        let (col, kw) = toks.next().unwrap_or((1, b""));
        check_keyword(kw).map_err(|msg| self.err(hline, col, msg))?;
        if let Some((col, b"BINARY")) = toks.clone().next() {
            return Err(self.err(hline, col, "binary OFF is not supported"));
        }
        // Counts: the rest of the keyword's line, or else the next line.
        let (cline, mut toks) = if toks.clone().next().is_some() {
            (hline, toks)
        } else {
            let Some((n, line)) = self.next() else {
                let msg = "missing counts `vertices faces edges`";
                return Err(Error::input(Location::file(self.path), msg));
            };
            (n, Tokens::new(line))
        };
        let mut count = |what: &str| -> Result<u64> {
            let Some((col, tok)) = toks.next() else {
                let msg = format!("missing {what} count (expected `vertices faces edges`)");
                return Err(self.err(cline, toks.end_col(), msg));
            };
            parse_num(tok, self.path, cline, col)
        };
        let (nv, nf) = (count("vertex")?, count("face")?);
        // Each vertex and each face takes a line: reject impossible counts before allocating.
        let left = count_lines(self.lines.rest());
        if nv.saturating_add(nf) > left {
            let msg = format!("header claims {nv} vertices and {nf} faces but only {left} lines follow");
            return Err(self.err(cline, 0, msg));
        }
        if nv > u64::from(u32::MAX) {
            return Err(self.err(cline, 0, format!("{nv} vertices do not fit in 32-bit indices")));
        }
        Ok((nv, nf))
    }

    /// `x y z`, then any extra columns (colour, normal, texture), ignored.
    fn vertex(&self, i: u64, line: u32, text: &[u8]) -> Result<Vec3> {
        let mut toks = Tokens::new(text);
        let mut p = [0.0f32; 3];
        for (k, c) in p.iter_mut().enumerate() {
            let Some((col, tok)) = toks.next() else {
                let msg = format!("vertex {i} has {k} coordinates, expected 3");
                return Err(self.err(line, toks.end_col(), msg));
            };
            *c = parse_coord(tok, self.path, line, col)?;
        }
        Ok(Vec3::from_array(p))
    }

    /// `n i0 ... i(n-1)` into `poly`, then any extra columns (colour), ignored.
    fn face(&self, i: u64, nv: u64, line: u32, text: &[u8], poly: &mut Vec<u32>) -> Result<()> {
        let mut toks = Tokens::new(text);
        let (col, tok) = toks.next().unwrap_or((1, b""));
        let n: u64 = parse_num(tok, self.path, line, col)?;
        if n < 3 {
            return Err(self.err(line, col, too_few_vertices(&format!("face {i}"), n)));
        }
        poly.clear();
        for k in 0..n {
            let Some((col, tok)) = toks.next() else {
                let msg = format!("face {i} lists {n} vertices but gives {k}");
                return Err(self.err(line, toks.end_col(), msg));
            };
            let idx: i64 = parse_num(tok, self.path, line, col)?;
            if idx < 0 || idx as u64 >= nv {
                let msg = format!("face {i}: vertex index {idx} out of range (the file has {nv} vertices)");
                return Err(self.err(line, col, msg));
            }
            poly.push(idx as u32);
        }
        Ok(())
    }
}

/// Accepts `OFF` with the optional prefixes `ST`, `C`, `N` (in that order), in the keyword itself.
fn check_keyword(kw: &[u8]) -> std::result::Result<(), String> {
    let Some(prefix) = kw.strip_suffix(b"OFF") else {
        return Err(format!("not an OFF file: expected `OFF`, found `{}`", shown(kw)));
    };
    let mut p = prefix;
    for part in [&b"ST"[..], b"C", b"N"] {
        p = p.strip_prefix(part).unwrap_or(p);
    }
    if p.is_empty() {
        Ok(())
    } else if p.ends_with(b"4") || p.ends_with(b"n") {
        Err(format!("`{}`: only 3-D OFF files are supported", shown(kw)))
    } else {
        Err(format!("not an OFF file: unknown keyword `{}`", shown(kw)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(src: &str) -> Result<TriangleMesh> {
        parse_off(src.as_bytes(), Path::new("m.off"))
    }
    fn err(src: &str) -> String {
        parse(src).unwrap_err().to_string()
    }

    const SQUARE: &str = "OFF\n# a square\n4 1 4\n\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn off_quad_fan_triangulated() {
        let m = parse(SQUARE).unwrap();
        assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn off_counts_on_header_line_and_variants() {
        let src = "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n0 1 0 255 0 0 255\n3 0 1 2 0.5 0.5 0.5\n";
        assert_eq!(parse(src).unwrap().indices, vec![[0, 1, 2]]);
        let src = "NOFF\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1 # normal\n3 2 1 0\n";
        assert_eq!(parse(src).unwrap().indices, vec![[2, 1, 0]]);
        assert_eq!(err("4OFF\n"), "m.off:1:1: `4OFF`: only 3-D OFF files are supported");
        assert_eq!(err("PLY\n"), "m.off:1:1: not an OFF file: expected `OFF`, found `PLY`");
        assert_eq!(err("OFF BINARY\n"), "m.off:1:5: binary OFF is not supported");
    }

    #[test]
    fn off_counts_larger_than_file_rejected() {
        assert_eq!(
            err("OFF\n1000000000 1 0\n0 0 0\n"),
            "m.off:2: header claims 1000000000 vertices and 1 faces but only 1 lines follow"
        );
        assert_eq!(err("OFF\n3\n"), "m.off:2:2: missing face count (expected `vertices faces edges`)");
    }

    #[test]
    fn off_malformed_number() {
        let src = SQUARE.replace("1 1 0", "1 1,5 0");
        assert_eq!(err(&src), "m.off:7:3: malformed number `1,5`");
    }

    #[test]
    fn off_index_out_of_range() {
        let src = SQUARE.replace("4 0 1 2 3", "4 0 1 2 4");
        assert_eq!(err(&src), "m.off:9:9: face 0: vertex index 4 out of range (the file has 4 vertices)");
        let src = SQUARE.replace("4 0 1 2 3", "4 0 -1 2 3");
        assert_eq!(err(&src), "m.off:9:5: face 0: vertex index -1 out of range (the file has 4 vertices)");
    }

    #[test]
    fn off_face_with_two_vertices() {
        let src = SQUARE.replace("4 0 1 2 3", "2 0 1");
        assert_eq!(err(&src), "m.off:9:1: face 0 has 2 vertices (a face needs at least 3)");
        let src = SQUARE.replace("4 0 1 2 3", "4 0 1 2");
        assert_eq!(err(&src), "m.off:9:8: face 0 lists 4 vertices but gives 3");
    }

    #[test]
    fn off_nan_vertex_and_short_file() {
        let src = SQUARE.replace("1 1 0", "1 NaN 0");
        assert_eq!(err(&src), "m.off:7:3: non-finite coordinate `NaN`");
        let src = SQUARE.replace("0 1 0\n", "0 1\n");
        assert_eq!(err(&src), "m.off:8:4: vertex 3 has 2 coordinates, expected 3");
        let src = "OFF\n3 1 0\n0 0 0\n# gone\n\n\n";
        assert_eq!(err(src), "m.off: file ends after 1 of 3 vertices");
    }

    #[test]
    fn off_data_after_the_last_face_is_an_error() {
        assert_eq!(err(&format!("{SQUARE}3 0 1 2\n")), "m.off:10:1: unexpected line after the last of 1 faces");
        // Comments and blank lines after the faces are fine.
        assert_eq!(parse(&format!("{SQUARE}\n# end\n\n")).unwrap().indices.len(), 2);
    }
}
