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
//! common count and index types, so neither dispatches per property (`binary.rs`). Anything else goes
//! through the generic path (`generic.rs`), one `Source` call per value. Nothing is allocated per
//! vertex or per face. The header and its size check are in `header.rs`.

mod binary;
mod counts;
mod generic;
mod header;

use std::path::Path;

use self::generic::{read_element, Ascii};
use self::header::{check_sizes, parse_header, Element, Format, Header, Kind, Property, Ty};
use crate::geometry::TriangleMesh;
use crate::math::{Vec2, Vec3};
use crate::mesh_io::vec_for;
use crate::{Error, Location, Result};

/// Parses a PLY file already in memory; `path` is only used in error messages.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<TriangleMesh> {
    let header = parse_header(bytes, path)?;
    parse_body(&header, bytes, path).map_err(|e| {
        let named = match header.format {
            Format::Ascii => counts::disagreeing_count(&header, bytes, path),
            Format::Le => counts::disagreeing_count_binary::<binary::Le>(&header, bytes, path),
            Format::Be => counts::disagreeing_count_binary::<binary::Be>(&header, bytes, path),
        };
        named.unwrap_or(e)
    })
}

fn parse_body(header: &Header, bytes: &[u8], path: &Path) -> Result<TriangleMesh> {
    check_sizes(header, bytes, path)?;
    let (roles, nv) = plan_roles(header, path)?;
    let faces: u64 = header.elements.iter().filter(|e| e.name == "face").map(|e| e.count).sum();
    let mut out = Out {
        positions: vec_for(nv, "vertices", path)?,
        normals: Vec::new(),
        uvs: Vec::new(),
        indices: vec_for(faces, "faces", path)?,
    };
    let plan = roles.iter().find_map(|r| match r {
        Role::Vertex(p) => Some(p),
        _ => None,
    });
    let (has_normals, has_uvs) = plan.map_or((false, false), |p| (p.normals, p.uvs));
    if has_normals {
        out.normals = vec_for(nv, "vertex normals", path)?;
    }
    if has_uvs {
        out.uvs = vec_for(nv, "texture coordinates", path)?;
    }
    match header.format {
        Format::Ascii => {
            let mut src = Ascii::new(path, &bytes[header.body..], header.body_line);
            for (e, role) in header.elements.iter().zip(&roles) {
                read_element(&mut src, e, role, nv, &mut out)?;
            }
            src.finish()?;
        }
        Format::Le => binary::read_binary::<binary::Le>(bytes, header, &roles, path, nv, &mut out)?,
        Format::Be => binary::read_binary::<binary::Be>(bytes, header, &roles, path, nv, &mut out)?,
    }
    Ok(TriangleMesh {
        positions: out.positions,
        indices: out.indices,
        normals: has_normals.then_some(out.normals),
        uvs: has_uvs.then_some(out.uvs),
    })
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
                    return Err(err(format!("{} vertices do not fit in 32-bit indices", e.count)));
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
    Ok(VertexPlan { slots, normals, uvs })
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
        let k = self.slots.iter().position(|&s| s == Some(slot)).unwrap_or(0);
        let msg = format!("vertex {i}: non-finite {} ({val})", e.props[k].name);
        Error::input(loc, msg)
    }
}

fn index_error(what: &str, i: u64, idx: i64, nv: u64, loc: Location) -> Error {
    let msg = format!("{what} {i}: vertex index {idx} out of range (the file has {nv} vertices)");
    Error::input(loc, msg)
}

