//! Closest hits of coherent rays a packet at a time: up to [`PACKET`] consecutive rays of a batch that
//! start close together and point the same way (a camera's neighbouring pixels, a scanner's parallel
//! beams) walk the tree once, each node's eight boxes tested once for all of them with interval
//! arithmetic over their origins and reciprocal directions (Wald, Boulos and Shirley 2007, "Ray tracing
//! deformable scenes using dynamic bounding volume hierarchies", the interval test of large packets;
//! Reshetov, Soupikov and Hurley 2005, "Multi-level ray tracing algorithm"), while leaves test each ray
//! on its own with the same triangle test as the single query.
//!
//! Invariant: a ray of a packet meets every leaf its own traversal would keep, so it gets the same hit
//! (the closest, ties to the lowest index, whatever the order leaves are met in: `closest.rs` of the
//! accel). The single query keeps a box when `near <= far + slack` in its rounded arithmetic
//! (`kernel.rs`). Rounding is monotone, so the same expressions evaluated at the corners of the
//! packet's intervals bound every ray's values: the packet's `near` is at most each ray's, its `far`
//! and `slack` at least each ray's (all its rays share the major axis that sizes the slack), so a box
//! any ray keeps, the packet keeps. Where a product is NaN (a zero direction component meeting a plane
//! the origin lies on) the single test ignores that axis; the packet then leaves that axis
//! unconstrained. At a leaf, each ray first takes its own test of the leaf's box (the single query's
//! arithmetic, `kernel::lane_test`) with its own best distance, and skips only a leaf that test prunes.
//!
//! Cost: a node test is about three single-ray tests (four corner products per plane instead of one),
//! paid once per packet; leaves are paid per ray, for the union of the leaves the packet meets. Rays that
//! form no packet keep the two-ray interleaved walk (`batch.rs`). A packet needs its rays' direction
//! signs, zero components and major axis to agree; beyond that, spreads that make the boxes' intervals
//! loose cost time, never hits, so [`MAX_SPREAD`] only keeps the test worth its price; and where rays
//! are sparser than the leaves a packet's rays part at once, so one that makes more node tests than it
//! has rays sends the next [`SKIP`] rays the single way.

use std::mem::MaybeUninit;

use super::batch::{check_lengths, many, ClosestWalk};
use super::dispatch::{run_with, Traversal};
use super::kernel::{lane_test, Kernel, Lanes, NodeTest};
use super::leaves::{prepare, LeafRay, Leaves};
use super::visit::STACK;
use super::{Node8, Ref, Wide, WIDTH};
use crate::accel::closest::{trivially_misses, ClosestHit};
use crate::accel::{Hit, Primitives, TraversalCounts, BOX_SLACK};
use crate::geometry::major_axis;
use crate::math::{Ray, Vec3};

/// Most rays in a packet.
pub(super) const PACKET: usize = 16;
/// Rays sent the single way after a packet that did not pay ([`Coherent`]).
const SKIP: usize = 256;
/// Fewest rays worth a packet: below it the rays go the single way.
pub(super) const MIN_PACKET: usize = 4;
/// Largest sine of the angle between a packet's first direction and each other one, and largest
/// spread of its origins (per axis, as a share of the diagonal of the tree's box).
const MAX_SPREAD: f32 = 1.0 / 64.0;

/// Closest-hit queries for a batch of rays in a coherent order with `kernel`'s node test, `out[i]` for
/// `rays[i]` in `(0, t_max[i])`: the same hits as [`super::intersect_with`] ray by ray, packets where
/// consecutive rays form them, the two-ray interleaved walk for the rest.
///
/// # Panics
/// When `rays`, `t_max` and `out` differ in length.
pub(in crate::accel::bvh) fn intersect_coherent_with<P: Primitives + ?Sized>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
) {
    check_lengths(rays, t_max, out.len());
    run_with(kernel, wide, indices, prims, Coherent { rays, t_max, out })
}

