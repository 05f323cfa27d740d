//! Every surface crossing along a ray, each reported once, and containment by the parity of
//! crossings.
//!
//! Collecting: a second structure of the same kind and parameters is built (once, on the first
//! query that needs it) over [`Collector`], which shares the mesh (an `Arc`, no copy) and answers each
//! triangle test the structure asks for with the mesh's own watertight test on the ray as given,
//! records the hit in a per-thread list and then reports a miss. The structure's closest-hit search
//! therefore never shrinks its interval and visits every node the ray meets in `(0, t_max)`: the
//! list ends up holding every triangle the ray hits, each decided by exactly the test (and the same
//! arithmetic) brute force and the closest-hit query use. This is Embree's way of collecting all hits
//! (an intersection filter that rejects every hit). A kd-tree or octree puts a triangle in every cell
//! it overlaps and may test it more than once: repeats (same triangle, same bits) are dropped.
//!
//! The tie rule for shared edges and vertices: the watertight test (Woop et al. 2013) accepts a hit
//! whose edge function is exactly zero, and computes an edge's function from its two vertices alone,
//! so a ray through the edge shared by two triangles gets a zero there from both and is hit by both
//! (never by neither). A barycentric coordinate is exactly zero exactly when its edge function is, so
//! a hit lies on an edge (one zero) or a vertex (two zeros) as the test decided it. Hits of one ray
//! are merged into one crossing when they lie on the same edge, or one lies on a vertex and the
//! other on that vertex or on an edge ending there; edges and vertices are compared by their
//! coordinates' bits, so an unwelded mesh (vertices repeated per triangle) merges the same way. The
//! crossing is reported as its closest hit (smallest `t`, then lowest triangle index: the
//! closest-hit query's answer when it is the first crossing). A ray that grazes an edge or a vertex
//! without passing through the surface is one crossing there too.
//!
//! Containment: the parity of the crossings along a ray from the point, taken along the first of
//! [`DIRECTIONS`] whose ray meets no edge and no vertex, nor passes within [`NEAR_EDGE`] (barycentric)
//! of one (so that every crossing is a triangle's interior, counted once); when all of them do, the
//! majority of their parities. The mesh should be closed; a point on the surface may go either way.

use std::cell::RefCell;
use std::sync::Arc;

use arbor::accel::{PrimHit, Primitives, Structure};
use arbor::geometry::{intersect_triangle, TriangleMesh};
use arbor::math::{Aabb, Ray, Vec3};

/// A mesh's triangles for the collecting structure (see the module documentation).
pub struct Collector {
    /// The mesh, shared with the closest-hit structure.
    pub mesh: Arc<TriangleMesh>,
}

/// A hit of a ray on a triangle: `t`, the triangle, its barycentric `u` and `v`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawHit {
    /// Ray parameter.
    pub t: f32,
    /// Triangle index.
    pub prim: u32,
    /// Weight of the triangle's vertex 1.
    pub u: f32,
    /// Weight of the triangle's vertex 2.
    pub v: f32,
}

thread_local! {
    /// The hits of the query running on this thread.
    static FOUND: RefCell<Vec<RawHit>> = const { RefCell::new(Vec::new()) };
}

impl Primitives for Collector {
    fn len(&self) -> usize {
        self.mesh.len()
    }
    fn bounds(&self, i: usize) -> Aabb {
        Primitives::bounds(self.mesh.as_ref(), i)
    }
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit> {
        if let Some(h) = Primitives::intersect(self.mesh.as_ref(), i, ray, t_max) {
            FOUND.with(|f| f.borrow_mut().push(RawHit { t: h.t, prim: i as u32, u: h.u, v: h.v }));
        }
        None
    }
    fn overlaps_box(&self, i: usize, b: &Aabb) -> bool {
        Primitives::overlaps_box(self.mesh.as_ref(), i, b)
    }
    fn clipped_bounds(&self, i: usize, b: &Aabb) -> Aabb {
        Primitives::clipped_bounds(self.mesh.as_ref(), i, b)
    }
}

/// Every triangle `ray` hits in `(0, t_max)`, sorted by `t` then triangle, each once.
pub fn raw_hits(s: &Structure<Collector>, ray: &Ray, t_max: f32) -> Vec<RawHit> {
    FOUND.with(|f| f.borrow_mut().clear());
    let none = s.intersect(ray, t_max);
    debug_assert!(none.is_none(), "the collector reports every hit as a miss");
    let mut hits = FOUND.with(|f| std::mem::take(&mut *f.borrow_mut()));
    hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.prim.cmp(&b.prim)));
    // Repeats of one triangle (tested from two cells) carry the same bits: the first is kept.
    let mut seen = std::collections::HashSet::with_capacity(hits.len());
    hits.retain(|h| seen.insert(h.prim));
    hits
}

