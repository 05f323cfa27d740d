//! What a path carries between its vertices: the state the one-path loop keeps in locals and the
//! wavefront keeps per path in flight.

use crate::integrator::split::Branch;
use crate::math::{Color, Vec3};

/// What a path carries from one vertex to the next.
pub(super) struct PathState {
    /// Under the course's roulette, the light of the vertex being shaded, until the roulette weighs it
    /// (zero between vertices, but while its shadow rays wait to be traced).
    pub(super) e: Color,
    pub(super) beta: Color,
    /// The absorption of the medium the ray travels in (inside a dielectric), if any.
    pub(super) inside: Option<Color>,
    /// The last bounce: the point it left from and its direction's density, for the weight of the light
    /// it meets; `None` after a delta lobe (or for the camera ray), which meets light in full.
    pub(super) last: Option<(Vec3, f32)>,
    /// The course's roulette's throughput: the product of the BRDF values met so far.
    pub(super) t: Color,
    pub(super) bounce: u32,
}

impl PathState {
    /// The state of a camera ray's path.
    pub(super) fn camera() -> PathState {
        PathState { e: Color::ZERO, beta: Color::ONE, inside: None, last: None, t: Color::ONE, bounce: 0 }
    }

    /// The state of a branch of a split path, which takes over the light `e` still waiting for the
    /// roulette of the vertex that made it.
    pub(super) fn branch(b: &Branch, e: Color) -> PathState {
        PathState { e, beta: b.beta, inside: b.inside, last: None, t: b.t, bounce: b.bounce }
    }
}
