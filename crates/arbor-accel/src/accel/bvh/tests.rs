//! Unit tests of the SAH BVH: hostile inputs, determinism, structure. Equality with brute force on
//! many rays is the job of `tests/accel_conformance.rs`.

use super::*;
use crate::accel::{build, AccelKind, BruteForce, PrimHit};
use crate::geometry::TriangleMesh;

pub(super) use crate::test_rng::Rng;

pub(super) fn soup(n: usize, seed: u64) -> TriangleMesh {
    let mut rng = Rng(seed);
    let mut mesh = TriangleMesh::default();
    for i in 0..n {
        let c = rng.vec3() * 10.0;
        for _ in 0..3 {
            mesh.positions.push(c + rng.vec3() - 0.5);
        }
        let k = 3 * i as u32;
        mesh.indices.push([k, k + 1, k + 2]);
    }
    mesh
}

pub(super) fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    (0..n).map(|_| Ray::new(rng.vec3() * 14.0 - 2.0, rng.vec3() - 0.5)).collect()
}

/// A hit as bits, to compare hits bit for bit (`-0.0` is not `0.0`).
pub(super) fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32, u32)> {
    h.map(|h| (h.prim, h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.sub))
}

pub(super) fn assert_matches_brute(mesh: &TriangleMesh, bvh: &Bvh, rays: &[Ray]) {
    let brute = BruteForce::build(mesh);
    for ray in rays {
        let (a, b) = (bvh.intersect(mesh, ray, f32::INFINITY), brute.intersect(mesh, ray, f32::INFINITY));
        assert_eq!(bits(a), bits(b), "ray {ray:?}: {a:?}, brute force {b:?}");
        assert_eq!(bvh.occluded(mesh, ray, 5.0), brute.occluded(mesh, ray, 5.0));
    }
}

#[test]
fn bvh_empty_set_hits_nothing() {
    let mesh = TriangleMesh::default();
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    bvh.validate(&mesh).unwrap();
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(bvh.intersect(&mesh, &ray, f32::INFINITY), None);
    assert!(!bvh.occluded(&mesh, &ray, f32::INFINITY));
    assert!(Accel::<TriangleMesh>::bounds(&bvh).is_empty());
    assert_eq!(Accel::<TriangleMesh>::stats(&bvh).nodes, 0);
}

#[test]
fn bvh_single_primitive_is_one_leaf() {
    let mesh = soup(1, 7);
    let bvh = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
    bvh.validate(&mesh).unwrap();
    assert_eq!(bvh.nodes().len(), 1);
    assert!(bvh.nodes()[0].is_leaf());
    let [a, b, c] = mesh.triangle(0);
    let target = (a + b + c) / 3.0;
    let ray = Ray::new(target + Vec3::new(0.0, 0.0, 20.0), Vec3::new(0.0, 0.0, -1.0));
    let ray = Ray::new(ray.origin, target - ray.origin);
    assert_eq!(bvh.intersect(&mesh, &ray, f32::INFINITY).map(|h| h.prim), Some(0));
}

#[test]
fn bvh_matches_brute_force_on_small_soup() {
    for (n, params) in [(200, BvhParams::default()), (300, BvhParams::fast_build()), (500, BvhParams::quality())] {
        let mesh = soup(n, n as u64);
        let bvh = Bvh::build_sah(&mesh, &params);
        bvh.validate(&mesh).unwrap();
        assert_matches_brute(&mesh, &bvh, &rays(2000, 3));
    }
}

#[test]
fn bvh_duplicates_at_one_point_keep_leaves_bounded() {
    let mut mesh = soup(1, 1);
    mesh.indices = vec![[0, 1, 2]; 1000];
    let bvh = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
    bvh.validate(&mesh).unwrap();
    assert!(bvh.nodes().iter().all(|n| (n.count as usize) <= LEAF_HARD_MAX));
    // Every copy is hit at the same t; the lowest index wins.
    let [a, b, c] = mesh.triangle(0);
    let ray = Ray::new(Vec3::splat(-5.0), (a + b + c) / 3.0 - Vec3::splat(-5.0));
    assert_eq!(bvh.intersect(&mesh, &ray, f32::INFINITY).map(|h| h.prim), Some(0));
}

