//! Binary PLY data: byte order, the fixed-stride vertex path and the single-list face path.

use std::marker::PhantomData;
use std::path::Path;

use super::generic::{read_element, Source};
use super::{index_error, truncated, Element, Header, Kind, Out, Role, Ty, VertexPlan};
use crate::mesh_io::{fan, too_few_vertices};
use crate::{Error, Location, Result};

pub(super) trait Order {
    fn u16(b: [u8; 2]) -> u16;
    fn u32(b: [u8; 4]) -> u32;
    fn u64(b: [u8; 8]) -> u64;
}
pub(super) struct Le;
pub(super) struct Be;
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
pub(super) fn read_int<E: Order>(ty: Ty, b: &[u8]) -> i64 {
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

pub(super) fn read_binary<E: Order>(
    bytes: &[u8],
    h: &Header,
    roles: &[Role],
    path: &Path,
    nv: u64,
    out: &mut Out,
) -> Result<()> {
    let mut src = Bin::<E> { path, bytes, pos: h.body, last: h.body, start: h.body, elem: None, order: PhantomData };
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
    // Bytes left over mean a count too small: the rest of the file would be dropped without a word.
    if src.pos < bytes.len() {
        let last = h.elements.last().map_or(String::new(), |e| format!(" (`{}`, {} claimed)", e.name, e.count));
        let msg = format!("{} bytes after the data of the last element{last}", bytes.len() - src.pos);
        return Err(Error::input(Location::byte(path, src.pos as u64), msg));
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
        let Kind::Scalar(ty) = p.kind else { unreachable!("stride() is Some") };
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
    let Kind::List { count, item } = e.props[0].kind else { unreachable!("index_list checked") };
    match (count, item) {
        (Ty::U8, Ty::I32) => {
            faces_loop(src, e, nv, out, (1, 4), |b| i64::from(b[0]), |b| i64::from(E::u32(arr(b)) as i32))
        }
        (Ty::U8, Ty::U32) => faces_loop(src, e, nv, out, (1, 4), |b| i64::from(b[0]), |b| i64::from(E::u32(arr(b)))),
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
