//! Which element's count disagrees with the data of an ASCII PLY.
//!
//! A header that claims one vertex too many makes the reader take the first face line for a vertex,
//! and the error then lands on the faces ("only 5 lines are left") or on a number; one vertex too few
//! makes a vertex line a face. When reading fails, the body is matched against the elements instead:
//! each element's entries are the lines that have its shape (one number per scalar property; a count
//! `k` then `k` numbers per list), and the first element whose run of such lines is not the length its
//! header line claims is named, at that header line. The reader's own error stands when the counts add
//! up to the lines (the fault is inside a line), when the data simply ends (the size check names the
//! element already) and when two consecutive elements share a shape, so that the boundary cannot be
//! told.

use std::path::Path;

use super::binary::{read_int, Order};
use super::header::{Element, Header, Kind};
use crate::mesh_io::{Lines, Tokens};
use crate::{Error, Location};

/// The element whose count disagrees with the ASCII body, as an error at its header line.
pub(super) fn disagreeing_count(h: &Header, bytes: &[u8], path: &Path) -> Option<Error> {
    let lines: Vec<&[u8]> =
        Lines::new(&bytes[h.body..], h.body_line).map(|(_, l)| l).filter(|l| !l.trim_ascii().is_empty()).collect();
    // Counts that add up to the lines: the failure is inside a line (a bad number, an extra value).
    if h.elements.iter().map(|e| e.count).sum::<u64>() == lines.len() as u64 {
        return None;
    }
    let mut at = 0usize;
    for (i, e) in h.elements.iter().enumerate() {
        let run = lines[at..].iter().take_while(|l| fits(e, l)).count() as u64;
        if run < e.count && at + run as usize == lines.len() {
            // The data ends inside this element: the size check before reading already says so.
            return None;
        }
        if run < e.count {
            let msg = format!(
                "element `{}` claims {} entries but the data has {run} (then a line of another shape)",
                e.name, e.count
            );
            return Some(Error::input(Location::at(path, e.line, 0), msg));
        }
        if run > e.count {
            // More lines of this shape than claimed: a count too small, unless the next element's entries
            // look the same, and the extra lines may be its own.
            let boundary = lines[at + e.count as usize];
            if h.elements.get(i + 1).is_some_and(|next| fits(next, boundary)) {
                return None;
            }
            let more = if i + 1 == h.elements.len() { "" } else { " before the next element" };
            let msg = format!("element `{}` claims {} entries but the data has {run}{more}", e.name, e.count);
            return Some(Error::input(Location::at(path, e.line, 0), msg));
        }
        at += run as usize;
    }
    None
}

/// True when `line` has the shape of one entry of `e`.
fn fits(e: &Element, line: &[u8]) -> bool {
    let mut toks = Tokens::new(line).map(|(_, t)| t);
    let number = |t: Option<&[u8]>| t.and_then(|t| std::str::from_utf8(t).ok()?.parse::<f64>().ok());
    for p in &e.props {
        match p.kind {
            Kind::Scalar(_) => {
                if number(toks.next()).is_none() {
                    return false;
                }
            }
            Kind::List { .. } => {
                let Some(k) = toks.next().and_then(|t| std::str::from_utf8(t).ok()?.parse::<u32>().ok()) else {
                    return false;
                };
                for _ in 0..k {
                    if number(toks.next()).is_none() {
                        return false;
                    }
                }
            }
        }
    }
    toks.next().is_none()
}

/// How far from its claim a binary element's count is looked for.
const BINARY_SEARCH: u64 = 64;

/// The element whose count disagrees with the binary body, as an error at its header line.
///
/// Binary data has no lines to match, so the counts are tried instead: an element of fixed-size entries
/// whose claimed count leaves the elements after it unreadable, while a count at most
/// [`BINARY_SEARCH`] away lets them fill the rest of the file exactly (faces with at least three
/// corners, every index below the vertex count), is the one named. Elements after the first one with
/// lists are not tried: where they start depends on every list before them.
pub(super) fn disagreeing_count_binary<E: Order>(h: &Header, bytes: &[u8], path: &Path) -> Option<Error> {
    let body = &bytes[h.body..];
    let mut at = 0u64;
    for (i, e) in h.elements.iter().enumerate() {
        let stride = e.stride()? as u64;
        let tail = &h.elements[i + 1..];
        if tail.is_empty() {
            return None;
        }
        let vertices = |n: u64| if e.name == "vertex" { n } else { vertex_count(h) };
        if ends_exactly::<E>(tail, body, at + e.count * stride, vertices(e.count)) {
            at += e.count * stride;
            continue;
        }
        let candidates = (1..=BINARY_SEARCH).flat_map(|d| [e.count.checked_sub(d), e.count.checked_add(d)]).flatten();
        for n in candidates {
            if ends_exactly::<E>(tail, body, at + n * stride, vertices(n)) {
                let msg = format!(
                    "element `{}` claims {} entries but the data holds {n} (then the elements after it fill the \
                     file exactly)",
                    e.name, e.count
                );
                return Some(Error::input(Location::at(path, e.line, 0), msg));
            }
        }
        return None;
    }
    None
}

fn vertex_count(h: &Header) -> u64 {
    h.elements.iter().find(|e| e.name == "vertex").map_or(0, |e| e.count)
}

/// True when `elements`, read from `start`, end exactly at the end of `body` with plausible faces.
fn ends_exactly<E: Order>(elements: &[Element], body: &[u8], start: u64, vertices: u64) -> bool {
    let Ok(mut pos) = usize::try_from(start) else { return false };
    for e in elements {
        let face = e.name == "face";
        for _ in 0..e.count {
            for p in &e.props {
                match p.kind {
                    Kind::Scalar(t) => pos += t.size(),
                    Kind::List { count, item } => {
                        let Some(b) = body.get(pos..pos + count.size()) else { return false };
                        let k = read_int::<E>(count, b);
                        pos += count.size();
                        let indices = face && (p.name == "vertex_indices" || p.name == "vertex_index");
                        if k < 0 || (indices && k < 3) {
                            return false;
                        }
                        for _ in 0..k {
                            let Some(b) = body.get(pos..pos + item.size()) else { return false };
                            if indices && !(0..vertices as i64).contains(&read_int::<E>(item, b)) {
                                return false;
                            }
                            pos += item.size();
                        }
                    }
                }
                if pos > body.len() {
                    return false;
                }
            }
        }
    }
    pos == body.len()
}