#[test]
fn bvh_ties_between_leaves_go_to_the_lowest_index() {
    // The same triangle at indices 0 and n-1, with a soup between them so that they land in
    // different leaves; rays through it must report index 0 whatever the visiting order.
    let mut mesh = soup(500, 11);
    let first = mesh.indices[0];
    mesh.indices.push(first);
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    assert_matches_brute(&mesh, &bvh, &rays(3000, 5));
    let [a, b, c] = mesh.triangle(0);
    for o in [Vec3::splat(-3.0), Vec3::splat(13.0), Vec3::new(13.0, -3.0, 5.0)] {
        let ray = Ray::new(o, (a + b + c) / 3.0 - o);
        let hit = bvh.intersect(&mesh, &ray, f32::INFINITY);
        assert_eq!(hit, BruteForce::build(&mesh).intersect(&mesh, &ray, f32::INFINITY));
    }
}

#[test]
fn bvh_non_finite_primitives_stay_out_of_the_tree() {
    let mut mesh = soup(100, 2);
    let nan = mesh.positions.len() as u32;
    mesh.positions.push(Vec3::new(f32::NAN, 0.0, 0.0));
    mesh.positions.push(Vec3::new(f32::INFINITY, 1.0, 1.0));
    mesh.positions.push(Vec3::new(f32::NEG_INFINITY, f32::NAN, 1.0));
    mesh.indices.push([nan, nan + 1, nan + 2]);
    mesh.indices.push([nan + 1, nan + 2, 0]);
    mesh.indices.push([0, nan + 1, 1]);
    let bvh = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
    bvh.validate(&mesh).unwrap();
    let root = bvh.nodes()[0].bounds();
    assert!(root.min.is_finite() && root.max.is_finite());
    assert_matches_brute(&mesh, &bvh, &rays(2000, 9));
}

#[test]
fn bvh_flat_and_degenerate_triangles_are_handled() {
    let mut mesh = soup(200, 4);
    for i in 0..50 {
        let p = Vec3::new(i as f32 * 0.1, 1.0, 2.0);
        let k = mesh.positions.len() as u32;
        mesh.positions.extend([p, p, p + Vec3::X]);
        mesh.indices.push([k, k + 1, k + 2]);
        mesh.indices.push([k, k, k]);
    }
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    bvh.validate(&mesh).unwrap();
    assert_matches_brute(&mesh, &bvh, &rays(2000, 8));
}

/// `n` parallel triangles at x = 0.93^i: each binned split can peel off only the few largest.
fn exponentially_spaced(n: i32) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for i in 0..n {
        let x = 0.93f32.powi(i);
        let k = mesh.positions.len() as u32;
        mesh.positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0)]);
        mesh.indices.push([k, k + 1, k + 2]);
    }
    mesh
}

#[test]
fn bvh_depth_is_bounded_on_exponentially_spaced_centroids() {
    // Each binned split peels off only the few largest centroids: without the depth limit the tree
    // would be hundreds of levels deep.
    let mesh = exponentially_spaced(2000);
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    bvh.validate(&mesh).unwrap();
    let stats = Accel::<TriangleMesh>::stats(&bvh);
    assert!(stats.max_depth < MAX_DEPTH, "{stats:?}");
    let ray = Ray::new(Vec3::new(2.0, 0.2, 0.2), -Vec3::X);
    let hit = bvh.intersect(&mesh, &ray, f32::INFINITY);
    assert_eq!(hit, BruteForce::build(&mesh).intersect(&mesh, &ray, f32::INFINITY));
}

#[test]
fn bvh_build_is_identical_for_any_thread_count() {
    let mut mesh = soup(50_000, 12);
    // Triangles that cannot be hit, spread over the setup pass's chunks, which then close the gaps.
    for t in (7..50_000).step_by(4999) {
        mesh.positions[3 * t] = Vec3::INFINITY;
    }
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep))
    };
    let (one, four) = (on(1), on(4));
    one.validate(&mesh).unwrap();
    assert_eq!(one.prim_indices()[one.live..], (7..50_000).step_by(4999).map(|t| t as u32).collect::<Vec<_>>());
    assert_eq!(one.nodes(), four.nodes());
    assert_eq!(one.prim_indices(), four.prim_indices());
    // The collapse too: large enough that the wide tree's top is planned in parallel.
    assert!(one.nodes().len() >= 2 * wide::PLAN_PARALLEL, "{}", one.nodes().len());
    let (w1, w4) = (one.wide(), four.wide());
    assert_eq!(w1.nodes().len(), w4.nodes().len());
    for (a, b) in w1.nodes().iter().zip(w4.nodes()) {
        assert!(a.min == b.min && a.max == b.max && a.child == b.child && a.count == b.count);
    }
    assert_eq!(w1.blocks().len(), w4.blocks().len());
    for (a, b) in w1.blocks().iter().zip(w4.blocks()) {
        assert!(a.tris.v == b.tris.v && a.prim == b.prim);
    }
}

