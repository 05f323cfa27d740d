//! Merging partial images: tiles side by side, sample ranges added, into the image a single process
//! would have rendered, bit for bit.
//!
//! Rules, each refused with a message naming the file: every part has the identity, frame, samples per
//! pixel and radiance scale of the first; no pixel gets the same sample twice (overlapping tiles or
//! sample ranges); and every pixel gets every sample `0..spp` (no missing tile, no gap between ranges).
//!
//! Algorithm: parts are visited by sample start; a per-pixel counter holds the next sample expected, so a
//! part starting below it overlaps an earlier part and one starting above it leaves a gap no later part
//! can fill. Sums are exact integers, so the order of addition does not change the result. Cost: one
//! pass over every part's pixels, two `u32` and a sum per frame pixel, allocated fallibly.

use std::path::PathBuf;

use crate::accum::SampleSum;
use crate::error::{Error, Location, Result};
use crate::farm::Partial;
use crate::film::{try_filled, Film};
use crate::math::Color;

/// Merges `parts` (each with the file it came from, for messages) into the full frame.
pub fn merge(parts: &[(PathBuf, Partial)]) -> Result<Film> {
    let Some((first_path, first)) = parts.first() else {
        return Err(Error::Invalid("nothing to merge: no partial images given".into()));
    };
    let f = &first.sums;
    for (path, p) in &parts[1..] {
        let s = &p.sums;
        let differs = if p.identity != first.identity {
            Some("the scene, camera or options differ")
        } else if s.frame != f.frame {
            Some("the frame size differs")
        } else if s.spp != f.spp {
            Some("the samples per pixel differ")
        } else if s.scale.to_bits() != f.scale.to_bits() {
            Some("the radiance scale differs")
        } else {
            None
        };
        if let Some(what) = differs {
            let msg = format!("not from the same render as {} ({what})", first_path.display());
            return Err(Error::input(Location::file(path), msg));
        }
    }
    let (w, h) = f.frame;
    let mut next = try_filled(0u32, w, h)?;
    let mut by = try_filled(u32::MAX, w, h)?;
    let mut total = try_filled(SampleSum::default(), w, h)?;
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&i| (parts[i].1.sums.samples.0, parts[i].1.sums.window.1, parts[i].1.sums.window.0));
    for i in order {
        let (path, p) = &parts[i];
        let s = &p.sums;
        let (x0, y0, x1, _) = s.window;
        let (k0, k1) = s.samples;
        for (j, sum) in s.sums.iter().enumerate() {
            let (x, y) = (x0 + j as u32 % (x1 - x0), y0 + j as u32 / (x1 - x0));
            let at = (y * w + x) as usize;
            if next[at] > k0 {
                let other = &parts[by[at] as usize].0;
                let msg = format!("samples {k0}..{k1} of pixel ({x}, {y}) are also in {}", other.display());
                return Err(Error::input(Location::file(path), msg));
            }
            if next[at] < k0 {
                return Err(missing(x, y, next[at], k0));
            }
            next[at] = k1;
            by[at] = i as u32;
            total[at].add(sum);
        }
    }
    if let Some(at) = next.iter().position(|&k| k != f.spp) {
        return Err(missing(at as u32 % w, at as u32 / w, next[at], f.spp));
    }
    let mut film = Film { width: w, height: h, pixels: try_filled(Color::ZERO, w, h)? };
    for (p, s) in film.pixels.iter_mut().zip(&total) {
        *p = s.value(f.scale, f.spp);
    }
    Ok(film)
}

fn missing(x: u32, y: u32, from: u32, to: u32) -> Error {
    Error::Invalid(format!("the parts do not cover pixel ({x}, {y}): no part has its samples {from}..{to}"))
}
