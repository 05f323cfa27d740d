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