#[test]
fn bvh_nan_and_zero_rays_hit_nothing() {
    let mesh = soup(100, 3);
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    for ray in [
        Ray::new(Vec3::new(f32::NAN, 1.0, 1.0), Vec3::X),
        Ray::new(Vec3::splat(5.0), Vec3::new(f32::NAN, 0.0, 1.0)),
        Ray::new(Vec3::splat(5.0), Vec3::new(f32::INFINITY, 0.0, 1.0)),
        Ray::new(Vec3::splat(5.0), Vec3::ZERO),
    ] {
        assert_eq!(bvh.intersect(&mesh, &ray, f32::INFINITY), None);
        assert!(!bvh.occluded(&mesh, &ray, f32::INFINITY));
    }
    let ray = Ray::new(Vec3::splat(-1.0), Vec3::ONE);
    assert_eq!(bvh.intersect(&mesh, &ray, f32::NAN), None);
    assert_eq!(bvh.intersect(&mesh, &ray, -1.0), None);
}

#[test]
fn bvh_stats_describe_the_tree() {
    let mesh = soup(10_000, 6);
    let bvh = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
    let s = Accel::<TriangleMesh>::stats(&bvh);
    assert_eq!(s.kind, "bvh-sah");
    assert_eq!(s.primitives, 10_000);
    assert_eq!(s.nodes, 2 * s.leaves - 1);
    assert!(s.mean_leaf_prims >= 1.0 && s.mean_leaf_prims <= 8.0, "{s:?}");
    assert!(s.sah_cost > 1.0 && s.sah_cost < 10_000.0, "{s:?}");
    // Binary nodes and indices, the 8-wide nodes, and the blocks of four triangles.
    let wide = 256 * bvh.wide.nodes().len() + 160 * bvh.wide.blocks().len();
    assert_eq!(s.bytes, std::mem::size_of::<Bvh>() + 32 * s.nodes + 4 * 10_000 + wide);
}

#[test]
fn mesh_bvh_drops_its_binary_tree_and_indices_and_nothing_else_changes() {
    let mesh = soup(10_000, 6);
    let opaque = Opaque(&mesh);
    let rays = rays(2000, 8);
    for (kept, dropped) in [
        (Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep), Bvh::build_sah(&mesh, &BvhParams::default())),
        (
            Bvh::median(&mesh, &MedianParams::default(), Binary::Keep),
            Bvh::build_median(&mesh, &MedianParams::default()),
        ),
        (
            Bvh::bottom_up(&mesh, &BottomUpParams::default(), Binary::Keep),
            Bvh::build_bottom_up(&mesh, &BottomUpParams::default()),
        ),
    ] {
        assert!(!kept.binary_dropped() && dropped.binary_dropped());
        assert!(dropped.nodes().is_empty() && dropped.prim_indices().is_empty());
        let (k, d) = (Accel::<TriangleMesh>::stats(&kept), Accel::<TriangleMesh>::stats(&dropped));
        let freed = std::mem::size_of_val(kept.nodes()) + std::mem::size_of_val(kept.prim_indices());
        assert_eq!(d.bytes, k.bytes - freed, "{}", k.kind);
        assert_eq!(
            AccelStats { bytes: 0, build_time: Duration::ZERO, ..d },
            AccelStats { bytes: 0, build_time: Duration::ZERO, ..k }
        );
        assert_eq!(Accel::<TriangleMesh>::bounds(&dropped), Accel::<TriangleMesh>::bounds(&kept));
        dropped.validate(&mesh).unwrap();
        for ray in &rays {
            assert_eq!(bits(dropped.intersect(&mesh, ray, 30.0)), bits(kept.intersect(&mesh, ray, 30.0)));
            assert_eq!(dropped.occluded(&mesh, ray, 4.0), kept.occluded(&mesh, ray, 4.0));
        }
        let mut out = vec![None; rays.len()];
        dropped.intersect_many(&mesh, &rays, &vec![30.0; rays.len()], &mut out);
        let each: Vec<_> = rays.iter().map(|r| kept.intersect(&mesh, r, 30.0)).collect();
        assert_eq!(out.into_iter().map(bits).collect::<Vec<_>>(), each.into_iter().map(bits).collect::<Vec<_>>());
        // The boxes view shows the binary tree, built again once dropped: the same boxes at every depth.
        for depth in 0..=k.max_depth + 1 {
            let boxes = Accel::<TriangleMesh>::boxes_at_depth(&dropped, &mesh, depth);
            assert_eq!(boxes, Accel::<TriangleMesh>::boxes_at_depth(&kept, &mesh, depth), "{} depth {depth}", k.kind);
            assert_eq!(boxes.is_empty(), depth > k.max_depth, "{} depth {depth}", k.kind);
        }
    }
    // Other primitives keep the index array their leaves read.
    let generic = Bvh::build_sah(&opaque, &BvhParams::default());
    assert!(!generic.binary_dropped() && generic.prim_indices().len() == 10_000);
}