/// The queries of [`intersect_coherent_with`].
struct Coherent<'a> {
    rays: &'a [Ray],
    t_max: &'a [f32],
    out: &'a mut [Option<Hit>],
}

impl Traversal for Coherent<'_> {
    type Out = ();

    fn empty(self) {
        self.out.fill(None);
    }

    #[inline(always)]
    fn run<L: Leaves, K: NodeTest>(self, kernel: K, nodes: &[Node8], leaves: &L, root: Ref) {
        let Coherent { rays, t_max, out } = self;
        // A tree of one leaf: nothing for a packet to share.
        let size = if root.count == 0 { diagonal(&nodes[root.child as usize]) } else { f32::NAN };
        // Where rays form no packet, the next attempt backs off (doubling, up to 256 rays), so that
        // incoherent rays pay next to nothing for the attempts. One call of the interleaved walk, for
        // the rays up to the next packet, keeps its code in one place.
        let (n, mut start, mut skip) = (rays.len(), 0, 0);
        while start < n {
            let (mut i, mut backoff, mut found) = (start + skip, 1, None);
            while i < n && size.is_finite() {
                found = packet(&rays[i..], &t_max[i..], size);
                if found.is_some() {
                    break;
                }
                i += backoff;
                backoff = (2 * backoff).min(256);
            }
            let end = if found.is_some() { i } else { n };
            if start < end {
                many::<ClosestWalk, L, K>(
                    kernel,
                    nodes,
                    leaves,
                    root,
                    &rays[start..end],
                    &t_max[start..end],
                    &mut out[start..end],
                );
            }
            let Some((len, bounds)) = found else { break };
            let tests =
                trace(nodes, leaves, root, &bounds, &rays[i..i + len], &t_max[i..i + len], &mut out[i..i + len]);
            // A packet whose rays went separate ways (rays sparser than the leaves: more than one node
            // test per ray, each about three single visits) costs more than its rays alone: the next
            // rays of the batch go the single way before packets are tried again.
            skip = if tests > len { SKIP } else { 0 };
            start = i + len;
        }
    }
}

/// The diagonal of the box of `node`'s children (unused lanes, inverted, drop out).
fn diagonal(node: &Node8) -> f32 {
    let mut d = 0.0f32;
    for a in 0..3 {
        let lo = node.min[a].iter().fold(f32::INFINITY, |m, &x| m.min(x));
        let hi = node.max[a].iter().fold(f32::NEG_INFINITY, |m, &x| m.max(x));
        d += (hi - lo) * (hi - lo);
    }
    d.sqrt()
}

/// What a packet's node test needs: per axis the intervals of the rays' origins and reciprocal
/// directions, whether the direction is zero there (for all the rays alike), and the shared major axis.
pub(super) struct Bounds {
    o: [[f32; 2]; 3],
    inv: [[f32; 2]; 3],
    negative: [bool; 3],
    infinite: [bool; 3],
    major: usize,
}

/// The signature that rays must share to form a packet, as bits: per axis the sign of the reciprocal
/// direction and whether it is infinite, and the major axis.
#[inline(always)]
fn signature(ray: &Ray) -> u32 {
    let mut sig = (major_axis(ray.dir) as u32) << 6;
    for (a, x) in ray.inv_dir.to_array().into_iter().enumerate() {
        let bits = x.to_bits();
        sig |= (bits >> 31) << a | ((bits & 0x7fff_ffff == 0x7f80_0000) as u32) << (a + 3);
    }
    sig
}

