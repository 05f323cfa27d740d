//! The conformance suite every acceleration structure must pass: for each ray, the same hit (or none),
//! the same primitive index, the same `t` and surface parameters bit for bit, and the same `occluded`
//! answer as brute force. It loops over [`AccelKind::ALL`], so a new structure runs through every case
//! here as soon as the factory knows it.
//!
//! The cases follow Embree's verify checklist: random soups at three scales (a proptest family that
//! shrinks to a minimal scene and ray, plus seeded loops for volume), soups offset by 1e5 and scaled by
//! 1e-4, axis-aligned grids hit exactly on shared edges and vertices, a closed mesh hit from inside and
//! again from its hit points, duplicated and coplanar triangles
//! (ties at equal `t`), degenerate and non-finite triangles, rays along the axes (with signed zeros),
//! rays starting inside primitive boxes and exactly on their faces, triangles mixed with spheres, empty
//! and single-primitive sets, and NaN or infinite rays. Every case is also traced in batches
//! (`intersect_many`), which must give each ray the hit of its own query. Every family declares how
//! many rays it casts and the share of them that must hit something ([`Cast::require`]), so that a
//! generator that stops aiming at the geometry fails instead of comparing misses with misses.

use arbor::accel::{build, Accel, AccelKind, Hit, PrimHit, Primitives};
use arbor::geometry::{intersect_triangle, Sphere, TriangleMesh};
use arbor::math::{Aabb, Ray, Transform, Vec3};
use proptest::prelude::*;

mod common;
use common::soups::{closed_cube, mesh_of, random_soup, Rng};

// ---------------------------------------------------------------------------------------------------
// The harness

/// One query: a ray and its `t_max`.
#[derive(Debug, Clone, Copy)]
struct Probe {
    ray: Ray,
    t_max: f32,
}

/// Same hit, bit for bit: both none, or the same primitive at the same `t` with the same surface
/// parameters (`to_bits`, so that even a `t` one ulp apart, or a `-0.0` for a `0.0`, is a difference).
fn same_hit(a: Option<Hit>, b: Option<Hit>) -> bool {
    let bits = |h: Option<Hit>| h.map(|h| (h.prim, h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.sub));
    bits(a) == bits(b)
}

/// What a family of rays cast: rays per structure, and how many of them hit something (brute force).
#[derive(Debug, Default, Clone, Copy)]
struct Cast {
    rays: usize,
    hits: usize,
}

impl std::ops::AddAssign for Cast {
    fn add_assign(&mut self, o: Cast) {
        self.rays += o.rays;
        self.hits += o.hits;
    }
}

impl Cast {
    /// Asserts that `family` cast at least `rays` rays per structure and that at least `floor` of them
    /// hit something: a generator that broke so that its rays miss everything would still agree with
    /// brute force, and check nothing.
    fn require(self, family: &str, rays: usize, floor: f64) {
        assert!(self.rays >= rays, "{family}: {} rays cast, {rays} required", self.rays);
        let rate = self.hits as f64 / self.rays.max(1) as f64;
        assert!(
            rate >= floor,
            "{family}: {} of {} rays hit ({:.1}%, floor {:.1}%): its generator no longer aims at the geometry",
            self.hits,
            self.rays,
            100.0 * rate,
            100.0 * floor
        );
    }
}

/// Checks every structure against brute force on `probes`; returns the rays cast per structure and how
/// many hit. Besides `occluded` at `t_max`, each hit at `t` is also checked with `occluded` at exactly
/// `t` (false: the interval is open and nothing is closer) and at the next float (true). Brute force is
/// the reference, so it is only held to those two, on every 16th ray to keep the suite fast.
fn check<P: Primitives + 'static>(case: &str, prims: &P, probes: &[Probe]) -> Cast {
    let brute = build(AccelKind::Brute, prims);
    let expected: Vec<_> = probes
        .iter()
        .map(|p| (brute.intersect(prims, &p.ray, p.t_max), brute.occluded(prims, &p.ray, p.t_max)))
        .collect();
    for &kind in AccelKind::ALL {
        let accel = build(kind, prims);
        // `build` validates only in debug builds; the suite runs in release (README's one build).
        accel.validate(prims).unwrap_or_else(|e| panic!("{kind} on {case}: invalid structure: {e}"));
        let is_reference = kind == AccelKind::Brute;
        let step = if is_reference { 16 } else { 1 };
        let mut single = Vec::with_capacity(probes.len());
        for (p, &(hit, occluded)) in probes.iter().zip(&expected).step_by(step) {
            if let Some(h) = hit {
                let t_above = h.t.next_up();
                let got = (accel.occluded(prims, &p.ray, h.t), accel.occluded(prims, &p.ray, t_above));
                assert_eq!(
                    got,
                    (false, true),
                    "{kind} on {case}: occluded just at and above the hit t {} {:?}",
                    h.t,
                    p.ray
                );
            }
            if is_reference {
                continue;
            }
            let got = accel.intersect(prims, &p.ray, p.t_max);
            single.push(got);
            assert!(
                same_hit(got, hit),
                "{kind} on {case}: {:?} t_max {} hit {got:?}, brute force {hit:?}",
                p.ray,
                p.t_max
            );
            let got = accel.occluded(prims, &p.ray, p.t_max);
            assert_eq!(got, occluded, "{kind} on {case}: occluded {:?} t_max {}", p.ray, p.t_max);
        }
        if !is_reference {
            check_batches(case, kind, accel.as_ref(), prims, probes, &single, &expected);
        }
    }
    Cast { rays: probes.len(), hits: expected.iter().filter(|(hit, _)| hit.is_some()).count() }
}

