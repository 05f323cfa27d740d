//! The conformance suite of closest-point queries: every structure (each kind with its defaults, and
//! builder variants the defaults never reach) returns, for every point, exactly what brute force
//! returns: the same primitive, point, squared distance and weights, bit for bit, one query at a time
//! and in batches. Brute force itself is held to a dense sampling of the triangles.
//!
//! The cases: random soups at three scales, offset by 1e5 and scaled by 1e-4; an axis-aligned grid
//! queried exactly on its vertices, edges and cell centres (ties between the triangles sharing them);
//! a closed mesh queried inside, outside and on its surface; duplicated and coplanar triangles
//! (ties at equal distance); degenerate and non-finite triangles; far points; bounds (`max_distance`)
//! of every size; NaN points; and a property test on lattice soups, shrunk to a minimal failing case.
//! Each family declares how many of its queries must be ties (several primitives at the best
//! distance), so that the tie rule is tested and not only the easy cases.

use arbor::accel::{AccelConfig, AccelKind, Nearest, PrimHit, Primitives, Structure};
use arbor::geometry::TriangleMesh;
use arbor::math::{Aabb, DVec3, Ray, Vec3};
use proptest::prelude::*;

mod common;
use common::soups::{closed_cube, mesh_of, random_soup, Rng};

/// Every kind with its defaults, then variants: one-primitive leaves, PLOC, deep octrees.
fn configs() -> Vec<AccelConfig> {
    let mut out: Vec<AccelConfig> = AccelKind::ALL.iter().map(|&k| AccelConfig::from(k)).collect();
    for (kind, pairs) in [
        ("bvh-bottom-up", &["method=ploc", "leaf=1"][..]),
        ("bvh-median", &["leaf=1"]),
        ("bvh-sah", &["leaf=1"]),
        ("octree", &["leaf=1", "depth=12"]),
        ("kdtree", &["traversal-cost=1", "intersection-cost=80"]),
    ] {
        let config: AccelConfig = kind.parse().unwrap();
        out.push(config.with_pairs(pairs.iter().copied()).unwrap());
    }
    out
}

/// Same answer, bit for bit.
fn bits(n: Option<Nearest>) -> Option<(u32, [u64; 3], u64, u64, u64)> {
    n.map(|n| (n.prim, n.point.to_array().map(f64::to_bits), n.dist2.to_bits(), n.u.to_bits(), n.v.to_bits()))
}

/// One query: a point and its bound.
#[derive(Debug, Clone, Copy)]
struct Query {
    p: DVec3,
    max_distance: f64,
}

/// What a family asked: queries per structure, answers (not `None`), and ties among the answers.
#[derive(Debug, Default, Clone, Copy)]
struct Asked {
    queries: usize,
    answers: usize,
    ties: usize,
}

impl std::ops::AddAssign for Asked {
    fn add_assign(&mut self, o: Asked) {
        self.queries += o.queries;
        self.answers += o.answers;
        self.ties += o.ties;
    }
}

impl Asked {
    /// At least `queries` queries, `answers` of them answered and `ties` of them ties: a generator
    /// that drifted away from the geometry would compare `None` with `None`, and check nothing.
    fn require(self, family: &str, queries: usize, answers: f64, ties: f64) {
        assert!(self.queries >= queries, "{family}: {} queries, {queries} required", self.queries);
        let share = |k: usize| k as f64 / self.queries.max(1) as f64;
        assert!(share(self.answers) >= answers, "{family}: {self:?}, answers below {answers}");
        assert!(share(self.ties) >= ties, "{family}: {self:?}, ties below {ties}");
    }
}

