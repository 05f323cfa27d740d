//! The O(N log N) SAH build of Wald and Havran (RT 2006, section 4): per axis, a list of events (a
//! primitive's clipped bounds start, end, or lie flat at a position) sorted once by position and then
//! kept sorted by splitting the lists at each node instead of re-sorting them.
//!
//! Per node:
//! - find-split ([`find_split`]): one sweep per axis over the sorted events counts the primitives left
//!   of, right of and in each candidate plane, and evaluates the SAH cost of putting the planar ones on
//!   either side; a split leaving one side empty gets the empty-space bonus. The node becomes a leaf
//!   when no candidate strictly inside the box costs less than intersecting every primitive, or at the
//!   depth limit;
//! - partition ([`Builder::partition`]): each primitive is classified left-only, right-only or both by
//!   one pass over the split axis' events; the events of one-sided primitives are copied, in order, to
//!   that side's lists. A primitive on both sides is clipped to each child box ("perfect splits",
//!   [`Primitives::clipped_bounds`]); the new events, a small fraction on typical scenes, are sorted
//!   and merged into the lists, so sorted order costs O(n) per node;
//! - make-leaf ([`Builder::make_leaf`]): its primitives, in index order.
//!
//! Events carry `-0.0` folded into `+0.0`, so equal positions are equal bit patterns for sorting.
//!
//! Parallel: the two children of a node with at least [`PARALLEL_MIN`] primitives are built at once
//! (`rayon::join`), the right one by a builder of its own (its own `side` scratch: a primitive straddling
//! the plane is in both subtrees) whose nodes and references are then appended after the left subtree's,
//! with their offsets moved. The flat tree is the one the sequential build writes, node for node.

use rayon::prelude::*;

use super::{split_box, KdTreeParams, Node};
use crate::accel::Primitives;
use crate::math::Aabb;

/// What an event marks; the sort order at equal positions is end, planar, start (the sweep relies on it).
const END: u8 = 0;
const PLANAR: u8 = 1;
const START: u8 = 2;

/// Sides of a primitive relative to the chosen split.
const BOTH: u8 = 0;
const LEFT: u8 = 1;
const RIGHT: u8 = 2;

#[derive(Debug, Clone, Copy)]
struct Event {
    pos: f32,
    prim: u32,
    kind: u8,
}

/// One sorted event list per axis.
type Events = [Vec<Event>; 3];

/// The chosen split plane.
#[derive(Debug, Clone, Copy)]
struct Split {
    axis: usize,
    pos: f32,
    /// Whether primitives lying in the plane go to the left (below) child.
    planar_left: bool,
    cost: f64,
    /// Primitives whose bounds reach each side, planar ones included on their side (an upper bound
    /// on the children's counts: clipping may drop some).
    counts: [usize; 2],
}

/// Most bad refines ([`is_bad_refine`]) on the path from the root to any node (pbrt's limit of 3).
const MAX_BAD_REFINES: usize = 3;

/// A split of `n` primitives is a bad refine when its children together hold more than 1.5 n of
/// them: the primitives straddling the plane are copied to both sides, and a tree made mostly of such
/// splits grows exponentially with depth while its leaves barely shrink (flat primitives overlapping
/// in one plane, where the SAH always finds a slightly cheaper split). A split with an empty side is
/// never bad: that side is a leaf, so it cannot branch.
fn is_bad_refine(split: &Split, n: usize) -> bool {
    let [l, r] = split.counts;
    l > 0 && r > 0 && 2 * (l + r) > 3 * n
}

/// Nodes with at least this many primitives build their two children in parallel.
const PARALLEL_MIN: usize = 4096;

/// True for bounds a primitive can be hit within: finite and not empty.
pub(super) fn is_live(b: &Aabb) -> bool {
    !b.is_empty() && b.min.is_finite() && b.max.is_finite()
}

/// Builds the flat tree over `prims`: nodes, references of leaves of two or more, and the root box.
pub(super) fn build<P: Primitives + ?Sized>(
    prims: &P,
    params: &KdTreeParams,
    max_depth: usize,
) -> (Vec<Node>, Vec<u32>, Aabb) {
    build_split_at(prims, params, max_depth, PARALLEL_MIN)
}

/// [`build`], building children in parallel below nodes of `parallel_min` primitives or more.
pub(super) fn build_split_at<P: Primitives + ?Sized>(
    prims: &P,
    params: &KdTreeParams,
    max_depth: usize,
    parallel_min: usize,
) -> (Vec<Node>, Vec<u32>, Aabb) {
    let mut events: Events = Default::default();
    let mut bounds = Aabb::EMPTY;
    let mut live = 0;
    for i in 0..prims.len() {
        let b = prims.bounds(i);
        if is_live(&b) {
            bounds = bounds.union(b);
            push_events(&mut events, i as u32, &b);
            live += 1;
        }
    }
    if live == 0 {
        return (Vec::new(), Vec::new(), Aabb::EMPTY);
    }
    // `order` is total (a primitive has one event of a kind per axis), so the parallel sort is deterministic.
    events.par_iter_mut().for_each(|list| list.par_sort_unstable_by(order));
    let mut builder = Builder::new(prims, params, max_depth, parallel_min);
    builder.build_node(events, &bounds, live, 0, 0);
    (builder.nodes, builder.refs, bounds)
}