#[test]
fn validate_checks_the_wide_tree_of_a_mesh_bvh_without_its_binary_tree() {
    let mesh = soup(2000, 9);
    let good = Bvh::build_sah(&mesh, &BvhParams::default());
    good.validate(&mesh).unwrap();
    assert!(good.validate(&soup(1999, 9)).is_err());
    let mut swapped = good.clone();
    let blocks = swapped.wide.blocks_mut();
    let (a, b) = (blocks[0].prim[0], blocks[blocks.len() - 1].prim[0]);
    blocks[0].prim[0] = b;
    blocks.last_mut().unwrap().prim[0] = a;
    assert!(swapped.validate(&mesh).is_err(), "primitives swapped between far apart leaves");
    let mut moved = good.clone();
    moved.wide.blocks_mut()[0].tris.v[0][0][0] += 1.0;
    assert!(moved.validate(&mesh).is_err(), "a corner that is not the mesh's");
}

#[test]
fn bvh_params_are_clamped() {
    let mesh = soup(1000, 10);
    let wild = BvhParams {
        max_leaf_prims: 100_000,
        bins: 0,
        traversal_cost: f32::NAN,
        intersection_cost: -1.0,
        leaf_block: 0,
    };
    let bvh = Bvh::build_sah(&mesh, &wild);
    bvh.validate(&mesh).unwrap();
    assert_matches_brute(&mesh, &bvh, &rays(500, 1));
}

#[test]
fn bvh_factory_builds_a_bvh() {
    let mesh = soup(100, 5);
    let accel = build(AccelKind::BvhSah, &mesh);
    assert_eq!(accel.stats().kind, "bvh-sah");
}

/// Runs `f` on a pool of `threads` threads.
pub(super) fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

/// SAH cost of `bvh` (stats' convention: traversal and intersection cost 1).
pub(super) fn sah(bvh: &Bvh) -> f64 {
    Accel::<TriangleMesh>::stats(bvh).sah_cost
}

// ---------------------------------------------------------------------------------------------------
// Median split

#[test]
fn median_matches_brute_force_on_small_soup() {
    for (n, leaf) in [(1, 8), (2, 1), (200, 8), (300, 1), (500, 64)] {
        let mesh = soup(n, n as u64 + 40);
        let bvh = Bvh::build_median(&mesh, &MedianParams { max_leaf_prims: leaf });
        bvh.validate(&mesh).unwrap();
        assert_matches_brute(&mesh, &bvh, &rays(2000, 3));
    }
}

#[test]
fn median_tree_is_balanced_with_bounded_leaves() {
    let mesh = soup(10_000, 41);
    let bvh = Bvh::median(&mesh, &MedianParams { max_leaf_prims: 5 }, Binary::Keep);
    let s = Accel::<TriangleMesh>::stats(&bvh);
    assert_eq!(s.kind, "bvh-median");
    // 10,000 halved until at most 5: every leaf at depth 11 (10,000 / 2^11 is 4.9), 3 to 5 primitives.
    assert_eq!((s.max_depth, s.mean_depth), (11, 11.0), "{s:?}");
    assert!(bvh.nodes().iter().filter(|n| n.is_leaf()).all(|n| (3..=5).contains(&n.count)));
}

#[test]
fn median_splits_coincident_centroids_by_index() {
    // 1,000 copies of one triangle: selection by (centroid, index) still halves them.
    let mut mesh = soup(1, 1);
    mesh.indices = vec![[0, 1, 2]; 1000];
    let bvh = Bvh::build_median(&mesh, &MedianParams::default());
    bvh.validate(&mesh).unwrap();
    assert_eq!(Accel::<TriangleMesh>::stats(&bvh).max_depth, 7);
    assert_matches_brute(&mesh, &bvh, &rays(500, 2));
}

#[test]
fn median_build_is_identical_for_any_thread_count() {
    let mesh = soup(20_000, 42);
    let build = || Bvh::median(&mesh, &MedianParams::default(), Binary::Keep);
    let (one, four) = (on_threads(1, build), on_threads(4, build));
    assert_eq!(one.nodes(), four.nodes());
    assert_eq!(one.prim_indices(), four.prim_indices());
}

