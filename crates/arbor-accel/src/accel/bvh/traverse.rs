//! Stack-based traversal of the flat node array (pbrt-v4's `BVHAggregate::Intersect`): the child on the
//! ray's side of the split axis is visited first, the other is pushed, and a popped node is tested
//! against the current best `t` so that nodes entirely behind the closest hit are skipped.
//!
//! Exactness against brute force:
//! - ties: a node whose entry distance *equals* the best `t` is still visited, and a leaf asks each
//!   primitive for hits up to the float just above the best `t`, keeping one at the same `t` when its
//!   index is lower (`ClosestHit`);
//! - box tests are conservative. The `t` a primitive reports carries its own rounding error, and that
//!   error is not relative to `t`: the watertight test computes `t` as a barycentric blend of the
//!   corners' distances along the ray's major axis, so its error scales with the largest of them, which
//!   can be far larger than `t` when the ray starts next to a big triangle. The corners lie in the box,
//!   so that scale is bounded by the box's own slab distances on the major axis; the exit distance is
//!   enlarged by [`SLACK`](crate::accel::BOX_SLACK) times the larger of them. Slab rounding (pbrt's `gamma(3)`) is far smaller.
//!   This is an argued bound, not a proof (a grazing ray on a sliver has larger barycentric error);
//!   the conformance suite, slivers included, still passes with 16 times less slack.
//!   Visiting a box too many costs time, never correctness; missing one could change the closest hit,
//!   or a tie's winner, relative to brute force;
//! - a ray parallel to a slab with its origin exactly on the slab's plane gives `0 * inf = NaN`; `max`
//!   and `min` ignore the NaN, which treats the ray as inside that slab, the closed-box answer.
//!
//! Cost: at most one push per level, so a stack of [`MAX_DEPTH`](super::MAX_DEPTH) entries suffices.
//!
//! Queries run on the 8-wide form of the tree (`wide/`), whose exactness rests on this argument; this
//! binary traversal serves the tests, which check that both give the same hits.

#[cfg(test)]
use super::{Node, MAX_DEPTH};
#[cfg(test)]
use crate::accel::closest::{trivially_misses, ClosestHit};
#[cfg(test)]
use crate::accel::{Hit, Primitives, TraversalCounts};
#[cfg(test)]
use crate::math::Ray;

#[cfg(test)]
/// The shared slack of box and interval tests ([`crate::accel::BOX_SLACK`]).
const SLACK: f32 = crate::accel::BOX_SLACK;

#[cfg(test)]
/// A ray prepared for slab tests.
struct RayBoxTest {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    negative: [bool; 3],
    /// The axis of the direction's largest component: the one the watertight test divides by.
    major: usize,
}

#[cfg(test)]
impl RayBoxTest {
    fn new(ray: &Ray) -> Self {
        let inv = ray.inv_dir;
        let d = ray.dir.abs();
        RayBoxTest {
            origin: ray.origin.to_array(),
            inv_dir: inv.to_array(),
            negative: [inv.x.is_sign_negative(), inv.y.is_sign_negative(), inv.z.is_sign_negative()],
            major: if d.x > d.y && d.x > d.z {
                0
            } else if d.y > d.z {
                1
            } else {
                2
            },
        }
    }

    /// True when the ray meets the node's box in `[0, t_far]`, conservatively.
    #[inline]
    fn hits(&self, node: &Node, t_far: f32) -> bool {
        let mut near = 0.0f32;
        let mut far = t_far;
        let mut scale = 0.0f32;
        for a in 0..3 {
            let (enter, exit) = if self.negative[a] { (node.max[a], node.min[a]) } else { (node.min[a], node.max[a]) };
            let t0 = (enter - self.origin[a]) * self.inv_dir[a];
            let t1 = (exit - self.origin[a]) * self.inv_dir[a];
            // `f32::max`/`min` return the other operand when one is NaN.
            near = near.max(t0);
            far = far.min(t1);
            if a == self.major {
                scale = scale.max(t0.abs()).max(t1.abs());
            }
        }
        near <= far + scale * SLACK
    }

    /// The child to visit first (its index) and the one to push, for inner node `i`.
    #[inline]
    fn order(&self, i: usize, node: &Node) -> (usize, usize) {
        let second = node.offset as usize;
        if self.negative[node.axis as usize] {
            (second, i + 1)
        } else {
            (i + 1, second)
        }
    }
}

#[cfg(test)]
/// The closest hit in `(0, t_max)`, ties to the lowest primitive index. With `COUNT`, the nodes visited
/// and primitives tested are added to `counts` (compiled out otherwise).
pub(crate) fn intersect<P: Primitives + ?Sized, const COUNT: bool>(
    nodes: &[Node],
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    if nodes.is_empty() || trivially_misses(ray, t_max) {
        return None;
    }
    let test = RayBoxTest::new(ray);
    let mut best = ClosestHit::new(t_max);
    let mut stack = [0u32; MAX_DEPTH];
    let mut sp = 0;
    let mut i = 0usize;
    loop {
        let node = &nodes[i];
        if COUNT {
            counts.nodes += 1;
        }
        if test.hits(node, best.t_far()) {
            if node.is_leaf() {
                let first = node.offset as usize;
                for &prim in &indices[first..first + node.count as usize] {
                    let h = if COUNT {
                        prims.intersect_counted(prim as usize, ray, best.t_query(), counts)
                    } else {
                        prims.intersect(prim as usize, ray, best.t_query())
                    };
                    if let Some(h) = h {
                        best.offer(Hit::new(prim, h));
                    }
                }
            } else {
                let (near, far) = test.order(i, node);
                stack[sp] = far as u32;
                sp += 1;
                i = near;
                continue;
            }
        }
        if sp == 0 {
            return best.hit();
        }
        sp -= 1;
        i = stack[sp] as usize;
    }
}

#[cfg(test)]
/// Whether anything is hit in `(0, t_max)`; stops at the first hit.
pub(crate) fn occluded<P: Primitives + ?Sized>(
    nodes: &[Node],
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
) -> bool {
    if nodes.is_empty() || trivially_misses(ray, t_max) {
        return false;
    }
    let test = RayBoxTest::new(ray);
    let mut stack = [0u32; MAX_DEPTH];
    let mut sp = 0;
    let mut i = 0usize;
    loop {
        let node = &nodes[i];
        if test.hits(node, t_max) {
            if node.is_leaf() {
                let first = node.offset as usize;
                let leaf = &indices[first..first + node.count as usize];
                if leaf.iter().any(|&p| prims.occludes(p as usize, ray, t_max)) {
                    return true;
                }
            } else {
                let (near, far) = test.order(i, node);
                stack[sp] = far as u32;
                sp += 1;
                i = near;
                continue;
            }
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        i = stack[sp] as usize;
    }
}