/// `intersect_many` gives each probe the very hit its own query gave (`single`), and `occluded_many`
/// brute force's answer (`expected`), also at exactly each hit's `t` (false) and the float above
/// (true); in batches of 1, 2, 3, 5, 8, 13 and 64 probes in turn (odd sizes leave a slot of the
/// interleaved BVH idle, long ones refill its slots many times).
fn check_batches<P: Primitives>(
    case: &str,
    kind: AccelKind,
    accel: &dyn Accel<P>,
    prims: &P,
    probes: &[Probe],
    single: &[Option<Hit>],
    expected: &[(Option<Hit>, bool)],
) {
    let rays: Vec<Ray> = probes.iter().map(|p| p.ray).collect();
    let t_max: Vec<f32> = probes.iter().map(|p| p.t_max).collect();
    let mut batched = vec![None; probes.len()];
    let mut blocked = vec![false; probes.len()];
    let hit_t: Vec<f32> = expected.iter().zip(&t_max).map(|((h, _), &t)| h.map_or(t, |h| h.t)).collect();
    let above: Vec<f32> = expected.iter().zip(&t_max).map(|((h, _), &t)| h.map_or(t, |h| h.t.next_up())).collect();
    let (mut at, mut past) = (vec![false; probes.len()], vec![false; probes.len()]);
    let (mut start, mut k) = (0, 0);
    while start < probes.len() {
        let end = (start + [1, 2, 3, 5, 8, 13, 64][k % 7]).min(probes.len());
        let r = start..end;
        accel.intersect_many(prims, &rays[r.clone()], &t_max[r.clone()], &mut batched[r.clone()]);
        accel.occluded_many(prims, &rays[r.clone()], &t_max[r.clone()], &mut blocked[r.clone()]);
        accel.occluded_many(prims, &rays[r.clone()], &hit_t[r.clone()], &mut at[r.clone()]);
        accel.occluded_many(prims, &rays[r.clone()], &above[r.clone()], &mut past[r]);
        (start, k) = (end, k + 1);
    }
    for (i, (p, &(hit, occluded))) in probes.iter().zip(expected).enumerate() {
        assert_eq!(blocked[i], occluded, "{kind} on {case}: batch occluded of probe {i} {:?} t_max {}", p.ray, p.t_max);
        if hit.is_some() {
            assert_eq!(
                (at[i], past[i]),
                (false, true),
                "{kind} on {case}: batch occluded of probe {i} just at and above the hit t {} {:?}",
                hit_t[i],
                p.ray
            );
        }
    }
    for (i, p) in probes.iter().enumerate() {
        assert!(
            same_hit(batched[i], single[i]),
            "{kind} on {case}: batch hit of probe {i} {:?} t_max {}: {:?}, alone {:?}",
            p.ray,
            p.t_max,
            batched[i],
            single[i]
        );
    }
}

/// Points and boxes worth aiming at: primitive box corners and centres, and extra points (vertices).
struct Targets {
    bounds: Aabb,
    points: Vec<Vec3>,
    boxes: Vec<Aabb>,
}

impl Targets {
    fn of<P: Primitives>(prims: &P, extra: &[Vec3]) -> Self {
        let mut boxes: Vec<Aabb> = (0..prims.len())
            .map(|i| prims.bounds(i))
            .filter(|b| !b.is_empty() && b.min.is_finite() && b.max.is_finite())
            .collect();
        let mut points: Vec<Vec3> = extra.iter().copied().filter(|p| p.is_finite()).collect();
        for b in &boxes {
            points.extend([b.min, b.max, b.center()]);
        }
        let mut bounds = points.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p));
        if bounds.is_empty() {
            bounds = Aabb::new(Vec3::splat(-1.0), Vec3::ONE);
            points.push(Vec3::ZERO);
        }
        if boxes.is_empty() {
            boxes.push(bounds);
        }
        Targets { bounds, points, boxes }
    }

    /// The scene box grown by half its size on every side.
    fn around(&self) -> Aabb {
        let pad = 0.5 * self.bounds.extent() + Vec3::splat(1e-3 * self.bounds.max.abs().max_element());
        Aabb::new(self.bounds.min - pad, self.bounds.max + pad)
    }

    /// A ray of a random flavour; see the module docs.
    fn probe(&self, rng: &mut Rng) -> Probe {
        let around = self.around();
        let (origin, dir) = match rng.below(6) {
            // Aimed at a corner, centre or vertex: grazes edges and ties on shared vertices.
            0 => {
                let o = rng.in_box(&around);
                (o, rng.pick(&self.points) - o)
            }
            1 => (rng.in_box(&around), rng.vec3() - 0.5),
            // Along an axis through a target point's lines: exactly on edges of axis-aligned geometry.
            2 => {
                let mut o = rng.pick(&self.points);
                let axis = rng.below(3);
                o[axis] = rng.in_box(&around)[axis];
                (o, signed_axis(rng, axis))
            }
            // From inside a primitive's box.
            3 => {
                let b = rng.pick(&self.boxes);
                (rng.in_box(&b), rng.vec3() - 0.5)
            }
            // From a face of a primitive's box, sometimes parallel to that face.
            4 => {
                let b = rng.pick(&self.boxes);
                let mut o = rng.in_box(&b);
                let axis = rng.below(3);
                o[axis] = if rng.below(2) == 0 { b.min[axis] } else { b.max[axis] };
                let mut d = rng.vec3() - 0.5;
                if rng.below(2) == 0 {
                    d[axis] = if rng.below(2) == 0 { 0.0 } else { -0.0 };
                }
                (o, d)
            }
            // From a vertex or corner itself (re-intersection from a hit point).
            _ => (rng.pick(&self.points), rng.vec3() - 0.5),
        };
        let t_max = if rng.below(5) == 0 {
            rng.f32() * 2.0 * around.extent().length() / dir.length().max(1e-30)
        } else {
            f32::INFINITY
        };
        Probe { ray: Ray::new(origin, dir), t_max }
    }

    fn probes(&self, rng: &mut Rng, n: usize) -> Vec<Probe> {
        (0..n).map(|_| self.probe(rng)).collect()
    }
}