#[test]
fn median_depth_is_logarithmic_on_exponentially_spaced_centroids() {
    let mesh = exponentially_spaced(2000);
    let bvh = Bvh::build_median(&mesh, &MedianParams::default());
    bvh.validate(&mesh).unwrap();
    assert!(Accel::<TriangleMesh>::stats(&bvh).max_depth <= 11);
}

#[test]
fn median_sah_cost_is_within_a_sane_factor_of_binned_sah() {
    let mesh = soup(20_000, 43);
    let (median, binned) =
        (Bvh::build_median(&mesh, &MedianParams::default()), Bvh::build_sah(&mesh, &BvhParams::default()));
    assert!(sah(&median) < 2.0 * sah(&binned), "median {} binned {}", sah(&median), sah(&binned));
}

/// Primitives that are not a mesh, so the wide tree asks them through `Primitives` (no triangle copy).
pub(super) struct Opaque<'a>(pub(super) &'a TriangleMesh);

impl Primitives for Opaque<'_> {
    fn len(&self) -> usize {
        Primitives::len(self.0)
    }
    fn bounds(&self, i: usize) -> Aabb {
        Primitives::bounds(self.0, i)
    }
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<crate::accel::PrimHit> {
        Primitives::intersect(self.0, i, ray, t_max)
    }
}

#[test]
fn bvh_wide_traversal_matches_binary_traversal_with_and_without_triangle_copy() {
    let mesh = soup(3000, 17);
    let opaque = Opaque(&mesh);
    let with_copy = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
    let without = Bvh::build_sah(&opaque, &BvhParams::default());
    assert!(with_copy.wide.bytes() > without.wide.bytes(), "a mesh gets its triangles copied in leaf order");
    for ray in rays(2000, 5) {
        let mut c = TraversalCounts::default();
        let binary =
            traverse::intersect::<_, false>(&with_copy.nodes, &with_copy.prim_indices, &mesh, &ray, 30.0, &mut c);
        assert_eq!(with_copy.intersect(&mesh, &ray, 30.0), binary, "{ray:?}");
        assert_eq!(without.intersect(&opaque, &ray, 30.0), binary, "{ray:?}");
        let occ = traverse::occluded(&with_copy.nodes, &with_copy.prim_indices, &mesh, &ray, 4.0);
        assert_eq!(with_copy.occluded(&mesh, &ray, 4.0), occ);
        assert_eq!(without.occluded(&opaque, &ray, 4.0), occ);
    }
}

/// The node-test kernels this processor runs, scalar first.
pub(super) fn kernels() -> Vec<super::wide::Kernel> {
    use super::wide::Kernel;
    #[allow(unused_mut)] // only x86_64 has more than the scalar kernel
    let mut kernels = vec![Kernel::Scalar];
    #[cfg(target_arch = "x86_64")]
    {
        kernels.push(Kernel::Sse);
        kernels.extend(super::wide::Avx2::detect().map(Kernel::Avx2));
        kernels.extend(super::wide::Avx512::detect().map(Kernel::Avx512));
    }
    kernels
}

#[test]
fn bvh_wide_kernels_visit_the_same_nodes_and_return_the_same_hits() {
    use super::wide::{intersect_with, occluded_with, Kernel};
    let mesh = soup(5000, 29);
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    let kernels = kernels();
    let (mut hits, mut occluded) = (0, 0);
    for ray in rays(3000, 8) {
        let run = |k: Kernel| {
            let mut c = TraversalCounts::default();
            let hit = intersect_with::<_, true>(k, &bvh.wide, &bvh.prim_indices, &mesh, &ray, 30.0, &mut c);
            let occ = occluded_with(k, &bvh.wide, &bvh.prim_indices, &mesh, &ray, 4.0);
            (hit.map(|h| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits())), occ, c.nodes, c.prims)
        };
        let scalar = run(Kernel::Scalar);
        hits += scalar.0.is_some() as usize;
        occluded += scalar.1 as usize;
        for &k in &kernels[1..] {
            assert_eq!(run(k), scalar, "{k:?} {ray:?}");
        }
    }
    assert!(hits > 300 && occluded > 100, "the rays must hit: {hits} closest hits, {occluded} occluded of 3000");
}