fn truncated(path: &Path, pos: usize, e: &Element, i: u64, need: usize, left: usize) -> Error {
    let msg = format!("unexpected end of file in {} {i} of {} (needs {need} more bytes, {left} left)", e.name, e.count);
    Error::input(Location::byte(path, pos as u64), msg)
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
            let format = if le { "binary_little_endian" } else { "binary_big_endian" };
            let head = format!("ply\nformat {format} 1.0\n{header}end_header\n");
            W { le, buf: head.into_bytes() }
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
        assert_eq!(parse(crlf.as_bytes()).unwrap(), parse(CUBE.as_bytes()).unwrap());
    }

    /// Normals first, an ignored colour in the middle, uv as `s t`, indices as uint.
    fn shuffled(le: bool) -> Vec<u8> {
        let header = "element vertex 3\nproperty float nx\nproperty float ny\nproperty float nz\n\
property float x\nproperty uchar red\nproperty float y\nproperty float z\nproperty float s\n\
property float t\nelement face 1\nproperty list uchar uint vertex_indices\n";
        let mut w = W::new(le, header);
        for (i, p) in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().enumerate() {
            w.f32(0.0).f32(0.0).f32(1.0).f32(p[0]).u8(200).f32(p[1]).f32(p[2]);
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
        let uvs = vec![Vec2::new(0.0, 0.25), Vec2::new(0.5, 0.25), Vec2::new(1.0, 0.25)];
        assert_eq!(m.uvs, Some(uvs));
    }

    #[test]
    fn ply_binary_be_matches_le() {
        assert_eq!(parse(&shuffled(false)).unwrap(), parse(&shuffled(true)).unwrap());
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
            let want = [[0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, -1.0, 3.0]];
            assert_eq!(m.positions, want.map(Vec3::from_array).to_vec());
            assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        }
    }

    #[test]
    fn ply_ascii_faces_before_vertices_and_tristrips() {
        let src = "ply\nformat ascii 1.0\nelement tristrips 1\nproperty list int int vertex_indices\n\
element vertex 5\nproperty float x\nproperty float y\nproperty float z\nend_header\n\
8 0 1 2 3 -1 2 2 4\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 2 0\n";
        let m = parse(src.as_bytes()).unwrap();
        // 0 1 2 3 gives (0 1 2) and (2 1 3); the strip `2 2 4` is degenerate.
        assert_eq!(m.indices, vec![[0, 1, 2], [2, 1, 3]]);
        assert_eq!(
            err(src.replace("2 2 4", "2 2 9").as_bytes()),
            "m.ply:10:18: tristrips 0: vertex index 9 out of range (the file has 5 vertices)"
        );
    }

    #[test]
    fn ply_binary_generic_vertices_and_tristrips() {
        let header = "element vertex 4\nproperty list uchar float w\nproperty float x\n\
property float y\nproperty float z\nelement tristrips 1\nproperty list int int vertex_indices\n";
        for le in [true, false] {
            let mut w = W::new(le, header);
            for (x, y) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                w.u8(1).f32(9.0).f32(x).f32(y).f32(0.0);
            }
            w.i32(4).i32(0).i32(1).i32(2).i32(3);
            let m = parse(&w.buf).unwrap();
            assert_eq!(m.positions[3], Vec3::new(1.0, 1.0, 0.0));
            assert_eq!(m.indices, vec![[0, 1, 2], [2, 1, 3]]);
        }
    }

    #[test]
    fn ply_binary_negative_index_is_out_of_range() {
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar int vertex_indices\n";
        let mut w = W::new(true, header);
        for _ in 0..9 {
            w.f32(0.0);
        }
        w.u8(3).i32(0).i32(-1).i32(2);
        let at = w.buf.len() - 8;
        assert_eq!(
            err(&w.buf),
            format!("m.ply: byte {at}: face 0: vertex index -1 out of range (the file has 3 vertices)")
        );
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
    fn ply_binary_bytes_after_the_last_element_are_an_error() {
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar int vertex_indices\n";
        for le in [true, false] {
            let mut w = W::new(le, header);
            for v in [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
                w.f32(v);
            }
            w.u8(3).i32(0).i32(1).i32(2);
            let end = w.buf.len();
            assert_eq!(parse(&w.buf).unwrap().len(), 1);
            w.buf.extend_from_slice(b"junk");
            let want = format!("m.ply: byte {end}: 4 bytes after the data of the last element (`face`, 1 claimed)");
            assert_eq!(err(&w.buf), want);
            // A second face that the count leaves out.
            w.buf.truncate(end);
            w.u8(3).i32(0).i32(2).i32(1);
            let want = format!("m.ply: byte {end}: 13 bytes after the data of the last element (`face`, 1 claimed)");
            assert_eq!(err(&w.buf), want);
        }
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
            format!("m.ply: byte {}: unexpected end of file in vertex 0 of 1 (needs 12 more bytes, 4 left)", head + 9)
        );
        // The same through the generic path (a list in the vertex element).
        let header = "element vertex 1\nproperty list uchar float w\nproperty float x\n\
property float y\nproperty float z\n";
        let mut w = W::new(false, header);
        let head = w.buf.len();
        w.u8(2).f32(1.0).f32(2.0).f32(0.0);
        assert_eq!(
            err(&w.buf),
            format!("m.ply: byte {}: unexpected end of file in vertex 0 of 1 (needs 4 more bytes, 0 left)", head + 13)
        );
    }

    #[test]
    fn ply_header_claiming_too_many_elements_is_rejected() {
        let mut w =
            W::new(true, "element vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\n");
        w.f32(0.0);
        assert_eq!(
            err(&w.buf),
            "m.ply:3: element `vertex` claims 1000000000000 entries (at least 12000000000000 bytes) but only 4 bytes are left for it"
        );
        let ascii = CUBE.replace("element face 6", "element face 7");
        assert_eq!(err(ascii.as_bytes()), "m.ply:9: element `face` claims 7 entries but only 6 lines are left for it");
    }

    #[test]
    fn ply_index_out_of_range() {
        let ascii = CUBE.replace("4 2 6 7 3", "4 2 6 8 3");
        assert_eq!(err(ascii.as_bytes()), "m.ply:24:7: face 4: vertex index 8 out of range (the file has 8 vertices)");
        let mut bytes = shuffled(false);
        let n = bytes.len();
        bytes[n - 4..].copy_from_slice(&3u32.to_be_bytes());
        assert_eq!(
            err(&bytes),
            format!("m.ply: byte {}: face 0: vertex index 3 out of range (the file has 3 vertices)", n - 4)
        );
    }

    #[test]
    fn ply_nan_vertex() {
        let ascii = CUBE.replace("1 1 1\n", "1 nan 1\n");
        assert_eq!(err(ascii.as_bytes()), "m.ply:17: vertex 5: non-finite y (NaN)");
        let mut w = W::new(true, "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n");
        w.f32(0.0).f32(0.0).f32(0.0).f32(1.0).f32(f32::INFINITY).f32(0.0);
        let at = w.buf.len() - 12;
        assert_eq!(err(&w.buf), format!("m.ply: byte {at}: vertex 1: non-finite y (inf)"));
    }

    #[test]
    fn ply_face_with_two_vertices() {
        let ascii = CUBE.replace("4 0 4 5 1", "2 0 4");
        assert_eq!(err(ascii.as_bytes()), "m.ply:22: face 2 has 2 vertices (a face needs at least 3)");
        let mut bytes = shuffled(true);
        let n = bytes.len();
        bytes[n - 13] = 2;
        assert_eq!(err(&bytes), format!("m.ply: byte {}: face 0 has 2 vertices (a face needs at least 3)", n - 13));
    }

    #[test]
    fn ply_malformed_ascii_number() {
        let ascii = CUBE.replace("0 1 0\n", "0 1x 0\n");
        assert_eq!(err(ascii.as_bytes()), "m.ply:14:3: malformed number `1x`");
    }

    #[test]
    fn ply_header_errors() {
        assert_eq!(err(b"PLY\n"), "m.ply:1: not a PLY file (the first line must be `ply`)");
        assert_eq!(err(b"ply\nformat ascii 1.0\nelement vertex 0\n"), "m.ply: header has no `end_header` line");
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
            err(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float\nend_header\n"),
            "m.ply:4: malformed property line (expected `property <type> <name>` \
             or `property list <count type> <item type> <name>`)"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
            "m.ply:3: property before any element"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nend_header\n"),
            "m.ply:3: element `vertex` has no scalar property `z`"
        );
        assert_eq!(err(b"ply\nelement vertex 0\nend_header\n"), "m.ply:3: no `format` line before `end_header`");
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement face 0\nproperty list float int vertex_indices\nend_header\n"),
            "m.ply:4:15: list count type must be an integer type, not `float`"
        );
        assert_eq!(err(b"ply\nformat ascii 1.0\nend_header\n"), "m.ply: no `vertex` element");
    }

    #[test]
    fn ply_ascii_count_that_disagrees_with_the_data_is_named_at_its_header_line() {
        let more = CUBE.replace("element vertex 8", "element vertex 9");
        assert_eq!(
            err(more.as_bytes()),
            "m.ply:5: element `vertex` claims 9 entries but the data has 8 (then a line of another shape)"
        );
        let fewer = CUBE.replace("element vertex 8", "element vertex 7");
        assert_eq!(
            err(fewer.as_bytes()),
            "m.ply:5: element `vertex` claims 7 entries but the data has 8 before the next element"
        );
    }

    #[test]
    fn ply_binary_count_that_disagrees_with_the_data_is_named_at_its_header_line() {
        // Four vertices and two triangles, the header claiming one vertex more or less.
        for (le, claim) in [(true, 5), (false, 3), (true, 3)] {
            let header = format!(
                "element vertex {claim}\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 2\nproperty list uchar int vertex_indices\n"
            );
            let mut w = W::new(le, &header);
            for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                w.f32(x).f32(y).f32(0.0);
            }
            w.u8(3).i32(0).i32(1).i32(2).u8(3).i32(0).i32(2).i32(3);
            let want = format!(
                "m.ply:3: element `vertex` claims {claim} entries but the data holds 4 (then the elements after it \
                 fill the file exactly)"
            );
            assert_eq!(err(&w.buf), want, "{} claim {claim}", if le { "le" } else { "be" });
        }
    }

    #[test]
    fn ply_ascii_extra_value_is_an_error() {
        let ascii = CUBE.replace("0 1 0\n", "0 1 0 7\n");
        assert_eq!(err(ascii.as_bytes()), "m.ply:14:7: unexpected value `7` after the end of vertex 2");
    }

    #[test]
    fn ply_ascii_data_after_the_last_element_is_an_error() {
        let ascii = format!("{CUBE}\n  junk\n");
        assert_eq!(err(ascii.as_bytes()), "m.ply:27:3: unexpected `junk` after the data of the last element");
        // A seventh face: the count is named.
        let ascii = format!("{CUBE}3 0 1 2\n");
        assert_eq!(err(ascii.as_bytes()), "m.ply:9: element `face` claims 6 entries but the data has 7");
    }
}