/// A unit direction along `axis`, either sign, with the other components +0 or -0 (their reciprocals
/// are +inf or -inf, which slab tests must treat alike).
fn signed_axis(rng: &mut Rng, axis: usize) -> Vec3 {
    let mut d = Vec3::ZERO;
    for a in 0..3 {
        d[a] = if rng.below(2) == 0 { 0.0 } else { -0.0 };
    }
    d[axis] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
    d
}

/// Checks a mesh made of `tris` with `n` random probes aimed at its vertices and boxes.
fn check_mesh(case: &str, tris: &[[Vec3; 3]], rng: &mut Rng, n: usize) -> Cast {
    let mesh = mesh_of(tris);
    let vertices: Vec<Vec3> = tris.iter().flatten().copied().collect();
    let probes = Targets::of(&mesh, &vertices).probes(rng, n);
    check(case, &mesh, &probes)
}

/// The contract's interval is open: a hit at exactly `t_max` does not count, for the reference either.
#[test]
fn brute_force_excludes_hits_at_exactly_t_max() {
    let tri = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    let mesh = mesh_of(&[tri]);
    let ray = Ray::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
    let brute = build(AccelKind::Brute, &mesh);
    let t = brute.intersect(&mesh, &ray, f32::INFINITY).unwrap().t;
    assert_eq!(brute.intersect(&mesh, &ray, t), None);
    assert!(!brute.occluded(&mesh, &ray, t));
}

// ---------------------------------------------------------------------------------------------------
// Ray budget: each family casts at least this many rays per structure.

const SOUP_RAYS: usize = 40 * 2_500 + 12 * 20_000 + 2 * 15_000;
const SCALED_RAYS: usize = 2 * 100_000;
const GRID_RAYS: usize = 100_000;
const CLOSED_MESH_RAYS: usize = 50_000;
const DUPLICATE_RAYS: usize = 100_000;
const DEGENERATE_RAYS: usize = 80_000;
const AXIS_RAYS: usize = 100_000;
const SUBNORMAL_RAYS: usize = 50_000;
const MIXED_RAYS: usize = 100_000;
const TINY_SET_RAYS: usize = 3 * 10_000;
const NAN_RAYS: usize = 8 * 9;

// Hit-rate floors: the share of each family's rays that must hit something, about half of the share its
// generator gives (so a change of seeds or sizes passes, a generator that stops aiming fails).
const FLOOR_SOUPS: f64 = 0.11;
const FLOOR_SCALED: f64 = 0.14;
const FLOOR_GRID: f64 = 0.18;
const FLOOR_CLOSED_MESH: f64 = 0.38;
const FLOOR_DUPLICATES: f64 = 0.17;
const FLOOR_DEGENERATES: f64 = 0.045;
const FLOOR_AXIS: f64 = 0.24;
const FLOOR_SUBNORMAL: f64 = 0.22;
const FLOOR_MIXED: f64 = 0.23;
const FLOOR_TINY_SETS: f64 = 0.09;
const FLOOR_OCTREE_FACES: f64 = 0.36;
const FLOOR_VARIANTS: f64 = 0.16;
const FLOOR_LATTICE: f64 = 0.27;

// ---------------------------------------------------------------------------------------------------
// Triangle soups

#[test]
fn accel_matches_brute_force_on_random_soups_at_three_scales() {
    let mut cast = Cast::default();
    for seed in 0..40 {
        let mut rng = Rng::new(seed);
        let n = 1 + rng.below(24);
        let tris = random_soup(&mut rng, n, 4.0, 1.5);
        cast += check_mesh("small soup", &tris, &mut rng, 2_500);
    }
    for seed in 0..12 {
        let mut rng = Rng::new(100 + seed);
        let tris = random_soup(&mut rng, 300, 20.0, 2.0);
        cast += check_mesh("medium soup", &tris, &mut rng, 20_000);
    }
    for seed in 0..2 {
        let mut rng = Rng::new(200 + seed);
        let tris = random_soup(&mut rng, 4_000, 100.0, 3.0);
        cast += check_mesh("large soup", &tris, &mut rng, 15_000);
    }
    cast.require("soups", SOUP_RAYS, FLOOR_SOUPS);
}