#[test]
fn bvh_batches_give_every_ray_its_own_querys_hit_with_every_kernel_and_leaf_kind() {
    use super::wide::{intersect_many_with, occluded_many_with};
    let mesh = soup(4000, 41);
    let opaque = Opaque(&mesh);
    let with_copy = Bvh::build_sah(&mesh, &BvhParams::default());
    let without = Bvh::build_sah(&opaque, &BvhParams::default());
    let kernels = kernels();
    // Random rays with rays that trivially miss mixed in (NaN origin, zero direction, t_max of zero,
    // negative or NaN), so that slots are refilled past them, and short t_max that end rays early.
    let mut batch: Vec<(Ray, f32)> = rays(1500, 3).into_iter().map(|r| (r, 30.0)).collect();
    for k in (0..batch.len()).step_by(7) {
        batch[k] = match k % 5 {
            0 => (Ray::new(Vec3::NAN, Vec3::X), 30.0),
            1 => (Ray::new(Vec3::ZERO, Vec3::ZERO), 30.0),
            2 => (batch[k].0, 0.0),
            3 => (batch[k].0, f32::NAN),
            _ => (batch[k].0, 0.5),
        };
    }
    batch.push((batch[1].0, -1.0));
    let (rays, t_max): (Vec<Ray>, Vec<f32>) = batch.iter().copied().unzip();
    let single: Vec<Option<Hit>> = batch.iter().map(|(r, t)| with_copy.intersect(&mesh, r, *t)).collect();
    assert!(single.iter().filter(|h| h.is_some()).count() > 300, "the rays must hit");
    let blocked: Vec<bool> = batch.iter().map(|(r, t)| with_copy.occluded(&mesh, r, *t)).collect();
    assert!(blocked.iter().filter(|&&b| !b).count() > 300, "some rays must get through");
    for &k in &kernels {
        // Every batch size up to 5 (one or both slots, refilled or not), then the rest at once.
        for n in (0..=5).chain([rays.len()]) {
            let mut out = vec![Some(Hit::new(u32::MAX, PrimHit::new(1.0, 0.0, 0.0))); n];
            intersect_many_with(k, &with_copy.wide, &with_copy.prim_indices, &mesh, &rays[..n], &t_max[..n], &mut out);
            assert_eq!(out, single[..n], "{k:?} mesh leaves, batch of {n}");
            let mut out = vec![None; n];
            intersect_many_with(k, &without.wide, &without.prim_indices, &opaque, &rays[..n], &t_max[..n], &mut out);
            assert_eq!(out, single[..n], "{k:?} primitive leaves, batch of {n}");
            let mut any = vec![true; n];
            occluded_many_with(k, &with_copy.wide, &with_copy.prim_indices, &mesh, &rays[..n], &t_max[..n], &mut any);
            assert_eq!(any, blocked[..n], "{k:?} mesh leaves, any-hit batch of {n}");
            let mut any = vec![true; n];
            occluded_many_with(k, &without.wide, &without.prim_indices, &opaque, &rays[..n], &t_max[..n], &mut any);
            assert_eq!(any, blocked[..n], "{k:?} primitive leaves, any-hit batch of {n}");
        }
    }
    // Through the trait, and on an empty tree.
    let mut out = vec![None; rays.len()];
    with_copy.intersect_many(&mesh, &rays, &t_max, &mut out);
    assert_eq!(out, single);
    let mut any = vec![true; rays.len()];
    with_copy.occluded_many(&mesh, &rays, &t_max, &mut any);
    assert_eq!(any, blocked);
    let empty = TriangleMesh::default();
    let bvh = Bvh::build_sah(&empty, &BvhParams::default());
    let mut out = vec![Some(Hit::new(0, PrimHit::new(1.0, 0.0, 0.0))); 3];
    bvh.intersect_many(&empty, &rays[..3], &t_max[..3], &mut out);
    assert_eq!(out, [None, None, None]);
    let mut any = [true; 3];
    bvh.occluded_many(&empty, &rays[..3], &t_max[..3], &mut any);
    assert_eq!(any, [false; 3]);
}

#[test]
#[should_panic(expected = "differ in length")]
fn bvh_batch_of_mismatched_lengths_panics() {
    let mesh = soup(10, 1);
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    bvh.intersect_many(&mesh, &rays(3, 1), &[1.0; 2], &mut [None; 3]);
}