/// Checks every structure against brute force on `queries` over `mesh`.
fn check(case: &str, mesh: &TriangleMesh, queries: &[Query]) -> Asked {
    let brute = Structure::build(&"brute".parse().unwrap(), mesh.clone()).unwrap();
    let want: Vec<_> = queries.iter().map(|q| brute.closest_point(q.p, q.max_distance).unwrap()).collect();
    let mut asked = Asked { queries: queries.len(), ..Default::default() };
    for (q, w) in queries.iter().zip(&want) {
        let Some(w) = w else { continue };
        asked.answers += 1;
        let at_best = (0..mesh.len())
            .filter_map(|i| mesh.closest_point(i, q.p))
            .filter(|pp| (pp.point - q.p).length_squared() == w.dist2)
            .count();
        asked.ties += (at_best > 1) as usize;
    }
    for config in configs() {
        let s = Structure::build(&config, mesh.clone()).unwrap();
        s.validate().unwrap();
        for (q, w) in queries.iter().zip(&want) {
            let got = s.closest_point(q.p, q.max_distance).unwrap();
            assert_eq!(bits(got), bits(*w), "{config} on {case}: {q:?} gives {got:?}, brute force {w:?}");
        }
        // Batches: by bound, since a batch has one.
        for md in [f64::INFINITY, 0.5] {
            let (points, expect): (Vec<DVec3>, Vec<_>) =
                queries.iter().zip(&want).filter(|(q, _)| q.max_distance == md).map(|(q, w)| (q.p, *w)).unzip();
            let mut out = vec![None; points.len()];
            s.closest_points_many(&points, md, &mut out).unwrap();
            for (i, (g, w)) in out.iter().zip(&expect).enumerate() {
                assert_eq!(bits(*g), bits(*w), "{config} on {case}: batch point {:?}", points[i]);
            }
        }
    }
    asked
}

/// `n` queries of random flavours around `mesh`: anywhere in its box grown by half, on a triangle (a
/// random convex combination, so a hair off it after rounding), exactly on a vertex, on an edge's
/// midpoint, far away; one in eight with a bound of 0.5, one in sixteen with a bound of 0.
fn queries(mesh: &TriangleMesh, rng: &mut Rng, n: usize) -> Vec<Query> {
    let tris: Vec<[Vec3; 3]> =
        (0..mesh.len()).map(|i| mesh.triangle(i)).filter(|t| t.iter().all(|p| p.is_finite())).collect();
    let bounds = Aabb::from_points(tris.iter().flatten().copied());
    let (lo, size) = (bounds.min - 0.5 * bounds.extent(), 2.0 * bounds.extent());
    (0..n)
        .map(|i| {
            let t = rng.pick(&tris).map(|p| p.as_dvec3());
            let p = match rng.below(6) {
                0 | 1 => (lo + rng.vec3() * size).as_dvec3(),
                2 => {
                    let (u, v) = (rng.f32() as f64, rng.f32() as f64);
                    let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                    t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v
                }
                3 => t[rng.below(3)],
                4 => 0.5 * (t[rng.below(3)] + t[rng.below(3)]),
                _ => (bounds.center() + (rng.vec3() - 0.5) * 1e3 * bounds.extent().max_element()).as_dvec3(),
            };
            let max_distance = match i % 16 {
                0 => 0.0,
                1 | 9 => 0.5,
                _ => f64::INFINITY,
            };
            Query { p, max_distance }
        })
        .collect()
}

fn check_soup(case: &str, tris: &[[Vec3; 3]], rng: &mut Rng, n: usize) -> Asked {
    let mesh = mesh_of(tris);
    let q = queries(&mesh, rng, n);
    check(case, &mesh, &q)
}

#[test]
fn closest_point_matches_brute_force_on_random_soups() {
    let mut rng = Rng::new(1);
    let mut asked = Asked::default();
    for (n, extent, size) in [(300, 10.0, 1.0), (2000, 50.0, 3.0), (40, 1.0, 0.6)] {
        asked += check_soup("soup", &random_soup(&mut rng, n, extent, size), &mut rng, 1500);
    }
    let soup = random_soup(&mut rng, 800, 10.0, 1.5);
    let offset: Vec<_> = soup.iter().map(|t| t.map(|p| p + Vec3::splat(1e5))).collect();
    asked += check_soup("soup offset by 1e5", &offset, &mut rng, 1500);
    let scaled: Vec<_> = soup.iter().map(|t| t.map(|p| p * 1e-4)).collect();
    asked += check_soup("soup scaled by 1e-4", &scaled, &mut rng, 1500);
    // Vertices and unwelded soups: a query on a vertex ties only with duplicates, which soups lack.
    asked.require("soups", 7500, 0.8, 0.0);
}

/// An `n` x `n` grid of unit squares in `z = 0`, two triangles each (welded: shared edges and vertices).
fn grid(n: u32) -> TriangleMesh {
    let v = |i: u32, j: u32| Vec3::new(i as f32, j as f32, 0.0);
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            tris.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            tris.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    mesh_of(&tris)
}

