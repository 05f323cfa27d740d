//! Front-to-back traversal with a stack of cells and their `t` intervals: an inner cell pushes the
//! octants the ray crosses, sorted so that the nearest is popped first; a leaf tests its primitives and
//! ends the query when the closest hit lies well inside the cell.
//!
//! Exactness against brute force (the same reasoning as `accel::bvh::traverse`):
//! - a primitive reaches past its cells, so a hit found in a leaf can be beaten by a primitive met in
//!   a later cell; it is final only when its `t` is below the cell's exit. Any closer (or equally close)
//!   hit point lies in a cell already visited or in this one, and the primitive is referenced there
//!   (the build's margin keeps that true when rounding puts a reported hit a hair off the triangle).
//!   Cells of a regular subdivision never cut one another, so the cells still on the stack begin where
//!   this one ends. Cells are also skipped when their entry lies beyond the best `t`, and a leaf asks
//!   primitives for hits up to the float just above the best `t`, so ties go to the lowest index;
//! - a primitive met again in a later cell is not retested ([`Mailbox`]): its answer cannot change;
//! - interval tests are conservative: cells are entered when their interval, widened by a slack on
//!   both ends, is not empty, skipped only when their entry minus the slack exceeds the best `t`, and a
//!   hit ends the query only when it is below the exit minus twice the slack. The slack covers the
//!   rounding of the watertight test's `t`, whose error scales with the distances of the triangle's
//!   corners along the ray's major axis: those corners lie in the root cell, so the slack is
//!   [`SLACK`] times the larger of the root's two slab distances on that axis (the BVH uses the same
//!   ratio per node). Visiting a cell too many costs time; missing one could change the answer;
//! - a ray parallel to a slab with its origin on the slab's plane gives `0 * inf = NaN`, which `max`
//!   and `min` ignore: the ray counts as inside that slab (the closed-cell answer). Children share
//!   bit-identical faces with their neighbours, so their intervals meet exactly.
//!
//! Cost: per inner cell, nine plane distances and a sort of at most eight entries (a ray crosses at most
//! four octants, more only along split planes); at most eight cells are pushed per level, which sizes
//! the stack.

use super::{child_box, split_point, Octree, MAX_DEPTH};
use crate::accel::closest::{trivially_misses, ClosestHit};
use crate::accel::{Hit, Primitives, TraversalCounts};
use crate::math::{Aabb, Ray, Vec3};

/// The shared slack of box and interval tests ([`crate::accel::BOX_SLACK`]).
const SLACK: f32 = crate::accel::BOX_SLACK;

/// Deepest stack: each inner level pops one cell and pushes at most eight, and leaves are at depth
/// [`MAX_DEPTH`] at most, so `1 + 7 * MAX_DEPTH` entries.
const STACK: usize = 1 + 7 * MAX_DEPTH;

/// A ray prepared for interval tests.
struct RayCells {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    negative: [bool; 3],
    slack: f32,
}

impl RayCells {
    fn new(ray: &Ray, root: &Aabb) -> Self {
        let inv = ray.inv_dir;
        let d = ray.dir.abs();
        let major = if d.x > d.y && d.x > d.z {
            0
        } else if d.y > d.z {
            1
        } else {
            2
        };
        let t0 = (root.min[major] - ray.origin[major]) * inv[major];
        let t1 = (root.max[major] - ray.origin[major]) * inv[major];
        RayCells {
            origin: ray.origin.to_array(),
            inv_dir: inv.to_array(),
            negative: [inv.x.is_sign_negative(), inv.y.is_sign_negative(), inv.z.is_sign_negative()],
            slack: SLACK * t0.abs().max(t1.abs()),
        }
    }

    /// The parameter interval of `b` along the ray, clipped below at 0 (not widened).
    #[inline]
    fn interval(&self, b: &Aabb) -> (f32, f32) {
        let mut entry = 0.0f32;
        let mut exit = f32::INFINITY;
        for a in 0..3 {
            let (near, far) = if self.negative[a] { (b.max[a], b.min[a]) } else { (b.min[a], b.max[a]) };
            // `f32::max`/`min` return the other operand when one is NaN.
            entry = entry.max((near - self.origin[a]) * self.inv_dir[a]);
            exit = exit.min((far - self.origin[a]) * self.inv_dir[a]);
        }
        (entry, exit)
    }

    /// Whether a cell with interval `(entry, exit)` may hold a hit below `limit`.
    #[inline]
    fn visits(&self, entry: f32, exit: f32, limit: f32) -> bool {
        entry - self.slack <= exit + self.slack && entry - self.slack <= limit
    }

    /// The intervals of the eight octants of `b` cut at `mid`: the nine plane distances are computed
    /// once, with the same expressions as [`RayCells::interval`] on each octant's box (bit-identical).
    #[inline]
    fn octant_intervals(&self, b: &Aabb, mid: Vec3) -> [(f32, f32); 8] {
        // Per axis, (near, far) of the lower and the upper half.
        let mut halves = [[(0.0f32, 0.0f32); 2]; 3];
        for (a, h) in halves.iter_mut().enumerate() {
            let t = |x: f32| (x - self.origin[a]) * self.inv_dir[a];
            let (lo, m, hi) = (t(b.min[a]), t(mid[a]), t(b.max[a]));
            *h = if self.negative[a] { [(m, lo), (hi, m)] } else { [(lo, m), (m, hi)] };
        }
        let [x, y, z] = halves;
        std::array::from_fn(|k| {
            let ((nx, fx), (ny, fy), (nz, fz)) = (x[k & 1], y[(k >> 1) & 1], z[k >> 2]);
            (0.0f32.max(nx).max(ny).max(nz), f32::INFINITY.min(fx).min(fy).min(fz))
        })
    }
}

