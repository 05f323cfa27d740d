//! Unit tests of the bottom-up builders: merge order, tree quality against the binned SAH build,
//! determinism, the depth bound. Equality with brute force on many rays is the conformance suite's job.

use super::*;
use crate::accel::bvh::build::BuildPrim;
use crate::accel::bvh::tests::{assert_matches_brute, on_threads, rays, sah, soup};
use crate::accel::bvh::{Binary, Bvh, BvhParams, MAX_DEPTH, MAX_SAH_DEPTH};
use crate::accel::{Accel, AccelConfig, AccelKind};
use crate::geometry::TriangleMesh;
use crate::math::{Ray, Vec3};

fn prim(min: [f32; 3], max: [f32; 3], index: u32) -> BuildPrim {
    let bounds = Aabb::new(Vec3::from_array(min), Vec3::from_array(max));
    BuildPrim { bounds, centroid: bounds.center(), index }
}

fn with(method: BottomUpMethod, cost: MergeCost, leaf: usize) -> BottomUpParams {
    BottomUpParams { method, cost, max_leaf_prims: leaf, ..BottomUpParams::default() }
}

/// Height of an arena tree (leaves at 0), by one forward pass.
fn arena_height(arena: &[Cluster]) -> usize {
    let mut h = vec![0usize; arena.len()];
    for (i, c) in arena.iter().enumerate().filter(|(_, c)| !c.is_leaf()) {
        h[i] = 1 + h[c.kids[0] as usize].max(h[c.kids[1] as usize]);
    }
    h[arena.len() - 1]
}

#[test]
fn greedy_merges_the_least_pair_first_for_each_cost() {
    // 0, 1: flat squares 3 apart in one plane (merged volume 0). 2, 3: small cubes 0.6 apart (least
    // merged area). 4, 5: big cubes whose centres are 0.1 apart (least distance).
    let prims = [
        prim([0.0, 0.0, 0.0], [1.0, 1.0, 0.0], 0),
        prim([3.0, 0.0, 0.0], [4.0, 1.0, 0.0], 1),
        prim([10.0; 3], [10.5; 3], 2),
        prim([10.6, 10.0, 10.0], [11.1, 10.5, 10.5], 3),
        prim([20.0; 3], [26.0; 3], 4),
        prim([20.1, 20.0, 20.0], [26.1, 26.0, 26.0], 5),
    ];
    for (cost, pair) in [(MergeCost::Volume, [0, 1]), (MergeCost::Area, [2, 3]), (MergeCost::Distance, [4, 5])] {
        let arena = greedy::cluster(&prims, cost);
        assert_eq!(arena.len(), 11);
        assert_eq!(arena[6].kids, pair, "{cost:?}");
        assert_eq!(arena_height(&arena), 3, "{cost:?}");
    }
}

#[test]
fn ploc_merges_mutual_nearest_neighbours() {
    // Along a line: 0-1 and 2-3 are mutual nearest pairs by merged area, then the two pairs merge.
    let prims = [
        prim([0.0; 3], [1.0; 3], 0),
        prim([1.1, 0.0, 0.0], [2.1, 1.0, 1.0], 1),
        prim([5.0, 0.0, 0.0], [6.0, 1.0, 1.0], 2),
        prim([6.2, 0.0, 0.0], [7.2, 1.0, 1.0], 3),
    ];
    let arena = ploc::cluster(&prims, 16);
    assert_eq!(arena.iter().skip(4).map(|c| c.kids).collect::<Vec<_>>(), [[0, 1], [2, 3], [4, 5]]);
}

#[test]
fn bottom_up_matches_brute_force_for_each_method_and_cost() {
    let mesh = soup(400, 50);
    for method in [BottomUpMethod::Greedy, BottomUpMethod::Ploc] {
        for cost in [MergeCost::Distance, MergeCost::Volume, MergeCost::Area] {
            for leaf in [1, 8] {
                let bvh = Bvh::build_bottom_up(&mesh, &with(method, cost, leaf));
                bvh.validate(&mesh).unwrap();
                assert_matches_brute(&mesh, &bvh, &rays(1000, 7));
            }
        }
    }
}

#[test]
fn bottom_up_handles_empty_single_and_duplicate_sets() {
    for method in [BottomUpMethod::Greedy, BottomUpMethod::Ploc] {
        let params = with(method, MergeCost::Area, 8);
        let empty = TriangleMesh::default();
        let bvh = Bvh::bottom_up(&empty, &params, Binary::Keep);
        bvh.validate(&empty).unwrap();
        assert!(bvh.nodes().is_empty());
        let one = soup(1, 3);
        assert_eq!(Bvh::bottom_up(&one, &params, Binary::Keep).nodes().len(), 1);
        let mut dup = soup(1, 1);
        dup.indices = vec![[0, 1, 2]; 1000];
        let bvh = Bvh::build_bottom_up(&dup, &params);
        bvh.validate(&dup).unwrap();
        assert_matches_brute(&dup, &bvh, &rays(300, 4));
    }
}

#[test]
fn bottom_up_sah_cost_is_within_a_sane_factor_of_binned_sah_on_soups() {
    for (n, method) in [(1500, BottomUpMethod::Greedy), (20_000, BottomUpMethod::Ploc)] {
        let mesh = soup(n, n as u64);
        let binned = sah(&Bvh::build_sah(&mesh, &BvhParams::default()));
        let costs = [MergeCost::Area, MergeCost::Volume, MergeCost::Distance];
        for cost in if method == BottomUpMethod::Greedy { &costs[..] } else { &costs[..1] } {
            let got = sah(&Bvh::build_bottom_up(&mesh, &with(method, *cost, 8)));
            assert!(got < 1.5 * binned, "{method:?} {cost:?}: {got} vs binned {binned}");
        }
    }
}

