//! The one tally of a structure's statistics: a structure walks its nodes once and reports each inner
//! node and each leaf with its depth and the probability that a ray through the root visits it (its
//! surface area relative to the root's); [`StatsTally::finish`] turns the counts into [`AccelStats`]'s
//! means, with one definition for every structure.

use std::time::Duration;

use super::AccelStats;

/// Counts of one walk over a structure's nodes.
pub(crate) struct StatsTally {
    stats: AccelStats,
    depth_sum: usize,
    refs: usize,
    non_empty: usize,
}

impl StatsTally {
    /// A tally for structure `kind` over `primitives`, with `nodes` nodes in `bytes` bytes.
    pub(crate) fn new(kind: &'static str, primitives: usize, nodes: usize, bytes: usize, build_time: Duration) -> Self {
        let stats = AccelStats { kind, primitives, nodes, bytes, build_time, ..AccelStats::default() };
        StatsTally { stats, depth_sum: 0, refs: 0, non_empty: 0 }
    }

    /// An inner node visited with probability `p`: one traversal step in the SAH cost.
    pub(crate) fn inner(&mut self, p: f64) {
        self.stats.sah_cost += p;
    }

    /// A leaf at `depth` holding `count` primitive references, visited with probability `p`.
    pub(crate) fn leaf(&mut self, depth: usize, count: usize, p: f64) {
        let s = &mut self.stats;
        s.leaves += 1;
        s.max_depth = s.max_depth.max(depth);
        s.sah_cost += p * count as f64;
        self.depth_sum += depth;
        self.refs += count;
        self.non_empty += (count > 0) as usize;
    }

    /// The statistics: mean depth over all leaves, references per non-empty leaf and per primitive.
    pub(crate) fn finish(self) -> AccelStats {
        let mut s = self.stats;
        let ratio = |a: usize, b: usize| if b > 0 { a as f64 / b as f64 } else { 0.0 };
        s.mean_depth = ratio(self.depth_sum, s.leaves);
        s.mean_leaf_prims = ratio(self.refs, self.non_empty);
        s.refs_per_prim = ratio(self.refs, s.primitives);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_tally_means_follow_their_definitions() {
        let mut t = StatsTally::new("test", 4, 5, 100, Duration::ZERO);
        t.inner(1.0);
        t.inner(0.5);
        t.leaf(1, 3, 0.5);
        t.leaf(2, 0, 0.25);
        t.leaf(3, 2, 0.25);
        let s = t.finish();
        assert_eq!((s.leaves, s.max_depth, s.nodes, s.bytes), (3, 3, 5, 100));
        assert_eq!(s.mean_depth, 2.0, "over every leaf, empty ones too");
        assert_eq!(s.mean_leaf_prims, 2.5, "over non-empty leaves");
        assert_eq!(s.refs_per_prim, 1.25);
        assert_eq!(s.sah_cost, 1.5 + 1.5 + 0.5);
        let empty = StatsTally::new("test", 0, 0, 0, Duration::ZERO).finish();
        assert_eq!((empty.mean_depth, empty.mean_leaf_prims, empty.refs_per_prim), (0.0, 0.0, 0.0));
    }
}
