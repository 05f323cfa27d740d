//! Rendering on a farm: a frame cut into deterministic slices that separate processes render, and the
//! merge that puts them back together, equal byte for byte to a single-process render.
//!
//! - [`tile_window`]: tile `i` of `n` over a fixed grid that depends only on the frame size and `n`, so a
//!   scheduler's 0-based task index (Slurm's `SLURM_ARRAY_TASK_ID`, Kubernetes' `JOB_COMPLETION_INDEX`)
//!   maps straight to a tile.
//! - [`partial`]: a slice's result as an OpenEXR file: the frame (display window), the slice's window
//!   (data window), the exact per-pixel sample sums and weights, and the render's identity.
//! - [`merge()`]: checks that partials fit together (same render, no overlap, no gap in pixels or samples)
//!   and adds their sums; sums are exact integers ([`crate::accum`]), so grouping does not matter.

pub mod merge;
pub mod partial;

pub use merge::merge;
pub use partial::{decode_partial, encode_partial, read_partial, write_partial, Partial};

/// The tile grid for `n` tiles over a `w` x `h` frame, as `(cols, rows)` with `cols * rows == n`: of the
/// factorisations that give every tile at least one pixel, the one whose cells are closest to square
/// (smallest `|ln(cell width / cell height)|`; on a tie, fewer columns). `None` when no factorisation fits
/// or `n == 0`.
pub fn tile_grid(n: u32, w: u32, h: u32) -> Option<(u32, u32)> {
    let mut best: Option<((u32, u32), f64)> = None;
    for cols in (1..=n).filter(|c| n.is_multiple_of(*c)) {
        let rows = n / cols;
        if cols > w || rows > h {
            continue;
        }
        let badness = ((w as f64 / cols as f64) / (h as f64 / rows as f64)).ln().abs();
        let better = match best {
            None => true,
            Some((_, b)) => badness < b - 1e-12,
        };
        if better {
            best = Some(((cols, rows), badness));
        }
    }
    best.map(|(g, _)| g)
}

/// The window `(x0, y0, x1, y1)` of tile `i` (0-based, row-major from the top left) of `n` over a `w` x `h`
/// frame: column `c` spans pixels `c * w / cols .. (c + 1) * w / cols` (integer division), rows likewise,
/// so tile sizes differ by at most one pixel. An error in words when `n` is 0, `i >= n` or the grid does
/// not fit the frame.
pub fn tile_window(i: u32, n: u32, w: u32, h: u32) -> Result<(u32, u32, u32, u32), String> {
    if n == 0 {
        return Err("--tile I/N needs N >= 1".into());
    }
    if i >= n {
        return Err(format!("--tile {i}/{n}: the index is 0-based, so it must be below {n}"));
    }
    let (cols, rows) =
        tile_grid(n, w, h).ok_or_else(|| format!("--tile {i}/{n}: {n} tiles do not fit a {w}x{h} frame"))?;
    let cut = |k: u32, parts: u32, len: u32| (k as u64 * len as u64 / parts as u64) as u32;
    let (c, r) = (i % cols, i / cols);
    Ok((cut(c, cols, w), cut(r, rows, h), cut(c + 1, cols, w), cut(r + 1, rows, h)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn farm_tile_grid_is_most_square() {
        assert_eq!(tile_grid(4, 800, 800), Some((2, 2)));
        assert_eq!(tile_grid(9, 800, 600), Some((3, 3)));
        assert_eq!(tile_grid(2, 800, 400), Some((2, 1)));
        assert_eq!(tile_grid(2, 400, 800), Some((1, 2)));
        assert_eq!(tile_grid(7, 700, 10), Some((7, 1)));
        assert_eq!(tile_grid(6, 2, 2), None);
        assert_eq!(tile_grid(0, 2, 2), None);
    }

    #[test]
    fn farm_tiles_cover_the_frame_once() {
        for (n, w, h) in [(1, 5, 3), (4, 801, 599), (9, 100, 100), (6, 37, 11), (5, 5, 5)] {
            let mut hits = vec![0u8; (w * h) as usize];
            for i in 0..n {
                let (x0, y0, x1, y1) = tile_window(i, n, w, h).expect("fits");
                assert!(x0 < x1 && y0 < y1);
                for y in y0..y1 {
                    for x in x0..x1 {
                        hits[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(hits.iter().all(|&c| c == 1), "{n} tiles over {w}x{h}");
        }
    }

    #[test]
    fn farm_tile_errors_say_why() {
        assert_eq!(tile_window(0, 0, 8, 8).unwrap_err(), "--tile I/N needs N >= 1");
        assert_eq!(tile_window(4, 4, 8, 8).unwrap_err(), "--tile 4/4: the index is 0-based, so it must be below 4");
        assert_eq!(tile_window(0, 7, 3, 3).unwrap_err(), "--tile 0/7: 7 tiles do not fit a 3x3 frame");
    }
}