/// Position, then end < planar < start, then primitive (for a deterministic order).
fn order(a: &Event, b: &Event) -> std::cmp::Ordering {
    a.pos.total_cmp(&b.pos).then(a.kind.cmp(&b.kind)).then(a.prim.cmp(&b.prim))
}

/// Adds the events of a primitive whose bounds (clipped to the node) are `b`.
fn push_events(events: &mut Events, prim: u32, b: &Aabb) {
    for (k, list) in events.iter_mut().enumerate() {
        // Adding +0.0 turns -0.0 into +0.0, which `total_cmp` would otherwise order first.
        let (lo, hi) = (b.min[k] + 0.0, b.max[k] + 0.0);
        if lo == hi {
            list.push(Event { pos: lo, prim, kind: PLANAR });
        } else {
            list.push(Event { pos: lo, prim, kind: START });
            list.push(Event { pos: hi, prim, kind: END });
        }
    }
}

/// The two sorted lists as one.
fn merge(a: Vec<Event>, b: Vec<Event>) -> Vec<Event> {
    if b.is_empty() {
        return a;
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if order(&a[i], &b[j]).is_le() {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// The cheapest split of a node with box `bx` and `n` primitives, if it beats making a leaf.
fn find_split(events: &Events, bx: &Aabb, n: usize, params: &KdTreeParams) -> Option<Split> {
    let area = bx.area_f64();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let leaf_cost = params.intersection_cost as f64 * n as f64;
    let mut best: Option<Split> = None;
    for (axis, list) in events.iter().enumerate() {
        let (mut left, mut right) = (0usize, n);
        let mut i = 0;
        while i < list.len() {
            let pos = list[i].pos;
            let mut count = [0usize; 3];
            for kind in [END, PLANAR, START] {
                while i < list.len() && list[i].pos == pos && list[i].kind == kind {
                    count[kind as usize] += 1;
                    i += 1;
                }
            }
            let planar = count[PLANAR as usize];
            right -= planar + count[END as usize];
            // Splits on the box's faces cut nothing off.
            if bx.min[axis] < pos && pos < bx.max[axis] {
                let split = sah(bx, area, axis, pos, [left, planar, right], params);
                if best.is_none_or(|b| split.cost < b.cost) {
                    best = Some(split);
                }
            }
            left += count[START as usize] + planar;
        }
    }
    best.filter(|s| s.cost < leaf_cost)
}

/// Wald and Havran's SAH cost of splitting at `pos`, with `[left, planar, right]` primitives, the
/// planar ones put on whichever side is cheaper (left on ties).
fn sah(bx: &Aabb, area: f64, axis: usize, pos: f32, [left, planar, right]: [usize; 3], params: &KdTreeParams) -> Split {
    let (below, above) = split_box(bx, axis, pos);
    let (pl, pr) = (below.area_f64() / area, above.area_f64() / area);
    let (kt, ki) = (params.traversal_cost as f64, params.intersection_cost as f64);
    let bonus = 1.0 - params.empty_bonus as f64;
    let cost = |l: usize, r: usize| {
        let lambda = if l == 0 || r == 0 { bonus } else { 1.0 };
        lambda * (kt + ki * (pl * l as f64 + pr * r as f64))
    };
    let (to_left, to_right) = (cost(left + planar, right), cost(left, right + planar));
    let planar_left = to_left <= to_right;
    let (cost, counts) =
        if planar_left { (to_left, [left + planar, right]) } else { (to_right, [left, right + planar]) };
    Split { axis, pos, planar_left, cost, counts }
}

/// The recursive builder, writing nodes depth first.
struct Builder<'a, P: ?Sized> {
    prims: &'a P,
    params: KdTreeParams,
    max_depth: usize,
    parallel_min: usize,
    /// Side of each primitive of the node being partitioned (scratch, indexed by primitive).
    side: Vec<u8>,
    nodes: Vec<Node>,
    refs: Vec<u32>,
}

impl<'a, P: Primitives + ?Sized> Builder<'a, P> {
    fn new(prims: &'a P, params: &KdTreeParams, max_depth: usize, parallel_min: usize) -> Self {
        Builder {
            prims,
            params: *params,
            max_depth,
            parallel_min,
            side: vec![BOTH; prims.len()],
            nodes: Vec::new(),
            refs: Vec::new(),
        }
    }

    /// Builds the subtree of a node at `depth` below `bad` bad refines.
    fn build_node(&mut self, events: Events, bx: &Aabb, n: usize, depth: usize, bad: usize) {
        let split = if depth < self.max_depth && n > 0 { find_split(&events, bx, n, &self.params) } else { None };
        let split = split.map(|s| (s, bad + is_bad_refine(&s, n) as usize));
        let Some((split, bad)) = split.filter(|&(_, bad)| bad <= MAX_BAD_REFINES) else {
            return self.make_leaf(&events[0]);
        };
        let (below, above) = split_box(bx, split.axis, split.pos);
        let ((left, n_left), (right, n_right)) = self.partition(events, &split, &below, &above);
        let me = self.nodes.len();
        self.nodes.push(Node::leaf(0, 0));
        if n < self.parallel_min {
            self.build_node(left, &below, n_left, depth + 1, bad);
            self.nodes[me] = Node::inner(split.axis, split.pos, self.nodes.len() as u32);
            self.build_node(right, &above, n_right, depth + 1, bad);
            return;
        }
        let mut other = Builder::new(self.prims, &self.params, self.max_depth, self.parallel_min);
        rayon::join(
            || self.build_node(left, &below, n_left, depth + 1, bad),
            || other.build_node(right, &above, n_right, depth + 1, bad),
        );
        self.nodes[me] = Node::inner(split.axis, split.pos, self.nodes.len() as u32);
        self.append(other);
    }

    /// Appends a subtree built by another builder, moving its child and reference offsets.
    fn append(&mut self, other: Builder<'_, P>) {
        let (node_base, ref_base) = (self.nodes.len() as u32, self.refs.len() as u32);
        self.nodes.extend(other.nodes.into_iter().map(|node| node.relocated(node_base, ref_base)));
        self.refs.extend(other.refs);
    }

    /// A leaf over the primitives of `events` (one axis' list: each primitive has exactly one start or
    /// planar event on it).
    fn make_leaf(&mut self, events: &[Event]) {
        let mut prims: Vec<u32> = events.iter().filter(|e| e.kind != END).map(|e| e.prim).collect();
        prims.sort_unstable();
        let node = match prims[..] {
            [] => Node::leaf(0, 0),
            [p] => Node::leaf(1, p),
            _ => {
                let first = self.refs.len() as u32;
                self.refs.extend_from_slice(&prims);
                Node::leaf(prims.len() as u32, first)
            }
        };
        self.nodes.push(node);
    }

    /// Splits the node's events into the children's, each with its primitive count.
    fn partition(
        &mut self,
        events: Events,
        split: &Split,
        below: &Aabb,
        above: &Aabb,
    ) -> ((Events, usize), (Events, usize)) {
        self.classify(&events[split.axis], split);
        let (mut left, mut right): (Events, Events) = Default::default();
        for (k, list) in events.iter().enumerate() {
            for &e in list {
                match self.side[e.prim as usize] {
                    LEFT => left[k].push(e),
                    RIGHT => right[k].push(e),
                    _ => {}
                }
            }
        }
        let one_sided = |list: &Vec<Event>| list.iter().filter(|e| e.kind != END).count();
        let (mut n_left, mut n_right) = (one_sided(&left[0]), one_sided(&right[0]));
        // Primitives on both sides, clipped to each child: new events, sorted and merged.
        let (mut new_left, mut new_right): (Events, Events) = Default::default();
        for e in &events[split.axis] {
            if e.kind != START || self.side[e.prim as usize] != BOTH {
                continue;
            }
            for (bx, new, count) in [(below, &mut new_left, &mut n_left), (above, &mut new_right, &mut n_right)] {
                let clipped = self.prims.clipped_bounds(e.prim as usize, bx);
                if is_live(&clipped) {
                    push_events(new, e.prim, &clipped);
                    *count += 1;
                }
            }
        }
        drop(events);
        let merged = |old: Events, mut new: Events| {
            let mut k = 0;
            old.map(|list| {
                new[k].sort_unstable_by(order);
                k += 1;
                merge(list, std::mem::take(&mut new[k - 1]))
            })
        };
        ((merged(left, new_left), n_left), (merged(right, new_right), n_right))
    }

    /// Sets [`Builder::side`] for every primitive of the node from its events on the split axis.
    fn classify(&mut self, list: &[Event], split: &Split) {
        for e in list {
            self.side[e.prim as usize] = BOTH;
        }
        let p = split.pos;
        for e in list {
            let side = &mut self.side[e.prim as usize];
            match e.kind {
                END if e.pos <= p => *side = LEFT,
                START if e.pos >= p => *side = RIGHT,
                PLANAR if e.pos < p || (e.pos == p && split.planar_left) => *side = LEFT,
                PLANAR if e.pos > p || (e.pos == p && !split.planar_left) => *side = RIGHT,
                _ => {}
            }
        }
    }
}