/// The packet that starts at `rays[0]`: its length (at most [`PACKET`]) and bounds, or `None` when
/// fewer than [`MIN_PACKET`] rays form one. `size` is the diagonal of the tree's box.
pub(super) fn packet(rays: &[Ray], t_max: &[f32], size: f32) -> Option<(usize, Bounds)> {
    let first = &rays[0];
    if trivially_misses(first, t_max[0]) {
        return None;
    }
    let sig = signature(first);
    let (d0, len0) = (first.dir, first.dir.length_squared());
    let reach = size * MAX_SPREAD;
    let (mut olo, mut ohi, mut ilo, mut ihi) = (first.origin, first.origin, first.inv_dir, first.inv_dir);
    let mut n = 1;
    while n < PACKET.min(rays.len()) {
        let r = &rays[n];
        // The sine of the angle between the directions, squared, without a square root.
        let sin2 = r.dir.cross(d0).length_squared();
        if trivially_misses(r, t_max[n])
            || signature(r) != sig
            || sin2 > MAX_SPREAD * MAX_SPREAD * len0 * r.dir.length_squared()
            || (r.origin - first.origin).abs().max_element() > reach
        {
            break;
        }
        // Finite and of one sign per axis (or the same infinity): the plain minimum and maximum.
        (olo, ohi) = (olo.min(r.origin), ohi.max(r.origin));
        (ilo, ihi) = (ilo.min(r.inv_dir), ihi.max(r.inv_dir));
        n += 1;
    }
    (n >= MIN_PACKET).then(|| {
        let pair = |lo: Vec3, hi: Vec3| std::array::from_fn(|a| [lo[a], hi[a]]);
        let b = |bit: u32| std::array::from_fn(|a| sig >> (a as u32 + bit) & 1 == 1);
        (
            n,
            Bounds {
                o: pair(olo, ohi),
                inv: pair(ilo, ihi),
                negative: b(0),
                infinite: b(3),
                major: (sig >> 6) as usize,
            },
        )
    })
}

/// The length of the packet that starts at `rays[0]`, 0 for none ([`packet`]).
#[cfg(test)]
pub(super) fn packet_len(rays: &[Ray], t_max: &[f32], size: f32) -> usize {
    packet(rays, t_max, size).map_or(0, |(n, _)| n)
}

impl Bounds {
    /// The lanes of `node` that some ray of the packet may meet in `[0, t_far]`, with a lower bound of
    /// their entry distances and an upper bound of their slacks over the packet's rays.
    #[inline(always)]
    fn test(&self, node: &Node8, t_far: f32) -> (u32, [f32; WIDTH], [f32; WIDTH]) {
        let mut near = [0.0f32; WIDTH];
        let mut far = [t_far; WIDTH];
        let mut scale = [0.0f32; WIDTH];
        for a in 0..3 {
            let (enter, exit) =
                if self.negative[a] { (&node.max[a], &node.min[a]) } else { (&node.min[a], &node.max[a]) };
            let ([olo, ohi], [ilo, ihi]) = (self.o[a], self.inv[a]);
            let (nan, major) = (self.infinite[a], a == self.major);
            // Branch-free over the lanes, so that they vectorize: the choices are per axis.
            for l in 0..WIDTH {
                // `(plane - o) * inv` at the corners: subtraction falls as `o` grows, and each product
                // is monotone in either factor, so the corners hold every ray's rounded value.
                let (t0lo, t0hi) = corners(enter[l] - ohi, enter[l] - olo, ilo, ihi, nan);
                let (t1lo, t1hi) = corners(exit[l] - ohi, exit[l] - olo, ilo, ihi, nan);
                near[l] = max(near[l], t0lo);
                far[l] = min(far[l], t1hi);
                let s = max(max(t0lo.abs(), t0hi.abs()), max(t1lo.abs(), t1hi.abs()));
                scale[l] = if major { s } else { scale[l] };
            }
        }
        let mut mask = 0;
        let mut slack = [0.0f32; WIDTH];
        for l in 0..WIDTH {
            slack[l] = scale[l] * BOX_SLACK;
            mask |= ((near[l] <= far[l] + slack[l]) as u32) << l;
        }
        (mask, near, slack)
    }
}