#[test]
fn accel_matches_brute_force_on_offset_and_scaled_soups() {
    let mut cast = Cast::default();
    for (case, map) in [
        ("soup offset by 1e5", (|p: Vec3| p + Vec3::splat(1e5)) as fn(Vec3) -> Vec3),
        ("soup scaled by 1e-4", |p: Vec3| p * 1e-4),
    ] {
        for seed in 0..4 {
            let mut rng = Rng::new(300 + seed);
            let tris: Vec<_> = random_soup(&mut rng, 250, 10.0, 1.5).into_iter().map(|t| t.map(map)).collect();
            cast += check_mesh(case, &tris, &mut rng, 25_000);
        }
    }
    cast.require("offset and scaled soups", SCALED_RAYS, FLOOR_SCALED);
}

/// Unit squares (two triangles each) on the integer planes `x = k`, `y = k` and `z = k`: neighbours
/// share edges exactly, and the planes of different families cross along the same lines.
fn grid(cells: u32, planes: u32) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for axis in 0..3 {
        let frame = |k: u32, i: u32, j: u32| {
            let mut p = Vec3::ZERO;
            p[axis] = k as f32;
            p[(axis + 1) % 3] = i as f32;
            p[(axis + 2) % 3] = j as f32;
            p
        };
        for k in 0..planes {
            for i in 0..cells {
                for j in 0..cells {
                    let [a, b, c, d] = [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(di, dj)| frame(2 * k, i + di, j + dj));
                    tris.push([a, b, c]);
                    tris.push([a, c, d]);
                }
            }
        }
    }
    tris
}

#[test]
fn accel_matches_brute_force_on_axis_aligned_grids() {
    let tris = grid(6, 4);
    let mut rng = Rng::new(400);
    let mesh = mesh_of(&tris);
    // Origins and targets on the half-integer lattice: rays run exactly along edges and through
    // vertices, where two to six triangles tie.
    let lattice = |rng: &mut Rng| (rng.vec3() * 16.0 - 2.0).map(|x| (x * 2.0).round() / 2.0);
    let mut probes = Vec::with_capacity(GRID_RAYS);
    let targets = Targets::of(&mesh, &tris.concat());
    while probes.len() < GRID_RAYS {
        let o = lattice(&mut rng);
        let dir = match rng.below(3) {
            0 => lattice(&mut rng) - o,
            1 => {
                let axis = rng.below(3);
                signed_axis(&mut rng, axis)
            }
            _ => {
                probes.push(targets.probe(&mut rng));
                continue;
            }
        };
        probes.push(Probe { ray: Ray::new(o, dir), t_max: f32::INFINITY });
    }
    check("grid", &mesh, &probes).require("grid", GRID_RAYS, FLOOR_GRID);
}

#[test]
fn accel_matches_brute_force_on_duplicated_and_coplanar_triangles() {
    let mut rng = Rng::new(500);
    let mut tris = random_soup(&mut rng, 60, 6.0, 2.0);
    // Copies at random indices, so that the lowest-index rule is exercised across leaves.
    for _ in 0..120 {
        let t = rng.pick(&tris);
        let at = rng.below(tris.len() + 1);
        tris.insert(at, t);
    }
    // Overlapping triangles in the planes z = 1 and z = 3: equal t on every overlap.
    for _ in 0..80 {
        let z = if rng.below(2) == 0 { 1.0 } else { 3.0 };
        let c = rng.vec3() * 6.0;
        tris.push([0; 3].map(|_| (c + (rng.vec3() - 0.5) * 3.0).with_z(z)));
    }
    check_mesh("duplicates", &tris, &mut rng, DUPLICATE_RAYS).require("duplicates", DUPLICATE_RAYS, FLOOR_DUPLICATES);
}

#[test]
fn accel_matches_brute_force_on_degenerate_and_non_finite_triangles() {
    let mut rng = Rng::new(600);
    let mut tris = random_soup(&mut rng, 100, 8.0, 2.0);
    for _ in 0..150 {
        let a = rng.vec3() * 8.0;
        let b = rng.vec3() * 8.0;
        let bad = [
            [a, a, b],                                             // two equal corners
            [a, 0.5 * (a + b), b],                                 // collinear
            [a; 3],                                                // a point
            [a, a + Vec3::X * 1e-30, a + Vec3::Y * 1e-30],         // far below float spacing
            [a, b, Vec3::new(f32::NAN, a.y, a.z)],                 // NaN corner
            [a, b, Vec3::new(a.x, f32::INFINITY, a.z)],            // infinite corner
            [Vec3::splat(f32::NAN); 3],                            // nothing at all
            [a, Vec3::splat(-1e30), Vec3::new(1e30, -1e30, 1e30)], // huge
        ];
        tris.push(rng.pick(&bad));
    }
    // Slivers, long and a hair wide, whose `t` is least accurate for rays grazing them.
    for _ in 0..60 {
        let a = rng.vec3() * 8.0;
        let along = (rng.vec3() - 0.5) * 10.0;
        let across = (rng.vec3() - 0.5) * 1e-4;
        tris.push([a, a + along, a + 0.5 * along + across]);
    }
    check_mesh("degenerates", &tris, &mut rng, DEGENERATE_RAYS).require(
        "degenerates",
        DEGENERATE_RAYS,
        FLOOR_DEGENERATES,
    );
}