/// A cell waiting on the stack: octant `octant` of the last cell expanded at `depth - 1` (kept in
/// `expanded`, see [`traverse`]), which keeps entries at 16 bytes.
#[derive(Clone, Copy)]
struct Pending {
    node: u32,
    entry: f32,
    exit: f32,
    depth: u8,
    octant: u8,
}

/// The closest hit in `(0, t_max)`, ties to the lowest index; with `ANY`, the first hit found (for
/// `occluded`). With `COUNT`, cells visited and primitives tested are added to `counts`.
pub(super) fn traverse<P: Primitives + ?Sized, const COUNT: bool, const ANY: bool>(
    tree: &Octree,
    prims: &P,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    let (nodes, refs) = (&tree.nodes, &tree.refs);
    if nodes.is_empty() || trivially_misses(ray, t_max) {
        return None;
    }
    let rc = RayCells::new(ray, &tree.root);
    let (entry, exit) = rc.interval(&tree.root);
    if !rc.visits(entry, exit, t_max) {
        return None;
    }
    let root = Pending { node: 0, entry, exit, depth: 0, octant: 0 };
    let mut stack = [root; STACK];
    // The cell last expanded at each depth. Depth first, the entries on the stack above an entry of
    // depth `d - 1` are octants of the cell expanded after it was pushed, `expanded[d - 1]`, which
    // stays in place until they are all popped.
    let mut expanded = [tree.root; MAX_DEPTH + 1];
    let mut sp = 1;
    let mut best = ClosestHit::new(t_max);
    let mut mailbox = Mailbox::default();
    while sp > 0 {
        sp -= 1;
        let p = stack[sp];
        if p.entry - rc.slack > best.t_far() {
            continue;
        }
        if COUNT {
            counts.nodes += 1;
        }
        let node = nodes[p.node as usize];
        let depth = p.depth as usize;
        if node.is_leaf() {
            for &prim in &refs[node.range()] {
                if !mailbox.first_visit(prim) {
                    continue;
                }
                if ANY {
                    // Shadow rays want any hit: a primitive that is itself a structure may stop early.
                    if prims.occludes(prim as usize, ray, best.t_query()) {
                        return Some(Hit { t: 0.0, prim, u: 0.0, v: 0.0, sub: 0 });
                    }
                    continue;
                }
                let h = if COUNT {
                    prims.intersect_counted(prim as usize, ray, best.t_query(), counts)
                } else {
                    prims.intersect(prim as usize, ray, best.t_query())
                };
                if let Some(h) = h {
                    best.offer(Hit::new(prim, h));
                }
            }
            if best.hit().is_some() && best.t_far() < p.exit - 2.0 * rc.slack {
                return best.hit();
            }
            continue;
        }
        // Children crossed, sorted by decreasing entry so that the nearest is popped first.
        let cell = if depth == 0 {
            tree.root
        } else {
            let parent = &expanded[depth - 1];
            child_box(parent, split_point(parent), p.octant as usize)
        };
        expanded[depth] = cell;
        let mid = split_point(&cell);
        let intervals = rc.octant_intervals(&cell, mid);
        let mut crossed = [root; 8];
        let mut n = 0;
        for (k, &(entry, exit)) in intervals.iter().enumerate() {
            let child = node.offset + k as u32;
            if nodes[child as usize].count == 0 || !rc.visits(entry, exit, best.t_far()) {
                continue; // an empty leaf, or not crossed
            }
            let mut j = n;
            while j > 0 && crossed[j - 1].entry < entry {
                crossed[j] = crossed[j - 1];
                j -= 1;
            }
            crossed[j] = Pending { node: child, entry, exit, depth: p.depth + 1, octant: k as u8 };
            n += 1;
        }
        stack[sp..sp + n].copy_from_slice(&crossed[..n]);
        sp += n;
    }
    best.hit()
}

/// The last primitives tested (mailboxing, Arnaldi et al. 1987, here a small ring): a primitive
/// referenced by several cells along the ray is tested once. Skipping a repeat is exact: its hit, if
/// any, was already weighed against a best `t` that has only decreased since.
#[derive(Default)]
struct Mailbox {
    ids: [u32; MAILBOX],
    next: usize,
    full: bool,
}

/// Entries of the mailbox: a ray usually meets a few leaves of a few primitives before its hit.
const MAILBOX: usize = 16;

impl Mailbox {
    /// False when `prim` was tested recently; otherwise records it.
    #[inline]
    fn first_visit(&mut self, prim: u32) -> bool {
        let used = if self.full { MAILBOX } else { self.next };
        if self.ids[..used].contains(&prim) {
            return false;
        }
        self.ids[self.next] = prim;
        self.next = (self.next + 1) % MAILBOX;
        self.full |= self.next == 0;
        true
    }
}