/// `a` when it is not below `b` (NaN never is: then `b`), as one compare and select.
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// `a` when it is below `b` (NaN never is: then `b`).
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// The least and greatest of `d * inv` over `d` in `[dlo, dhi]` and `inv` in `[ilo, ihi]`, from the
/// four corners. Where a NaN may be (`nan`: an infinite `inv`, which the rays share), a NaN corner
/// (`0 * inf`, a zero `d`) makes it `(-inf, +inf)`: an axis the single test ignores.
#[inline(always)]
fn corners(dlo: f32, dhi: f32, ilo: f32, ihi: f32, nan: bool) -> (f32, f32) {
    let (p0, p1, p2, p3) = (dlo * ilo, dlo * ihi, dhi * ilo, dhi * ihi);
    let (lo, hi) = (min(min(p0, p1), min(p2, p3)), max(max(p0, p1), max(p2, p3)));
    let any_nan = nan && (dlo == 0.0 || dhi == 0.0);
    (if any_nan { f32::NEG_INFINITY } else { lo }, if any_nan { f32::INFINITY } else { hi })
}

/// A node or leaf waiting on the packet's stack, with its bounds over the packet's rays, and where its
/// box is: lane `lane` of node `node` (`u32::MAX` for the root, which has none).
#[derive(Clone, Copy)]
struct Entry {
    r: Ref,
    near: f32,
    slack: f32,
    node: u32,
    lane: u32,
}

/// The closest hits of the packet `rays` (in `(0, t_max[i])`) into `out`, from `root`; returns the
/// number of node tests it made.
#[inline(always)]
fn trace<L: Leaves>(
    nodes: &[Node8],
    leaves: &L,
    root: Ref,
    bounds: &Bounds,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
) -> usize {
    let n = rays.len();
    debug_assert!((MIN_PACKET..=PACKET).contains(&n));
    let mut q: [Option<(Lanes, LeafRay)>; PACKET] = Default::default();
    let mut best = [ClosestHit::new(0.0); PACKET];
    for i in 0..n {
        q[i] = Some(prepare(&rays[i]));
        best[i] = ClosestHit::new(t_max[i]);
    }
    let t_far = |best: &[ClosestHit; PACKET]| best[..n].iter().fold(0.0f32, |m, b| m.max(b.t_far()));
    let mut far = t_far(&best);
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
    stack[0] = MaybeUninit::new(Entry { r: root, near: 0.0, slack: 0.0, node: u32::MAX, lane: 0 });
    let (mut sp, mut tests) = (1, 0);
    while sp > 0 {
        sp -= 1;
        // SAFETY: the entries below `sp` were written (the root, then each node's children).
        let e = unsafe { stack[sp].assume_init() };
        if e.near > far + e.slack {
            continue;
        }
        if e.r.count != 0 {
            let mut counts = TraversalCounts::default();
            for i in 0..n {
                let Some((lanes, q)) = q[i].as_mut() else { continue };
                // The ray's own box test, as its single query makes it (the packet's bounds are looser):
                // a leaf it prunes cannot hold its closest hit.
                let t = best[i].t_far();
                if e.near > t + e.slack
                    || (e.node != u32::MAX && !lane_test(lanes, &nodes[e.node as usize], e.lane as usize, t).0)
                {
                    continue;
                }
                leaves.closest::<false>(e.r, q, &mut best[i], &mut counts);
            }
            far = t_far(&best);
            continue;
        }
        let node = &nodes[e.r.child as usize];
        let (mask, near, slack) = bounds.test(node, far);
        tests += 1;
        // Farthest first, so that the nearest child is popped next.
        let base = sp;
        let mut m = mask;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let r = Ref { child: node.child[l], count: node.count[l] };
            let c = Entry { r, near: near[l], slack: slack[l], node: e.r.child, lane: l as u32 };
            let mut j = sp;
            // SAFETY: entries `base..sp` were written above.
            while j > base && unsafe { stack[j - 1].assume_init_ref() }.near < c.near {
                stack[j] = stack[j - 1];
                j -= 1;
            }
            stack[j] = MaybeUninit::new(c);
            sp += 1;
        }
    }
    for i in 0..n {
        out[i] = best[i].hit();
    }
    tests
}