#[test]
fn accel_matches_brute_force_on_rays_along_the_axes() {
    let mut rng = Rng::new(700);
    let tris = random_soup(&mut rng, 300, 10.0, 2.0);
    let mesh = mesh_of(&tris);
    let targets = Targets::of(&mesh, &tris.concat());
    let probes: Vec<_> = (0..AXIS_RAYS)
        .map(|_| {
            // Two coordinates from a vertex or box corner: the ray meets it, or runs along a box face.
            let mut o = rng.pick(&targets.points);
            let axis = rng.below(3);
            let around = targets.around();
            o[axis] = rng.in_box(&around)[axis];
            Probe { ray: Ray::new(o, signed_axis(&mut rng, axis)), t_max: f32::INFINITY }
        })
        .collect();
    check("axis rays", &mesh, &probes).require("axis rays", AXIS_RAYS, FLOOR_AXIS);
}

/// Rays whose direction has subnormal components (reciprocals overflow to infinity) or components
/// negligible against the largest one, from points a subnormal distance off vertices and box planes,
/// and rays with huge directions: the slab tests must
/// not put a box met at a finite `t` at infinity (a fuzz finding, `tests/fuzz_regressions.rs`).
#[test]
fn accel_matches_brute_force_on_rays_with_subnormal_components() {
    let mut rng = Rng::new(710);
    let mut tris = random_soup(&mut rng, 200, 10.0, 3.0);
    tris.extend(grid(3, 2));
    let mesh = mesh_of(&tris);
    let targets = Targets::of(&mesh, &tris.concat());
    let around = targets.around();
    let subnormal = |rng: &mut Rng| {
        let s = f32::from_bits(1 + rng.u32() % 0x007f_ffff);
        if rng.below(2) == 0 {
            s
        } else {
            -s
        }
    };
    let probes: Vec<_> = (0..SUBNORMAL_RAYS)
        .map(|_| {
            let target = rng.pick(&targets.points);
            let mut o = if rng.below(2) == 0 { rng.in_box(&around) } else { target };
            let mut d = target - o;
            if d == Vec3::ZERO {
                d = rng.vec3() - 0.5;
            }
            for a in 0..3 {
                match rng.below(5) {
                    0 => d[a] = subnormal(&mut rng),
                    1 => o[a] = target[a] + subnormal(&mut rng),
                    // From the target's plane, drifting off it at a ratio to the largest component
                    // about `f32::MIN_POSITIVE`: the triangle test's shear by that ratio underflows (or
                    // just does not), so it sees the ray stay in the plane.
                    2 => {
                        o[a] = target[a];
                        d[a] = d.abs().max_element() * f32::MIN_POSITIVE * 2.0 * (rng.f32() - 0.5);
                    }
                    _ => {}
                }
            }
            if rng.below(8) == 0 {
                d *= 1e30;
            }
            Probe { ray: Ray::new(o, d), t_max: f32::INFINITY }
        })
        .collect();
    check("subnormal rays", &mesh, &probes).require("subnormal rays", SUBNORMAL_RAYS, FLOOR_SUBNORMAL);
}

#[test]
fn accel_matches_brute_force_inside_a_closed_mesh_and_from_hit_points() {
    let mut rng = Rng::new(450);
    let mesh = mesh_of(&closed_cube(8));
    let inside = Aabb::new(Vec3::splat(1e-3), Vec3::splat(8.0 - 1e-3));
    let brute = build(AccelKind::Brute, &mesh);
    let mut probes = Vec::with_capacity(CLOSED_MESH_RAYS);
    while probes.len() < CLOSED_MESH_RAYS {
        // Lattice origins put some rays exactly through edges and vertices from inside.
        let mut o = rng.in_box(&inside);
        if rng.below(2) == 0 {
            o = o.round().clamp(Vec3::ONE, Vec3::splat(7.0));
        }
        let ray = Ray::new(o, rng.vec3() - 0.5);
        let hit = brute.intersect(&mesh, &ray, f32::INFINITY);
        assert!(hit.is_some() || !ray.is_valid(), "{ray:?} leaked out");
        probes.push(Probe { ray, t_max: f32::INFINITY });
        // Re-intersection from the hit point: either leaves through the surface or hits it again.
        if let Some(h) = hit {
            let ray = Ray::new(ray.at(h.t), rng.vec3() - 0.5);
            probes.push(Probe { ray, t_max: f32::INFINITY });
        }
    }
    check("closed cube", &mesh, &probes).require("closed cube", CLOSED_MESH_RAYS, FLOOR_CLOSED_MESH);
}

// ---------------------------------------------------------------------------------------------------
// Triangles and spheres together

/// A mixed set, the shape of a top-level structure over objects.
enum Shape {
    Triangle([Vec3; 3]),
    Sphere(Sphere),
}

struct Shapes(Vec<Shape>);

