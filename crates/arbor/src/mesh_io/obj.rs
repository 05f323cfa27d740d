//! Wavefront OBJ reader: `v`, `vt`, `vn` and `f` lines -> one [`TriangleMesh`].
//!
//! A small line-based parser rather than the `tobj` crate: tobj 4.0.5 reports no line numbers, accepts
//! a face with 2 vertices (it emits a triangle from a line), accepts the invalid texture index 0
//! (`f 1/0 2/1 3/1`) and NaN coordinates without a word. Here every error names its line and column.
//!
//! Supported: all index forms `a`, `a/b`, `a//c`, `a/b/c`; negative (relative) indices; polygons,
//! fan-triangulated; several objects and groups, merged into one mesh. Everything else (`o`, `g`, `s`,
//! `usemtl`, `mtllib`, lines, points, free-form geometry) is ignored, and no other file is opened.
//! Indices must refer to vertices defined above the face (as the format says), so errors are found on
//! the face's own line.
//!
//! OBJ indexes positions, texture coordinates and normals separately, but [`TriangleMesh`] shares one
//! index between them. When every face corner names a texture coordinate (or a normal), the mesh keeps
//! them and gets one vertex per distinct `(v, vt, vn)` triple; otherwise that attribute is dropped and
//! the positions are used as they are. Cost: one pass over the bytes, plus a hash map over the corners
//! when attributes are kept.

use std::collections::HashMap;
use std::path::Path;

use super::{parse_coord, parse_num, shown, strip_comment, too_few_vertices, Lines, Tokens};
use crate::geometry::TriangleMesh;
use crate::math::{Vec2, Vec3};
use crate::{Error, Location, Result};

/// A corner without a texture coordinate or normal.
const NONE: u32 = u32::MAX;

/// Parses an OBJ file already in memory; `path` is only used in error messages.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<TriangleMesh> {
    let mut p = Parser {
        path,
        positions: Vec::new(),
        uvs: Vec::new(),
        normals: Vec::new(),
        tris: Vec::new(),
        all_uv: true,
        all_normal: true,
        poly: Vec::new(),
    };
    for (line, raw) in Lines::new(bytes, 1) {
        let mut toks = Tokens::new(strip_comment(raw));
        match toks.next() {
            Some((_, b"v")) => {
                let [x, y, z] = p.floats::<3>(&mut toks, line, "a vertex needs x y z")?;
                p.positions.push(Vec3::new(x, y, z));
            }
            Some((_, b"vt")) => {
                // `v` is optional in the format (1-D textures); it defaults to 0.
                let [u] = p.floats::<1>(&mut toks, line, "a texture coordinate needs u [v]")?;
                let v = match toks.next() {
                    Some((col, tok)) => parse_coord(tok, path, line, col)?,
                    None => 0.0,
                };
                p.uvs.push(Vec2::new(u, v));
            }
            Some((_, b"vn")) => {
                let [x, y, z] = p.floats::<3>(&mut toks, line, "a normal needs x y z")?;
                p.normals.push(Vec3::new(x, y, z));
            }
            Some((_, b"f")) => p.face(toks, line)?,
            _ => {}
        }
    }
    Ok(p.finish())
}

struct Parser<'a> {
    path: &'a Path,
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    normals: Vec<Vec3>,
    /// Triangles of corners `[v, vt, vn]` (0-based, [`NONE`] when absent).
    tris: Vec<[[u32; 3]; 3]>,
    all_uv: bool,
    all_normal: bool,
    /// The current face's corners, reused so that faces allocate nothing.
    poly: Vec<[u32; 3]>,
}