#[test]
fn bottom_up_build_is_identical_for_any_thread_count() {
    for (n, method) in [(1500, BottomUpMethod::Greedy), (20_000, BottomUpMethod::Ploc)] {
        let mesh = soup(n, 60);
        let build = || Bvh::bottom_up(&mesh, &with(method, MergeCost::Area, 8), Binary::Keep);
        let (one, four) = (on_threads(1, build), on_threads(4, build));
        assert_eq!(one.nodes(), four.nodes(), "{method:?}");
        assert_eq!(one.prim_indices(), four.prim_indices(), "{method:?}");
    }
}

/// Unit triangles across the x axis at x = ±4^i: the cluster around the origin is always closer to
/// the next triangle out than any two triangles outside it are to each other, so both methods build
/// one chain as long as the input (128).
fn chain_mesh() -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for i in 0..64 {
        for sign in [1.0f32, -1.0] {
            let x = sign * 4f32.powi(i);
            let k = mesh.positions.len() as u32;
            mesh.positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0)]);
            mesh.indices.push([k, k + 1, k + 2]);
        }
    }
    mesh
}

#[test]
fn bottom_up_depth_is_bounded_on_chains() {
    let mesh = chain_mesh();
    let (live, _) = crate::accel::bvh::build::split_live(&mesh);
    for method in [BottomUpMethod::Greedy, BottomUpMethod::Ploc] {
        let arena = match method {
            BottomUpMethod::Greedy => greedy::cluster(&live, MergeCost::Area),
            _ => ploc::cluster(&live, 16),
        };
        assert!(arena_height(&arena) > MAX_DEPTH + 20, "{method:?}: not adversarial");
        for leaf in [1, 8] {
            let bvh = Bvh::build_bottom_up(&mesh, &with(method, MergeCost::Area, leaf));
            bvh.validate(&mesh).unwrap();
            let stats = Accel::<TriangleMesh>::stats(&bvh);
            // The chain is kept down to MAX_SAH_DEPTH and rebuilt below it by the median split.
            assert!((MAX_SAH_DEPTH..MAX_DEPTH).contains(&stats.max_depth), "{method:?}: {stats:?}");
            for x in [-3e29f32, -1.5, 1.0, 2e20, 4f32.powi(63)] {
                let ray = Ray::new(Vec3::new(x, 0.2, 0.2) - Vec3::X, Vec3::X);
                let brute = crate::accel::BruteForce::build(&mesh);
                assert_eq!(bvh.intersect(&mesh, &ray, f32::INFINITY), brute.intersect(&mesh, &ray, f32::INFINITY));
            }
        }
    }
}

#[test]
fn bottom_up_params_parse_keys_and_presets() {
    let config = AccelConfig::from(AccelKind::BvhBottomUp)
        .with_pairs(["method=ploc", "cost=volume", "radius=4", "greedy-max=10", "leaf=1"])
        .unwrap();
    let AccelConfig::BvhBottomUp(p) = config.clone() else { panic!("{config:?}") };
    assert_eq!(
        p,
        BottomUpParams {
            method: BottomUpMethod::Ploc,
            cost: MergeCost::Volume,
            radius: 4,
            greedy_max: 10,
            max_leaf_prims: 1
        }
    );
    let bad = AccelConfig::from(AccelKind::BvhBottomUp).with_pairs(["method=best"]).unwrap_err();
    assert_eq!(bad.to_string(), "parameter 'method': cannot read 'best' (expected auto|greedy|ploc)");
    let unknown = AccelConfig::from(AccelKind::BvhBottomUp).with_pairs(["bins=4"]).unwrap_err();
    assert!(unknown.to_string().contains("no parameter 'bins'"));
    let d = BottomUpParams::default();
    assert_eq!((d.method_for(2000), d.method_for(2001)), (BottomUpMethod::Greedy, BottomUpMethod::Ploc));
    assert_eq!(BottomUpParams::fast_build().method_for(10), BottomUpMethod::Ploc);
    let mesh = soup(300, 9);
    for p in [
        BottomUpParams::fast_build(),
        BottomUpParams::quality(),
        BottomUpParams { radius: 0, max_leaf_prims: 1000, ..d },
    ] {
        let bvh = Bvh::build_bottom_up(&mesh, &p);
        bvh.validate(&mesh).unwrap();
        assert_matches_brute(&mesh, &bvh, &rays(300, 8));
    }
}

#[test]
fn ploc_pairs_off_identical_clusters_into_a_balanced_tree() {
    // Equal boxes tie on every merge cost: the tie order must still pair most clusters each iteration
    // (a chain here means one merge per iteration, quadratic time).
    for n in [2, 3, 1_000, 4_097] {
        let prims: Vec<_> = (0..n).map(|i| prim([0.0; 3], [1.0, 1.0, 0.0], i)).collect();
        let arena = ploc::cluster(&prims, 16);
        assert_eq!(arena.len(), 2 * n as usize - 1);
        assert_eq!(arena_height(&arena), (n as usize).next_power_of_two().trailing_zeros() as usize, "n = {n}");
    }
}