#[test]
fn closest_point_matches_brute_force_on_grid_vertices_and_edges() {
    let mesh = grid(12);
    let mut rng = Rng::new(2);
    // On the lattice of half-integers (vertices, edge midpoints, cell centres on the diagonals), above
    // and below it, beyond the grid's border; all ties between the triangles around a vertex or edge.
    let qs: Vec<Query> = (0..4000)
        .map(|_| {
            let h = |r: &mut Rng| (r.below(30) as f64 - 3.0) * 0.5;
            let z = [0.0, 0.0, 1.0, -2.5][rng.below(4)];
            let max_distance = if rng.below(8) == 0 { 0.5 } else { f64::INFINITY };
            Query { p: DVec3::new(h(&mut rng), h(&mut rng), z), max_distance }
        })
        .collect();
    check("grid", &mesh, &qs).require("grid", 4000, 0.9, 0.5);
}

#[test]
fn closest_point_matches_brute_force_inside_and_on_a_closed_mesh() {
    let tris = closed_cube(6);
    let mesh = mesh_of(&tris);
    let mut rng = Rng::new(3);
    let mut qs = queries(&mesh, &mut rng, 2000);
    // Inside the cube [0, 6]^3, where every face is a candidate; the centre is a six-way tie of faces.
    qs.extend((0..1500).map(|_| Query { p: (rng.vec3() * 5.9 + 0.05).as_dvec3(), max_distance: f64::INFINITY }));
    qs.push(Query { p: DVec3::splat(3.0), max_distance: f64::INFINITY });
    check("closed cube", &mesh, &qs).require("closed cube", 3500, 0.9, 0.15);
}

#[test]
fn closest_point_matches_brute_force_on_duplicated_and_coplanar_triangles() {
    let mut rng = Rng::new(4);
    let mut tris = random_soup(&mut rng, 60, 6.0, 2.0);
    for _ in 0..200 {
        let t = rng.pick(&tris);
        tris.insert(rng.below(tris.len() + 1), t);
    }
    tris.extend((0..80).map(|_| {
        let c = rng.vec3() * 6.0;
        [0; 3].map(|_| (c + (rng.vec3() - 0.5) * 3.0).with_z(1.0))
    }));
    check_soup("duplicates", &tris, &mut rng, 3000).require("duplicates", 3000, 0.8, 0.3);
}

#[test]
fn closest_point_matches_brute_force_on_degenerate_and_non_finite_triangles() {
    let mut rng = Rng::new(5);
    let mut tris = random_soup(&mut rng, 100, 8.0, 2.0);
    for _ in 0..150 {
        let (a, b) = (rng.vec3() * 8.0, rng.vec3() * 8.0);
        let nan = Vec3::new(f32::NAN, a.y, a.z);
        let inf = Vec3::new(a.x, f32::INFINITY, a.z);
        let sliver = [a, b, a + (b - a) * 0.5 + Vec3::splat(1e-6)];
        tris.push(rng.pick(&[[a; 3], [a, 0.5 * (a + b), b], [a, b, nan], [a, inf, b], sliver]));
    }
    let asked = check_soup("degenerates", &tris, &mut rng, 3000);
    asked.require("degenerates", 3000, 0.8, 0.0);
    // A triangle with a non-finite corner is never the answer, even on its finite corners.
    let mesh = mesh_of(&[[Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)], [Vec3::Z, Vec3::ONE, Vec3::Y]]);
    for config in configs() {
        let s = Structure::build(&config, mesh.clone()).unwrap();
        assert_eq!(s.closest_point(DVec3::ZERO, f64::INFINITY).unwrap().map(|n| n.prim), Some(1), "{config}");
    }
}

#[test]
fn closest_point_of_brute_force_agrees_with_a_dense_sampling() {
    let mut rng = Rng::new(6);
    let tris = random_soup(&mut rng, 12, 3.0, 2.0);
    let mesh = mesh_of(&tris);
    let brute = Structure::build(&"brute".parse().unwrap(), mesh).unwrap();
    let n = 120;
    let samples: Vec<DVec3> = tris
        .iter()
        .flat_map(|t| {
            let t = t.map(|p| p.as_dvec3());
            (0..=n).flat_map(move |i| {
                (0..=n - i)
                    .map(move |j| t[0] + (t[1] - t[0]) * (i as f64 / n as f64) + (t[2] - t[0]) * (j as f64 / n as f64))
            })
        })
        .collect();
    for q in queries(&mesh_of(&tris), &mut rng, 300) {
        let Some(got) = brute.closest_point(q.p, f64::INFINITY).unwrap() else { panic!("{q:?}: no answer") };
        let sampled = samples.iter().map(|s| (*s - q.p).length()).fold(f64::INFINITY, f64::min);
        // Never farther than a sample; nearer by at most the sampling's spacing (edges up to ~3.5).
        assert!(got.distance() <= sampled + 1e-12, "{q:?}: {got:?} farther than a sample at {sampled}");
        assert!(got.distance() >= sampled - 3.5 / n as f64, "{q:?}: {got:?} nearer than the samples allow ({sampled})");
        let t = tris[got.prim as usize].map(|p| p.as_dvec3());
        let at = t[0] + (t[1] - t[0]) * got.u + (t[2] - t[0]) * got.v;
        assert!((at - got.point).length() < 1e-9, "{q:?}: the weights {got:?} name {at}");
    }
}