#[test]
fn bvh_wide_leaf_blocks_hold_every_triangle_once_inside_their_lane_box_and_use_free_lanes() {
    let mesh = soup(3000, 41);
    let bvh = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
    let (nodes, blocks) = (bvh.wide.nodes(), bvh.wide.blocks());
    let mut seen = vec![0u32; mesh.len()];
    let mut leaf_lanes = 0;
    for node in nodes {
        for lane in 0..super::wide::WIDTH {
            let count = node.count[lane] as usize;
            if count == 0 {
                continue;
            }
            leaf_lanes += 1;
            let lo = Vec3::new(node.min[0][lane], node.min[1][lane], node.min[2][lane]);
            let hi = Vec3::new(node.max[0][lane], node.max[1][lane], node.max[2][lane]);
            let first = node.child[lane] as usize;
            for (k, block) in blocks[first..first + count.div_ceil(4)].iter().enumerate() {
                for l in 0..(count - 4 * k).min(4) {
                    seen[block.prim[l] as usize] += 1;
                    for p in block.tris.lane(l) {
                        assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{p:?} outside lane box {lo:?}..{hi:?}");
                    }
                }
            }
        }
    }
    assert!(seen.iter().all(|&n| n == 1), "every triangle in exactly one block lane");
    let binary_leaves = bvh.nodes.iter().filter(|n| n.is_leaf()).count();
    assert!(leaf_lanes > binary_leaves, "leaves of two blocks split over free lanes: {leaf_lanes} vs {binary_leaves}");
}

/// The scalar paths of every query, small enough for Miri (`.ci/miri` runs exactly the tests whose name
/// holds `scalar_path`): the wide traversal with the scalar node test and with the SSE one (Miri runs
/// SSE2 intrinsics, so it checks that kernel's raw loads too; not AVX2's) in every query (closest hit,
/// batch, any hit) and kind of leaf, the binary traversal, and every structure through the factory, all
/// against brute force bit for bit. Under Miri the four-triangle test is its scalar loop and
/// `Kernel::detect` gives the scalar kernel; natively, the tests above compare all kernels.
mod scalar_path {
    use super::*;
    use crate::accel::bvh::wide::{intersect_many_with, intersect_with, occluded_many_with, occluded_with, Kernel};

    /// Enough triangles for a wide tree of two levels (leaves of up to 8, 8 children per node).
    const TRIS: usize = if cfg!(miri) { 150 } else { 1500 };
    const RAYS: usize = if cfg!(miri) { 40 } else { 2000 };

    /// Rays from around the soup aimed at its triangles' centres, so most of them hit something.
    fn aimed_rays(mesh: &TriangleMesh, n: usize, seed: u64) -> Vec<Ray> {
        let mut rng = Rng(seed);
        (0..n)
            .map(|_| {
                let origin = rng.vec3() * 14.0 - 2.0;
                let [a, b, c] = mesh.triangle((rng.f32() * mesh.len() as f32) as usize % mesh.len());
                Ray::new(origin, (a + b + c) / 3.0 - origin)
            })
            .collect()
    }

    /// The node-test kernels Miri can run: all but AVX2 (whose intrinsics it does not implement).
    fn portable_kernels() -> Vec<Kernel> {
        #[allow(unused_mut)] // only x86_64 has the SSE kernel
        let mut kernels = vec![Kernel::Scalar];
        #[cfg(target_arch = "x86_64")]
        kernels.push(Kernel::Sse);
        kernels
    }