impl Primitives for Shapes {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: usize) -> Aabb {
        match &self.0[i] {
            Shape::Triangle(t) => Aabb::from_points(*t),
            Shape::Sphere(s) => s.bounds(),
        }
    }
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit> {
        match &self.0[i] {
            Shape::Triangle([a, b, c]) => {
                intersect_triangle(ray, *a, *b, *c, t_max).map(|h| PrimHit::new(h.t, h.b1, h.b2))
            }
            Shape::Sphere(s) => s.intersect(ray, t_max).map(|t| PrimHit::new(t, 0.0, 0.0)),
        }
    }
}

#[test]
fn accel_matches_brute_force_on_triangles_mixed_with_spheres() {
    let mut rng = Rng::new(800);
    let mut shapes: Vec<Shape> = random_soup(&mut rng, 150, 10.0, 2.0).into_iter().map(Shape::Triangle).collect();
    for i in 0..80 {
        let center = rng.vec3() * 10.0;
        // Some ellipsoids, some duplicates of the previous sphere (ties between spheres).
        let transform = match i % 4 {
            0 => Transform::scale(Vec3::new(2.0, 0.5, 1.0)).unwrap(),
            _ => Transform::IDENTITY,
        };
        let sphere = Sphere { center, radius: 0.05 + rng.f32(), transform };
        let at = rng.below(shapes.len() + 1);
        shapes.insert(at, Shape::Sphere(sphere));
        if i % 8 == 1 {
            shapes.push(Shape::Sphere(sphere));
        }
    }
    let shapes = Shapes(shapes);
    let probes = Targets::of(&shapes, &[]).probes(&mut rng, MIXED_RAYS);
    check("triangles and spheres", &shapes, &probes).require("triangles and spheres", MIXED_RAYS, FLOOR_MIXED);
}

// ---------------------------------------------------------------------------------------------------
// Tiny sets and invalid rays

#[test]
fn accel_matches_brute_force_on_empty_and_single_primitive_sets() {
    let mut rng = Rng::new(900);
    let empty = TriangleMesh::default();
    let probes = Targets::of(&empty, &[]).probes(&mut rng, 10_000);
    let empty_cast = check("empty set", &empty, &probes);
    assert_eq!(empty_cast.hits, 0, "nothing to hit in an empty set");
    let mut cast = empty_cast;
    let tri = [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 0.0, 3.0)];
    cast += check_mesh("one triangle", &[tri], &mut rng, 10_000);
    let sphere = Shapes(vec![Shape::Sphere(Sphere {
        center: Vec3::new(1.0, 2.0, 3.0),
        radius: 0.5,
        transform: Transform::IDENTITY,
    })]);
    let probes = Targets::of(&sphere, &[]).probes(&mut rng, 10_000);
    cast += check("one sphere", &sphere, &probes);
    cast.require("tiny sets", TINY_SET_RAYS, FLOOR_TINY_SETS);
}

#[test]
fn accel_nan_and_infinite_rays_hit_nothing() {
    let mut rng = Rng::new(1000);
    let tris = random_soup(&mut rng, 200, 5.0, 2.0);
    let mesh = mesh_of(&tris);
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let good_o = Vec3::splat(-1.0);
    let good_d = Vec3::ONE;
    let origins = [Vec3::new(nan, 1.0, 1.0), Vec3::new(1.0, inf, 1.0), Vec3::new(1.0, 1.0, -inf), Vec3::splat(nan)];
    let dirs = [Vec3::new(nan, 1.0, 1.0), Vec3::new(inf, 0.0, 0.0), Vec3::new(1.0, -inf, 1.0), Vec3::ZERO];
    let mut rays: Vec<Ray> = origins.iter().map(|&o| Ray::new(o, good_d)).collect();
    rays.extend(dirs.iter().map(|&d| Ray::new(good_o, d)));
    let mut probes = Vec::new();
    for ray in rays {
        for t_max in [inf, 10.0, nan, 0.0, -1.0, -inf, f32::MIN_POSITIVE, f32::MAX, 1e-30] {
            probes.push(Probe { ray, t_max });
        }
    }
    // A valid ray under an invalid t_max must miss too.
    let valid = Ray::new(good_o, good_d);
    for t_max in [nan, 0.0, -1.0, -inf] {
        probes.push(Probe { ray: valid, t_max });
    }
    // This family's rays must all miss (asserted below), so its floor is zero.
    check("invalid rays", &mesh, &probes).require("invalid rays", NAN_RAYS, 0.0);
    let brute = build(AccelKind::Brute, &mesh);
    for p in &probes {
        assert_eq!(brute.intersect(&mesh, &p.ray, p.t_max), None, "{p:?}");
    }
}

// ---------------------------------------------------------------------------------------------------
// Property test: small soups on a coarse lattice (shared vertices, coplanar faces and equal-t ties are
// common), shrunk to a minimal failing scene and ray.

fn lattice_point() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-12i32..=12).prop_map(|[x, y, z]| Vec3::new(x as f32, y as f32, z as f32) / 4.0)
}

/// A ray of the lattice family: origin, target and mode (0: +x, 1: -z, 2: at the target, 3: at the
/// target with `t_max` 1).
type LatticeRay = (Vec3, Vec3, u8);

/// A small soup on the lattice and rays between lattice points, some along the axes, some short.
fn lattice_case() -> impl Strategy<Value = (Vec<[Vec3; 3]>, Vec<LatticeRay>)> {
    (
        prop::collection::vec(prop::array::uniform3(lattice_point()), 0..48),
        prop::collection::vec((lattice_point(), lattice_point(), 0u8..4), 1..96),
    )
}