#[test]
fn closest_point_without_an_answer_nan_points_empty_meshes_and_bounds() {
    let mesh = mesh_of(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
    for config in configs() {
        let s = Structure::build(&config, mesh.clone()).unwrap();
        let at = |p: DVec3, md: f64| s.closest_point(p, md).unwrap().map(|n| (n.prim, n.dist2));
        assert_eq!(at(DVec3::new(f64::NAN, 0.0, 0.0), f64::INFINITY), None, "{config}");
        assert_eq!(at(DVec3::new(0.0, f64::NEG_INFINITY, 0.0), f64::INFINITY), None, "{config}");
        assert_eq!(at(DVec3::ZERO, f64::NAN), None, "{config}");
        assert_eq!(at(DVec3::ZERO, -1.0), None, "{config}");
        assert_eq!(at(DVec3::new(0.25, 0.25, 0.0), 0.0), Some((0, 0.0)), "{config}: on the surface, bound 0");
        assert_eq!(at(DVec3::new(0.25, 0.25, 2.0), 2.0), Some((0, 4.0)), "{config}: the bound is inclusive");
        assert_eq!(at(DVec3::new(0.25, 0.25, 2.0), 2f64.next_down()), None, "{config}");
        assert_eq!(at(DVec3::splat(1e300), f64::INFINITY).map(|a| a.0), Some(0), "{config}: far away");
        let empty = Structure::build(&config, TriangleMesh::default()).unwrap();
        assert_eq!(empty.closest_point(DVec3::ZERO, f64::INFINITY).unwrap(), None, "{config}");
    }
}

/// Primitives that cannot tell their closest point: spheres, as a renderer has them.
struct Balls(Vec<Vec3>);

impl Primitives for Balls {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: usize) -> Aabb {
        Aabb::new(self.0[i] - 0.5, self.0[i] + 0.5)
    }
    fn intersect(&self, _: usize, _: &Ray, _: f32) -> Option<PrimHit> {
        None
    }
}

#[test]
fn closest_point_over_primitives_without_one_is_an_error_not_an_answer() {
    for config in configs() {
        let s = Structure::build(&config, Balls(vec![Vec3::ZERO, Vec3::X])).unwrap();
        let err = s.closest_point(DVec3::ZERO, f64::INFINITY).unwrap_err();
        assert_eq!(err.kind, config.kind());
        assert_eq!(
            err.to_string(),
            format!(
                "{}: closest-point queries need primitives that give their closest point (triangle meshes do; these do not)",
                config.kind()
            )
        );
        assert!(s.closest_points_many(&[DVec3::ZERO], 1.0, &mut [None]).is_err());
    }
}

// Property test: small soups on a coarse lattice and points on a finer one (shared vertices, coplanar
// faces and equal distances are common), shrunk to a minimal failing scene and point.

fn lattice_point() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-8i32..=8).prop_map(|[x, y, z]| Vec3::new(x as f32, y as f32, z as f32) / 4.0)
}

fn lattice_query() -> impl Strategy<Value = Query> {
    (prop::array::uniform3(-24i32..=24), 0u8..4).prop_map(|(c, b)| Query {
        p: DVec3::from_array(c.map(|x| x as f64 / 8.0)),
        max_distance: [f64::INFINITY, f64::INFINITY, 0.5, 0.0][b as usize],
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn closest_point_matches_brute_force_on_lattice_soups(
        tris in prop::collection::vec(prop::array::uniform3(lattice_point()), 1..40),
        qs in prop::collection::vec(lattice_query(), 1..64),
    ) {
        check("lattice soup", &mesh_of(&tris), &qs);
    }
}
