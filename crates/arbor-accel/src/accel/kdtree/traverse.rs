//! Front-to-back traversal with a t-interval per node (pbrt-v4's `KdTreeAggregate::Intersect`): the ray
//! is clipped to the root box, each inner node splits the current interval at the plane's distance, the
//! child holding the near part is visited first and the far one pushed with its interval.
//!
//! Closest hit, exactly as brute force returns it: a primitive found in one leaf may be hit beyond that
//! leaf (it straddles cells), so finding a hit does not end the search. A pushed node is skipped only
//! when the best `t` lies before its interval by more than a margin, so a hit tying the best `t` there
//! is still seen and the lowest index wins ([`ClosestHit`]: primitives are asked for hits up to the
//! float just above the best `t`).
//!
//! Conservative margins. The decisions "the plane is crossed before / after the interval" and "the best
//! hit is before this interval" compare distances whose rounding errors are not relative to the values
//! compared: the watertight triangle test's `t` errs relative to the corners' distances along the ray's
//! major axis (see `bvh/traverse.rs`). All corners lie in the root box, so the margin is [`SLACK`]
//! times the larger of the root box's two slab distances on the major axis, computed once per ray.
//! Interval ends themselves are single slab or plane distances inside that range, far more accurate.
//! A margin too wide costs a few visits; one too narrow could lose the closest hit or a tie.
//!
//! Rays parallel to a split plane: `1 / 0` is infinite, so the plane's distance is `+-inf` (one child)
//! or, for an origin exactly in the plane, `0 * inf = NaN`, which visits both children (the ray runs
//! along both closed boxes). Root slab tests pick entry and exit planes by the sign of `1 / d`, so a
//! signed zero selects the plane whose NaN `max`/`min` ignore (the closed-box answer).
//!
//! Cost: at most one push per level, so a stack of [`MAX_DEPTH`] entries suffices.

use super::{KdTree, MAX_DEPTH};
use crate::accel::closest::{trivially_misses, ClosestHit};
use crate::accel::{Hit, Primitives, TraversalCounts};
use crate::math::Ray;

/// The shared slack of box and interval tests ([`crate::accel::BOX_SLACK`]).
const SLACK: f32 = crate::accel::BOX_SLACK;

/// A node still to visit and the part of the ray inside it.
#[derive(Debug, Clone, Copy, Default)]
struct Todo {
    node: u32,
    t_min: f32,
    t_max: f32,
}

/// A ray clipped to the root box.
struct Clipped {
    origin: [f32; 3],
    dir: [f32; 3],
    inv_dir: [f32; 3],
    root: Todo,
    margin: f32,
}

impl Clipped {
    /// The ray's interval in the root box within `(0, t_max)`, or `None` when nothing can be hit.
    fn new(tree: &KdTree, ray: &Ray, t_max: f32) -> Option<Self> {
        if tree.nodes.is_empty() || trivially_misses(ray, t_max) {
            return None;
        }
        let (origin, dir, inv_dir) = (ray.origin.to_array(), ray.dir.to_array(), ray.inv_dir.to_array());
        let d = ray.dir.abs();
        let major = if d.x > d.y && d.x > d.z {
            0
        } else if d.y > d.z {
            1
        } else {
            2
        };
        let b = &tree.bounds;
        let (mut near, mut far, mut scale) = (0.0f32, t_max, 0.0f32);
        for a in 0..3 {
            let (enter, exit) = if inv_dir[a].is_sign_negative() { (b.max[a], b.min[a]) } else { (b.min[a], b.max[a]) };
            let t0 = (enter - origin[a]) * inv_dir[a];
            let t1 = (exit - origin[a]) * inv_dir[a];
            // `f32::max`/`min` return the other operand when one is NaN.
            near = near.max(t0);
            far = far.min(t1);
            if a == major {
                scale = t0.abs().max(t1.abs());
            }
        }
        let margin = scale * SLACK;
        if near > far + margin {
            return None;
        }
        Some(Clipped { origin, dir, inv_dir, root: Todo { node: 0, t_min: near, t_max: far }, margin })
    }