/// Which of a hit's edges have an exactly zero edge function: `[opposite vertex 0, 1, 2]`.
fn zero_edges(mesh: &TriangleMesh, ray: &Ray, h: &RawHit) -> [bool; 3] {
    let on_12 = (1.0 - h.u - h.v).abs() < 1e-5 && {
        // The weight of vertex 0 is not returned; the same test with the corners rotated computes
        // that edge's function by the same expression and returns it as the weight of its vertex 2.
        let [a, b, c] = mesh.triangle(h.prim as usize);
        intersect_triangle(ray, b, c, a, f32::INFINITY).is_some_and(|r| r.b2 == 0.0)
    };
    [on_12, h.u == 0.0, h.v == 0.0]
}

/// What part of the surface a hit lies on, by coordinates' bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Element {
    /// A triangle's interior.
    Face,
    /// An edge, its ends in order.
    Edge([u32; 3], [u32; 3]),
    /// A vertex.
    Vertex([u32; 3]),
}

fn bits(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

fn element(mesh: &TriangleMesh, ray: &Ray, h: &RawHit) -> Element {
    let z = zero_edges(mesh, ray, h);
    let corners = mesh.triangle(h.prim as usize).map(bits);
    match z.iter().filter(|&&b| b).count() {
        0 => Element::Face,
        1 => {
            let k = z.iter().position(|&b| b).unwrap_or(0);
            let (p, q) = (corners[(k + 1) % 3], corners[(k + 2) % 3]);
            Element::Edge(p.min(q), p.max(q))
        }
        // Two zero edges meet at the vertex opposite neither (three cannot: the determinant is their sum).
        _ => Element::Vertex(corners[(0..3).find(|&k| !z[k]).unwrap_or(0)]),
    }
}

/// Barycentric distance to an edge under which a hit counts as near it (containment then tries
/// another direction).
pub const NEAR_EDGE: f32 = 1e-6;

/// Whether two hits of one ray are the same crossing under the module's exact rule.
fn same_crossing(a: Element, b: Element) -> bool {
    match (a, b) {
        (Element::Face, _) | (_, Element::Face) => false,
        (Element::Edge(p, q), Element::Edge(r, s)) => (p, q) == (r, s),
        (Element::Vertex(v), Element::Vertex(w)) => v == w,
        (Element::Vertex(v), Element::Edge(p, q)) | (Element::Edge(p, q), Element::Vertex(v)) => v == p || v == q,
    }
}

/// The crossings of `ray` in `(0, t_max)`: its hits merged under the module's rule, each given by its
/// closest hit, in order of `t`.
pub fn crossings(s: &Structure<Collector>, ray: &Ray, t_max: f32) -> Vec<RawHit> {
    let hits = raw_hits(s, ray, t_max);
    merge(s.primitives().mesh.as_ref(), ray, hits).0
}

/// `hits` (sorted) merged into crossings, and whether any lay on an edge or a vertex.
fn merge(mesh: &TriangleMesh, ray: &Ray, hits: Vec<RawHit>) -> (Vec<RawHit>, bool) {
    let elements: Vec<Element> = hits.iter().map(|h| element(mesh, ray, h)).collect();
    let on_edge = elements.iter().any(|e| *e != Element::Face) || hits.iter().any(near_edge);
    if !on_edge {
        return (hits, false);
    }
    // Union of the hits that are one crossing (few per ray: quadratic is fine), keeping for each group
    // its first member, the closest hit since `hits` is sorted.
    let n = hits.len();
    let mut group: Vec<usize> = (0..n).collect();
    for i in 0..n {
        for j in 0..i {
            if same_crossing(elements[i], elements[j]) {
                let (gi, gj) = (root(&group, i), root(&group, j));
                group[gi.max(gj)] = gi.min(gj);
            }
        }
    }
    let kept = (0..n).filter(|&i| root(&group, i) == i).map(|i| hits[i]).collect();
    (kept, true)
}

fn near_edge(h: &RawHit) -> bool {
    h.u.min(h.v).min(1.0 - h.u - h.v) <= NEAR_EDGE
}

fn root(group: &[usize], mut i: usize) -> usize {
    while group[i] != i {
        i = group[i];
    }
    i
}

/// Directions of the containment rays: far from the axes and from each other, so that a ray along
/// one rarely meets an edge or vertex of a mesh made on a grid.
pub const DIRECTIONS: [[f32; 3]; 7] = [
    [0.5773, 0.6138, 0.5386],
    [-0.6719, 0.2953, 0.6793],
    [0.3187, -0.8215, 0.4729],
    [-0.4466, -0.5871, -0.6752],
    [0.7718, -0.1829, -0.6090],
    [-0.2139, 0.9112, -0.3521],
    [0.1213, 0.3391, -0.9329],
];

/// Whether `p` is inside the closed mesh (see the module documentation).
pub fn contains(s: &Structure<Collector>, p: Vec3) -> bool {
    let mesh = s.primitives().mesh.as_ref();
    let mut odd_votes = 0;
    for d in &DIRECTIONS {
        let ray = Ray::new(p, Vec3::from_array(*d));
        let (crossings, on_edge) = merge(mesh, &ray, raw_hits(s, &ray, f32::INFINITY));
        let odd = crossings.len() % 2 == 1;
        if !on_edge {
            return odd;
        }
        odd_votes += odd as usize;
    }
    2 * odd_votes > DIRECTIONS.len()
}