    #[test]
    fn bvh_scalar_path_and_sse_kernel_match_brute_force_in_every_query_and_leaf_kind() {
        let mesh = soup(TRIS, 61);
        let opaque = Opaque(&mesh);
        let brute = BruteForce::build(&mesh);
        let with_copy = Bvh::sah(&mesh, &BvhParams::default(), Binary::Keep);
        let without = Bvh::build_sah(&opaque, &BvhParams::default());
        assert!(with_copy.wide.nodes().len() > 1, "a tree of more than one wide node");
        let rays = aimed_rays(&mesh, RAYS, 13);
        let t_max: Vec<f32> = (0..RAYS).map(|i| if i % 4 == 0 { 3.0 } else { 30.0 }).collect();
        let want: Vec<_> = rays.iter().zip(&t_max).map(|(r, &t)| bits(brute.intersect(&mesh, r, t))).collect();
        let occluded: Vec<bool> = rays.iter().zip(&t_max).map(|(r, &t)| brute.occluded(&mesh, r, t)).collect();
        let hits = want.iter().filter(|h| h.is_some()).count();
        assert!(2 * hits >= RAYS, "the rays must hit: {hits} of {RAYS}");
        let mut c = TraversalCounts::default();
        for (k, (ray, &t)) in rays.iter().zip(&t_max).enumerate() {
            let binary =
                traverse::intersect::<_, false>(&with_copy.nodes, &with_copy.prim_indices, &mesh, ray, t, &mut c);
            assert_eq!(bits(binary), want[k], "binary traversal {ray:?}");
            let binary = traverse::occluded(&with_copy.nodes, &with_copy.prim_indices, &mesh, ray, t);
            assert_eq!(binary, occluded[k], "binary traversal {ray:?}");
        }
        for kernel in portable_kernels() {
            for (k, (ray, &t)) in rays.iter().zip(&t_max).enumerate() {
                let (w, i) = (&with_copy.wide, &with_copy.prim_indices);
                let got = intersect_with::<_, true>(kernel, w, i, &mesh, ray, t, &mut c);
                assert_eq!(bits(got), want[k], "{kernel:?} mesh leaves {ray:?}");
                assert_eq!(occluded_with(kernel, w, i, &mesh, ray, t), occluded[k], "{kernel:?} {ray:?}");
                let (w, i) = (&without.wide, &without.prim_indices);
                let got = intersect_with::<_, false>(kernel, w, i, &opaque, ray, t, &mut c);
                assert_eq!(bits(got), want[k], "{kernel:?} primitive leaves {ray:?}");
                assert_eq!(occluded_with(kernel, w, i, &opaque, ray, t), occluded[k], "{kernel:?} {ray:?}");
            }
            // Batches of 1 and 2 (one slot, both slots) and the rest (slots refilled), both leaf kinds.
            for n in [1, 2, RAYS] {
                let mut out = vec![None; n];
                let (w, i) = (&with_copy.wide, &with_copy.prim_indices);
                intersect_many_with(kernel, w, i, &mesh, &rays[..n], &t_max[..n], &mut out);
                assert_eq!(out.iter().map(|&h| bits(h)).collect::<Vec<_>>(), want[..n], "{kernel:?} batch of {n}");
                let (w, i) = (&without.wide, &without.prim_indices);
                intersect_many_with(kernel, w, i, &opaque, &rays[..n], &t_max[..n], &mut out);
                assert_eq!(out.iter().map(|&h| bits(h)).collect::<Vec<_>>(), want[..n], "{kernel:?} batch of {n}");
                let mut any = vec![false; n];
                occluded_many_with(kernel, w, i, &opaque, &rays[..n], &t_max[..n], &mut any);
                assert_eq!(any, occluded[..n], "{kernel:?} primitive leaves, any-hit batch of {n}");
                let (w, i) = (&with_copy.wide, &with_copy.prim_indices);
                occluded_many_with(kernel, w, i, &mesh, &rays[..n], &t_max[..n], &mut any);
                assert_eq!(any, occluded[..n], "{kernel:?} mesh leaves, any-hit batch of {n}");
            }
        }
    }

    /// Natively only: the other builders run parallel iterators, and rayon's work-stealing deques
    /// (crossbeam-epoch) break Miri's Stacked Borrows rules, which would end the run before our code.
    #[test]
    #[cfg_attr(miri, ignore = "rayon's crossbeam-epoch fails Stacked Borrows")]
    fn accel_scalar_path_every_structure_matches_brute_force() {
        let mesh = soup(TRIS / 3, 71);
        let brute = BruteForce::build(&mesh);
        let rays = aimed_rays(&mesh, RAYS / 2, 17);
        let hits = rays.iter().filter(|r| brute.intersect(&mesh, r, 30.0).is_some()).count();
        assert!(2 * hits >= rays.len(), "the rays must hit: {hits} of {}", rays.len());
        for &kind in AccelKind::ALL {
            let accel = build(kind, &mesh);
            for ray in &rays {
                let (got, want) = (accel.intersect(&mesh, ray, 30.0), brute.intersect(&mesh, ray, 30.0));
                assert_eq!(bits(got), bits(want), "{kind} {ray:?}");
                assert_eq!(accel.occluded(&mesh, ray, 3.0), brute.occluded(&mesh, ray, 3.0), "{kind} {ray:?}");
            }
        }
    }
}

#[test]
fn query_kernel_names_the_detected_kernel() {
    let names: Vec<&str> = kernels().into_iter().map(|k| k.name()).collect();
    assert_eq!(names[0], "scalar");
    #[cfg(all(target_arch = "x86_64", not(miri)))]
    {
        let avx2 = super::wide::Avx2::detect().is_some();
        let avx512 = super::wide::Avx512::detect().is_some();
        // A run under `ARBOR_MAX_ISA` gets the cap's kernel (the CLI's tests set it).
        let cap = super::Isa::cap_from_env().unwrap().unwrap_or(super::Isa::Avx512);
        let expected = if avx512 && cap >= super::Isa::Avx512 {
            "avx512"
        } else if avx2 && cap >= super::Isa::Avx2 {
            "avx2"
        } else {
            "sse"
        };
        assert_eq!(super::query_kernel(), expected);
        let mut runs = vec!["sse"];
        runs.extend(avx2.then_some("avx2"));
        runs.extend(avx512.then_some("avx512"));
        assert_eq!(&names[1..], runs);
    }
}