fn lattice_probes(rays: &[LatticeRay]) -> Vec<Probe> {
    rays.iter()
        .map(|&(o, target, mode)| {
            let dir = match mode {
                0 => Vec3::X,
                1 => -Vec3::Z,
                _ => target - o,
            };
            Probe { ray: Ray::new(o, dir), t_max: if mode == 3 { 1.0 } else { f32::INFINITY } }
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(192))]

    #[test]
    fn accel_matches_brute_force_on_lattice_soups((tris, rays) in lattice_case()) {
        check("lattice soup", &mesh_of(&tris), &lattice_probes(&rays));
    }
}

/// The property test's cases, drawn as it draws them, hit often enough to test something (proptest
/// cannot sum over its cases).
#[test]
fn lattice_soup_rays_hit_the_soup() {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = lattice_case();
    let mut cast = Cast::default();
    for _ in 0..192 {
        let (tris, rays) = strategy.new_tree(&mut runner).unwrap().current();
        let mesh = mesh_of(&tris);
        let brute = build(AccelKind::Brute, &mesh);
        for p in lattice_probes(&rays) {
            cast += Cast { rays: 1, hits: brute.intersect(&mesh, &p.ray, p.t_max).is_some() as usize };
        }
    }
    cast.require("lattice soups", 192, FLOOR_LATTICE);
}

// ---------------------------------------------------------------------------------------------------
// Builder variants that the defaults above never reach: `build` uses each kind's default parameters,
// and the default bottom-up build picks the greedy method (area cost) for every set under 2,000
// primitives, so PLOC, the other merge costs and one-primitive leaves are checked here, on the
// adversarial families.

/// Non-default parameter sets, as `--accel-param` would give them.
const VARIANTS: &[(AccelKind, &[&str])] = &[
    (AccelKind::BvhBottomUp, &["method=ploc"]),
    (AccelKind::BvhBottomUp, &["method=ploc", "radius=1", "leaf=1"]),
    (AccelKind::BvhBottomUp, &["method=greedy", "cost=distance"]),
    (AccelKind::BvhBottomUp, &["method=greedy", "cost=volume", "leaf=1"]),
    (AccelKind::BvhMedian, &["leaf=1"]),
];
const VARIANT_RAYS: usize = 10_000;

/// [`check`] for every entry of [`VARIANTS`] (built from an `AccelConfig`, then validated).
fn check_variants(case: &str, tris: &[[Vec3; 3]], rng: &mut Rng) -> Cast {
    use arbor::accel::AccelConfig;
    let mesh = mesh_of(tris);
    let probes = Targets::of(&mesh, &tris.concat()).probes(rng, VARIANT_RAYS);
    let brute = build(AccelKind::Brute, &mesh);
    for &(kind, params) in VARIANTS {
        let config = AccelConfig::from(kind).with_pairs(params.iter().copied()).unwrap();
        let accel = config.build_accel(&mesh).unwrap();
        accel.validate(&mesh).unwrap_or_else(|e| panic!("{kind} {params:?} on {case}: invalid structure: {e}"));
        for p in &probes {
            let (got, want) = (accel.intersect(&mesh, &p.ray, p.t_max), brute.intersect(&mesh, &p.ray, p.t_max));
            assert!(same_hit(got, want), "{kind} {params:?} on {case}: {p:?} hit {got:?}, brute force {want:?}");
            let (got, want) = (accel.occluded(&mesh, &p.ray, p.t_max), brute.occluded(&mesh, &p.ray, p.t_max));
            assert_eq!(got, want, "{kind} {params:?} on {case}: occluded {p:?}");
        }
    }
    let hits = probes.iter().filter(|p| brute.intersect(&mesh, &p.ray, p.t_max).is_some()).count();
    Cast { rays: probes.len(), hits }
}

#[test]
fn bvh_variants_match_brute_force_on_adversarial_sets() {
    let mut rng = Rng::new(1100);
    let soup = random_soup(&mut rng, 500, 20.0, 2.0);
    let mut cast = check_variants("soup", &soup, &mut rng);
    let offset: Vec<_> = soup.iter().map(|t| t.map(|p| p + Vec3::splat(1e5))).collect();
    cast += check_variants("soup offset by 1e5", &offset, &mut rng);
    cast += check_variants("grid", &grid(6, 4), &mut rng);
    cast += check_variants("closed cube", &closed_cube(8), &mut rng);
    // Duplicates at random indices and coplanar overlaps: ties at equal t across leaves.
    let mut dups = random_soup(&mut rng, 60, 6.0, 2.0);
    for _ in 0..200 {
        let t = rng.pick(&dups);
        dups.insert(rng.below(dups.len() + 1), t);
    }
    dups.extend((0..80).map(|_| {
        let c = rng.vec3() * 6.0;
        [0; 3].map(|_| (c + (rng.vec3() - 0.5) * 3.0).with_z(1.0))
    }));
    cast += check_variants("duplicates", &dups, &mut rng);
    // Points, lines, non-finite and huge triangles among good ones.
    let mut bad = random_soup(&mut rng, 100, 8.0, 2.0);
    for _ in 0..150 {
        let (a, b) = (rng.vec3() * 8.0, rng.vec3() * 8.0);
        let nan = Vec3::new(f32::NAN, a.y, a.z);
        bad.push(rng.pick(&[[a; 3], [a, 0.5 * (a + b), b], [a, b, nan], [a, Vec3::splat(-1e30), Vec3::splat(1e30)]]));
    }
    cast += check_variants("degenerates", &bad, &mut rng);
    // Gaps growing fourfold: clustering builds one chain as long as the input, which the builder must
    // rebalance to fit the traversal stack.
    let chain: Vec<_> = (0..64)
        .flat_map(|i| [1.0f32, -1.0].map(|s| s * 4f32.powi(i)))
        .map(|x| [Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0)])
        .collect();
    cast += check_variants("chain", &chain, &mut rng);
    cast.require("builder variants", 7 * VARIANT_RAYS, FLOOR_VARIANTS);
}

