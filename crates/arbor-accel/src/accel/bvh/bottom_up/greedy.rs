//! The exact greedy agglomerative method: while more than one cluster is left, merge the pair of least
//! [`MergeCost`] over all pairs (the exact greedy clustering Walter et al. 2008 compare against; the
//! merged box's area is their cost).
//!
//! Each cluster caches its best partner and that pair's cost. After merging `a` and `b` into `a`'s
//! slot, only clusters whose partner was `a` or `b` search all clusters again; every other cluster just
//! compares its cached partner with the new cluster, since the rest of its candidates did not change.
//! The least pair is then the least cached one. That is exact for any symmetric cost.
//!
//! Ties: pairs are ordered by (cost, distance between the slots, lower slot), a total order, so the
//! least pair is unique and the tree deterministic. Preferring nearby slots (input order is usually
//! spatially coherent) also keeps ties from pointing every cluster at one partner, which would make
//! duplicate primitives cost O(n³).
//!
//! Cost: O(n) memory. Each merge scans the clusters once (O(n)) plus O(n) per cluster that lost its
//! partner, which is a few in practice, so O(n²) in practice and O(n³) in the worst case (many
//! clusters sharing one partner at every step). Hence the `greedy-max` threshold
//! (2,000 primitives by default) in `auto`.

use super::{merge, merge_cost, Cluster, MergeCost};
use crate::accel::bvh::build::BuildPrim;

/// No partner yet (a single cluster).
const NONE: u32 = u32::MAX;

/// Clustering state: one slot per primitive, in input order.
struct Slots {
    cost: MergeCost,
    alive: Vec<bool>,
    /// Arena index of each slot's cluster.
    node: Vec<u32>,
    bounds: Vec<crate::math::Aabb>,
    /// Best partner slot and that pair's cost.
    partner: Vec<u32>,
    partner_cost: Vec<f64>,
}

/// The pair order: cost, then slot distance, then lower slot. `(cost, i, j)` is the pair of slots
/// `i` and `j`.
#[inline]
fn less(a: (f64, u32, u32), b: (f64, u32, u32)) -> bool {
    let key = |(c, i, j): (f64, u32, u32)| (c, i.abs_diff(j), i.min(j));
    let (ka, kb) = (key(a), key(b));
    ka.0 < kb.0 || (ka.0 == kb.0 && (ka.1, ka.2) < (kb.1, kb.2))
}

impl Slots {
    fn pair_cost(&self, i: usize, j: usize) -> f64 {
        merge_cost(self.cost, &self.bounds[i], &self.bounds[j])
    }

    /// Searches every live slot for `i`'s best partner.
    fn find_partner(&mut self, i: usize) {
        let mut best = (f64::INFINITY, i as u32, NONE);
        for j in (0..self.alive.len()).filter(|&j| j != i && self.alive[j]) {
            let cand = (self.pair_cost(i, j), i as u32, j as u32);
            if best.2 == NONE || less(cand, best) {
                best = cand;
            }
        }
        self.partner[i] = best.2;
        self.partner_cost[i] = best.0;
    }

    /// The least pair over all live slots.
    fn least_pair(&self) -> (usize, usize) {
        let mut best = (f64::INFINITY, 0, NONE);
        for i in (0..self.alive.len()).filter(|&i| self.alive[i]) {
            let cand = (self.partner_cost[i], i as u32, self.partner[i]);
            if best.2 == NONE || less(cand, best) {
                best = cand;
            }
        }
        (best.1 as usize, best.2 as usize)
    }
}

/// Clusters `prims` greedily; returns the arena (leaves `0..n`, root last).
pub(super) fn cluster(prims: &[BuildPrim], cost: MergeCost) -> Vec<Cluster> {
    let n = prims.len();
    let mut arena: Vec<Cluster> = prims.iter().map(|p| Cluster::leaf(p.bounds)).collect();
    arena.reserve(n.saturating_sub(1));
    let mut s = Slots {
        cost,
        alive: vec![true; n],
        node: (0..n as u32).collect(),
        bounds: prims.iter().map(|p| p.bounds).collect(),
        partner: vec![NONE; n],
        partner_cost: vec![f64::INFINITY; n],
    };
    for i in 0..n {
        s.find_partner(i);
    }
    for _ in 1..n {
        let (i, j) = s.least_pair();
        let (a, b) = (i.min(j), i.max(j));
        s.node[a] = merge(&mut arena, s.node[a], s.node[b]);
        s.bounds[a] = arena[s.node[a] as usize].bounds;
        s.alive[b] = false;
        s.find_partner(a);
        for c in 0..n {
            if c == a || !s.alive[c] {
                continue;
            }
            let p = s.partner[c] as usize;
            if p == a || p == b {
                s.find_partner(c);
            } else {
                let cand = (s.pair_cost(c, a), c as u32, a as u32);
                if less(cand, (s.partner_cost[c], c as u32, p as u32)) {
                    s.partner[c] = a as u32;
                    s.partner_cost[c] = cand.0;
                }
            }
        }
    }
    arena
}
