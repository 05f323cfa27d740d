//! The course's split at refractive surfaces (CENG 795 hw6's official path tracer): where a path meets a
//! surface that refracts (a `dielectric`, or the 2019 files' `Transparency`), it follows both Fresnel
//! lobes, the reflected and the transmitted ray, each weighted by its lobe weight and not divided by
//! the probability of a choice, and still takes its BRDF bounce where the material has a BRDF part; the
//! branches' light is summed. This is Whitted's split inside a path tracer. It is unbiased, as a
//! stochastic choice of one lobe is, and its noise differs: a pixel seen through glass gets light along
//! both lobes in every sample instead of along one at random. The official images show it: over the
//! 2022 `glass.exr` sphere (100 samples) the histogram of pixel radiance is 11.8% (L1 over 13 bins) from
//! the official one with the split, 75.5% with one lobe picked; pixels below 1e-4: 21.1% against the
//! official 24.8%, 54.7% with one lobe (docs/reference-results.md).
//!
//! A METU path-traced camera gets it ([`crate::renderer::PathOptions::split_refraction`]). Paths split
//! only within `MaxRecursionDepth` bounces (beyond it, reachable under a Russian roulette, they pick one
//! lobe as before), and one camera sample makes at most [`MAX_BRANCHES`] branches: a scene of many
//! refractive layers and a deep recursion limit, which would make up to 3^depth of them, picks lobes
//! past that bound, so that no input makes a sample unbounded in time or memory.
//!
//! Invariants: branches are traced depth-first in a fixed order (the reflected lobe, the transmitted
//! one, in the order the material gives them, after the BRDF bounce's own path), so a sample's value
//! still depends only on its random stream. Cost: a split path traces one ray per branch; the pending
//! branches live on a stack that allocates only when a path first splits.

use crate::material::Lobe;
use crate::math::{Color, Ray};

/// The most branches one camera sample may make; past them, paths pick one lobe at random.
pub const MAX_BRANCHES: u32 = 64;

/// A branch waiting to be traced: the path state after a delta lobe.
#[derive(Clone, Copy)]
pub struct Branch {
    /// The lobe's ray, from its surface.
    pub ray: Ray,
    /// The throughput, the lobe's weight included.
    pub beta: Color,
    /// The course's roulette's product of BRDF values (lobe weights) so far.
    pub t: Color,
    /// The absorption of the medium the ray travels in.
    pub inside: Option<Color>,
    /// Bounces so far, this one included.
    pub bounce: u32,
}

/// The branches a path makes at a splitting vertex, and the bound on them.
#[derive(Default)]
pub struct Branches {
    pending: Vec<Branch>,
    made: u32,
}

impl Branches {
    /// Whether a vertex with `lobes` may split: under the bound, with room for every lobe.
    pub fn room_for(&self, lobes: &[Lobe]) -> bool {
        self.made + lobes.len() as u32 <= MAX_BRANCHES
    }

    /// Queues one branch per lobe of nonzero weight, each made by `branch`; traced in lobe order.
    pub fn push(&mut self, lobes: &[Lobe], branch: impl Fn(&Lobe) -> Branch) {
        self.made += lobes.len() as u32;
        for lobe in lobes.iter().rev().filter(|lb| lb.weight != Color::ZERO) {
            self.pending.push(branch(lobe));
        }
    }

    /// The next branch to trace.
    pub fn pop(&mut self) -> Option<Branch> {
        self.pending.pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn lobe(weight: f32) -> Lobe {
        Lobe { dir: Vec3::Z, weight: Color::splat(weight), transmitted: false }
    }

    fn branch(bounce: u32) -> impl Fn(&Lobe) -> Branch {
        move |lb| Branch { ray: Ray::new(Vec3::ZERO, lb.dir), beta: lb.weight, t: Color::ONE, inside: None, bounce }
    }

    #[test]
    fn branches_come_back_in_lobe_order_and_stop_at_the_bound() {
        let mut b = Branches::default();
        let two = [lobe(0.25), lobe(0.75)];
        b.push(&two, branch(1));
        // A lobe of zero weight brings nothing: no branch, but it counts against the bound.
        b.push(&[lobe(0.0)], branch(2));
        assert_eq!(b.pop().map(|x| x.beta.x), Some(0.25));
        assert_eq!(b.pop().map(|x| x.beta.x), Some(0.75));
        assert!(b.pop().is_none());
        // 3 made; room for 61 more, in pairs up to 63, then no pair fits.
        for _ in 0..30 {
            assert!(b.room_for(&two));
            b.push(&two, branch(1));
        }
        assert_eq!(b.made, 63);
        assert!(b.room_for(&[lobe(1.0)]) && !b.room_for(&two));
    }
}