// Octree cell faces: the generic cases rarely put geometry or rays exactly on the planes where the
// octree cuts its cells, so here triangles lie in those planes (some duplicated: ties across cells),
// along the lines where they cross, and rays run inside them, along their crossings, through cell
// corners, and from far away (the traversal's slack and the build's margin are relative to the scene).

const OCTREE_FACE_RAYS: usize = 4 * 25_000;

/// The faces of the octree's cells down to depth 3 over `mesh`, per axis (exact `f32` coordinates).
fn octree_faces(mesh: &TriangleMesh) -> (Aabb, [Vec<f32>; 3]) {
    let tree =
        arbor::accel::Octree::build(mesh, &arbor::accel::OctreeParams { max_leaf_prims: 1, ..Default::default() });
    let mut faces: [Vec<f32>; 3] = Default::default();
    for depth in 0..4 {
        for b in arbor::accel::Accel::<TriangleMesh>::boxes_at_depth(&tree, mesh, depth) {
            for (a, f) in faces.iter_mut().enumerate() {
                f.extend([b.min[a], b.max[a]]);
            }
        }
    }
    for f in &mut faces {
        f.sort_by(f32::total_cmp);
        f.dedup();
    }
    (tree.root(), faces)
}

#[test]
fn accel_matches_brute_force_on_octree_cell_faces() {
    let mut cast = Cast::default();
    for seed in 0..4 {
        let mut rng = Rng::new(900 + seed);
        let mut tris = random_soup(&mut rng, 200, 20.0, 2.0);
        let (root, faces) = octree_faces(&mesh_of(&tris));
        let bounds = mesh_of(&tris).positions.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p));
        // A point of the scene's bounds with coordinates snapped to faces on the axes of `on`.
        let snapped = |rng: &mut Rng, on: &[usize]| {
            let mut p = rng.in_box(&bounds);
            for &a in on {
                p[a] = rng.pick(&faces[a]).clamp(bounds.min[a], bounds.max[a]);
            }
            p
        };
        for i in 0..150 {
            let a = rng.below(3);
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let mut t = [snapped(&mut rng, &[a]), rng.in_box(&bounds), rng.in_box(&bounds)];
            t[1][a] = t[0][a];
            t[2][a] = t[0][a];
            if i % 3 == 0 {
                // An edge along the crossing of two face planes.
                t[1][b] = t[0][b];
                t[1][c] = rng.in_box(&bounds)[c];
                t[0][b] = rng.pick(&faces[b]).clamp(bounds.min[b], bounds.max[b]);
                t[1][b] = t[0][b];
            }
            tris.push(t);
            if i % 5 == 0 {
                tris.push(t); // a tie, possibly decided in another cell than the first copy's
            }
        }
        let mesh = mesh_of(&tris);
        let (root_after, _) = octree_faces(&mesh);
        assert_eq!(root, root_after, "the added triangles lie inside the first ones' bounds");
        let vertices: Vec<Vec3> = tris.iter().flatten().copied().collect();
        let targets = Targets::of(&mesh, &vertices);
        let mut probes = targets.probes(&mut rng, 10_000);
        for k in 0..15_000 {
            let a = rng.below(3);
            let (origin, dir) = match k % 5 {
                // Inside a face plane, in any direction within it.
                0 => {
                    let mut d = rng.vec3() - 0.5;
                    d[a] = if rng.below(2) == 0 { 0.0 } else { -0.0 };
                    (snapped(&mut rng, &[a]), d)
                }
                // Along the crossing of two face planes.
                1 => {
                    let o = snapped(&mut rng, &[(a + 1) % 3, (a + 2) % 3]);
                    (o, signed_axis(&mut rng, a))
                }
                // Through a cell corner.
                2 => {
                    let o = rng.in_box(&targets.around());
                    (o, snapped(&mut rng, &[0, 1, 2]) - o)
                }
                // From far away (10 and 1000 scene sizes) at a vertex.
                _ => {
                    let far = if k % 5 == 3 { 10.0 } else { 1000.0 };
                    let o = root.center() + (rng.vec3() - 0.5) * far * root.extent();
                    (o, rng.pick(&vertices) - o)
                }
            };
            probes.push(Probe { ray: Ray::new(origin, dir), t_max: f32::INFINITY });
        }
        cast += check("octree cell faces", &mesh, &probes);
    }
    cast.require("octree cell faces", OCTREE_FACE_RAYS, FLOOR_OCTREE_FACES);
}