    /// Whether the ray moves towards the plane `split` on axis `a` (so may reach its far side). Decided
    /// by signs, which are exact: `t_split` itself can underflow to +0 for a tiny distance times a tiny
    /// reciprocal direction, and must not be read as "moving away" (found by fuzzing).
    #[inline]
    fn toward(&self, a: usize, split: f32) -> bool {
        let (o, d) = (self.origin[a], self.dir[a]);
        (o < split && d > 0.0) || (o > split && d < 0.0)
    }

    /// The children of inner node `at.node` the ray meets: the near one to visit now, the far one (if
    /// met too) to push.
    #[inline]
    fn children(&self, tree: &KdTree, at: Todo) -> (Todo, Option<Todo>) {
        let node = &tree.nodes[at.node as usize];
        let (a, split) = (node.axis(), node.split());
        let t_split = (split - self.origin[a]) * self.inv_dir[a];
        let below_first = self.origin[a] < split || (self.origin[a] == split && self.dir[a] <= 0.0);
        let (below, above) = (at.node + 1, node.above() as u32);
        let (first, second) = if below_first { (below, above) } else { (above, below) };
        let whole = |node| Todo { node, ..at };
        if t_split.is_nan() {
            // Origin in the plane, ray parallel to it: it runs along both children.
            (whole(first), Some(whole(second)))
        } else if t_split > at.t_max + self.margin || !self.toward(a, split) {
            (whole(first), None)
        } else if t_split < at.t_min - self.margin {
            (whole(second), None)
        } else {
            let near = Todo { node: first, t_min: at.t_min, t_max: t_split.min(at.t_max) };
            let far = Todo { node: second, t_min: t_split.max(at.t_min), t_max: at.t_max };
            (near, Some(far))
        }
    }
}

/// The closest hit in `(0, t_max)`, ties to the lowest primitive index. With `COUNT`, the nodes visited
/// and primitives tested are added to `counts` (compiled out otherwise).
pub(super) fn intersect<P: Primitives + ?Sized, const COUNT: bool>(
    tree: &KdTree,
    prims: &P,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    let clipped = Clipped::new(tree, ray, t_max)?;
    let mut best = ClosestHit::new(t_max);
    let mut stack = [Todo::default(); MAX_DEPTH];
    let mut sp = 0;
    let mut at = clipped.root;
    loop {
        let node = &tree.nodes[at.node as usize];
        if COUNT {
            counts.nodes += 1;
        }
        if !node.is_leaf() {
            let (near, far) = clipped.children(tree, at);
            if let Some(far) = far {
                stack[sp] = far;
                sp += 1;
            }
            at = near;
            continue;
        }
        for &prim in node.prims(&tree.refs) {
            let h = if COUNT {
                prims.intersect_counted(prim as usize, ray, best.t_query(), counts)
            } else {
                prims.intersect(prim as usize, ray, best.t_query())
            };
            if let Some(h) = h {
                best.offer(Hit::new(prim, h));
            }
        }
        // Skip pushed nodes that start after the best hit (by more than the margin).
        loop {
            if sp == 0 {
                return best.hit();
            }
            sp -= 1;
            at = stack[sp];
            if best.hit().is_none_or(|b| b.t >= at.t_min - clipped.margin) {
                break;
            }
        }
    }
}

/// Whether anything is hit in `(0, t_max)`; stops at the first hit.
pub(super) fn occluded<P: Primitives + ?Sized>(tree: &KdTree, prims: &P, ray: &Ray, t_max: f32) -> bool {
    let Some(clipped) = Clipped::new(tree, ray, t_max) else {
        return false;
    };
    let mut stack = [Todo::default(); MAX_DEPTH];
    let mut sp = 0;
    let mut at = clipped.root;
    loop {
        let node = &tree.nodes[at.node as usize];
        if !node.is_leaf() {
            let (near, far) = clipped.children(tree, at);
            if let Some(far) = far {
                stack[sp] = far;
                sp += 1;
            }
            at = near;
            continue;
        }
        if node.prims(&tree.refs).iter().any(|&p| prims.occludes(p as usize, ray, t_max)) {
            return true;
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        at = stack[sp];
    }
}