impl Parser<'_> {
    fn floats<const N: usize>(&self, toks: &mut Tokens, line: u32, need: &str) -> Result<[f32; N]> {
        let mut out = [0.0; N];
        for v in &mut out {
            let Some((col, tok)) = toks.next() else {
                let loc = Location::at(self.path, line, toks.end_col());
                return Err(Error::input(loc, format!("missing number: {need}")));
            };
            *v = parse_coord(tok, self.path, line, col)?;
        }
        Ok(out)
    }

    fn face(&mut self, toks: Tokens, line: u32) -> Result<()> {
        let mut poly = std::mem::take(&mut self.poly);
        poly.clear();
        for (col, tok) in toks {
            poly.push(self.corner(tok, line, col)?);
        }
        if poly.len() < 3 {
            let loc = Location::at(self.path, line, 0);
            return Err(Error::input(loc, too_few_vertices("face", poly.len())));
        }
        for c in &poly {
            self.all_uv &= c[1] != NONE;
            self.all_normal &= c[2] != NONE;
        }
        for w in poly[1..].windows(2) {
            self.tris.push([poly[0], w[0], w[1]]);
        }
        self.poly = poly;
        Ok(())
    }

    /// One face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, resolved to 0-based indices.
    fn corner(&self, tok: &[u8], line: u32, col: u32) -> Result<[u32; 3]> {
        if tok.iter().filter(|&&b| b == b'/').count() > 2 {
            let msg = format!("malformed face vertex `{}`", shown(tok));
            return Err(Error::input(Location::at(self.path, line, col), msg));
        }
        let mut parts = tok.split(|&b| b == b'/');
        let mut out = [NONE; 3];
        let kinds =
            [("vertex", self.positions.len()), ("texture coordinate", self.uvs.len()), ("normal", self.normals.len())];
        for (k, &(what, count)) in kinds.iter().enumerate() {
            match parts.next() {
                Some(b"") if k > 0 => {}
                Some(part) => out[k] = self.index(part, what, count, line, col)?,
                None => break,
            }
        }
        Ok(out)
    }

    fn index(&self, tok: &[u8], what: &str, count: usize, line: u32, col: u32) -> Result<u32> {
        let i: i64 = parse_num(tok, self.path, line, col)?;
        // 1-based from the start, or negative: relative to the end of the list so far.
        let resolved = if i > 0 { i - 1 } else { count as i64 + i };
        if i == 0 || resolved < 0 || resolved >= count as i64 {
            let msg = format!("{what} index {i} out of range ({count} defined so far)");
            return Err(Error::input(Location::at(self.path, line, col), msg));
        }
        u32::try_from(resolved).map_err(|_| {
            let msg = format!("{what} index {i} does not fit in 32 bits");
            Error::input(Location::at(self.path, line, col), msg)
        })
    }

    fn finish(self) -> TriangleMesh {
        let keep_uv = self.all_uv && !self.tris.is_empty();
        let keep_normal = self.all_normal && !self.tris.is_empty();
        if !keep_uv && !keep_normal {
            return TriangleMesh {
                indices: self.tris.iter().map(|t| [t[0][0], t[1][0], t[2][0]]).collect(),
                positions: self.positions,
                normals: None,
                uvs: None,
            };
        }
        // One output vertex per distinct (position, uv, normal) triple actually used.
        let mut map: HashMap<[u32; 3], u32> = HashMap::new();
        let mut mesh =
            TriangleMesh { normals: keep_normal.then(Vec::new), uvs: keep_uv.then(Vec::new), ..Default::default() };
        mesh.indices.reserve(self.tris.len());
        for tri in &self.tris {
            let mut out = [0; 3];
            for (o, c) in out.iter_mut().zip(tri) {
                let uv = if keep_uv { c[1] } else { NONE };
                let key = [c[0], uv, if keep_normal { c[2] } else { NONE }];
                *o = *map.entry(key).or_insert_with(|| {
                    mesh.positions.push(self.positions[key[0] as usize]);
                    if let Some(uvs) = &mut mesh.uvs {
                        uvs.push(self.uvs[key[1] as usize]);
                    }
                    if let Some(ns) = &mut mesh.normals {
                        ns.push(self.normals[key[2] as usize]);
                    }
                    (mesh.positions.len() - 1) as u32
                });
            }
            mesh.indices.push(out);
        }
        mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(src: &str) -> Result<TriangleMesh> {
        parse_obj(src.as_bytes(), Path::new("m.obj"))
    }
    fn err(src: &str) -> String {
        parse(src).unwrap_err().to_string()
    }

    const QUAD: &str = "# a unit quad\nmtllib missing.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
usemtl red\ns off\nf 1 2 3 4\n";

    #[test]
    fn obj_quad_fan_triangulated() {
        let m = parse(QUAD).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.normals.is_none() && m.uvs.is_none());
    }

    #[test]
    fn obj_negative_indices_and_groups_merge() {
        let src = "g a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\ng b\nv 5 5 5\nf 4 -2 1\n";
        let m = parse(src).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2], [3, 2, 0]]);
    }

    #[test]
    fn obj_index_forms_keep_uvs_and_normals() {
        let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
f 1/1/1 2/2/1 3/3/1\nf 1/2/1 2/2/1 3/3/1\n";
        let m = parse(src).unwrap();
        // Vertex 1 appears with two texture coordinates: it is split.
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.indices, vec![[0, 1, 2], [3, 1, 2]]);
        assert_eq!(m.positions[3], Vec3::ZERO);
        assert_eq!(m.uvs.as_ref().unwrap()[3], Vec2::new(1.0, 0.0));
        assert_eq!(m.normals, Some(vec![Vec3::Z; 4]));

        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n").unwrap();
        assert!(m.uvs.is_none());
        assert_eq!(m.normals, Some(vec![Vec3::Z; 3]));
        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5\nf 1/1 2/1 3/1\n").unwrap();
        assert_eq!(m.uvs, Some(vec![Vec2::new(0.5, 0.0); 3]));
        assert!(m.normals.is_none());
    }

    #[test]
    fn obj_attributes_dropped_when_some_corners_lack_them() {
        let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 3 2 1\n";
        let m = parse(src).unwrap();
        assert!(m.normals.is_none());
        assert_eq!(m.indices, vec![[0, 1, 2], [2, 1, 0]]);
    }

    #[test]
    fn obj_malformed_number() {
        assert_eq!(err("v 0 0 0\nv 1 0.5.1 0\n"), "m.obj:2:5: malformed number `0.5.1`");
        assert_eq!(err("v 0 0 0\nf 1 x 1\n"), "m.obj:2:5: malformed number `x`");
        assert_eq!(err("v 0 0\n"), "m.obj:1:6: missing number: a vertex needs x y z");
    }

    #[test]
    fn obj_index_out_of_range() {
        let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        assert_eq!(err(&format!("{v}f 1 2 4\n")), "m.obj:4:7: vertex index 4 out of range (3 defined so far)");
        assert_eq!(err(&format!("{v}f 0 1 2\n")), "m.obj:4:3: vertex index 0 out of range (3 defined so far)");
        assert_eq!(err(&format!("{v}f -4 1 2\n")), "m.obj:4:3: vertex index -4 out of range (3 defined so far)");
        assert_eq!(
            err(&format!("{v}vt 0 0\nf 1/0 2/1 3/1\n")),
            "m.obj:5:3: texture coordinate index 0 out of range (1 defined so far)"
        );
        assert_eq!(err(&format!("{v}f 1//1 2//1 3//1\n")), "m.obj:4:3: normal index 1 out of range (0 defined so far)");
        assert_eq!(err(&format!("{v}f 1/1/1/1 2 3\n")), "m.obj:4:3: malformed face vertex `1/1/1/1`");
    }

    #[test]
    fn obj_face_with_two_vertices() {
        assert_eq!(err("v 0 0 0\nv 1 0 0\nf 1 2\n"), "m.obj:3: face has 2 vertices (a face needs at least 3)");
    }

    #[test]
    fn obj_non_finite_coordinate() {
        assert_eq!(err("v 0 nan 0\n"), "m.obj:1:5: non-finite coordinate `nan`");
        assert_eq!(err("vn 0 0 inf\n"), "m.obj:1:8: non-finite coordinate `inf`");
    }

    #[test]
    fn obj_crlf_comments_and_non_utf8_comments() {
        let mut bytes = b"# caf\xe9\r\nv 0 0 0 # end\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n".to_vec();
        bytes.extend_from_slice(b"l 1 2\r\n");
        let m = parse_obj(&bytes, Path::new("m.obj")).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2]]);
    }
}
