//! Unit tests of the kd-tree: structure, hostile inputs, determinism, parameters. Equality with brute
//! force on many rays is the job of `tests/accel_conformance.rs`.

use super::*;
use crate::accel::{AccelConfig, AccelKind, BruteForce};
use crate::geometry::TriangleMesh;
use crate::math::Vec3;

use crate::test_rng::Rng;

fn mesh_of(tris: &[[Vec3; 3]]) -> TriangleMesh {
    TriangleMesh {
        positions: tris.iter().flatten().copied().collect(),
        indices: (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        ..Default::default()
    }
}

fn soup(n: usize, seed: u64) -> TriangleMesh {
    let mut rng = Rng(seed);
    let tris: Vec<_> = (0..n)
        .map(|_| {
            let c = rng.vec3() * 10.0;
            [0; 3].map(|_| c + rng.vec3() - 0.5)
        })
        .collect();
    mesh_of(&tris)
}

fn assert_matches_brute(mesh: &TriangleMesh, tree: &KdTree, seed: u64, n: usize) {
    let brute = BruteForce::build(mesh);
    let mut rng = Rng(seed);
    for _ in 0..n {
        let ray = Ray::new(rng.vec3() * 14.0 - 2.0, rng.vec3() - 0.5);
        let (a, b) = (tree.intersect(mesh, &ray, f32::INFINITY), brute.intersect(mesh, &ray, f32::INFINITY));
        assert_eq!(a, b, "ray {ray:?}");
        assert_eq!(tree.occluded(mesh, &ray, 5.0), brute.occluded(mesh, &ray, 5.0), "ray {ray:?}");
    }
}

#[test]
fn kdtree_node_is_eight_bytes_and_packs_its_fields() {
    assert_eq!(std::mem::size_of::<Node>(), 8);
    let n = Node::inner(2, -1.5, 12345);
    assert!(!n.is_leaf());
    assert_eq!((n.axis(), n.split(), n.above()), (2, -1.5, 12345));
    let l = Node::leaf(1, 77);
    assert!(l.is_leaf());
    assert_eq!(l.prims(&[]), &[77]);
    let l = Node::leaf(2, 1);
    assert_eq!(l.prims(&[9, 4, 6]), &[4, 6]);
}

#[test]
fn kdtree_empty_set_hits_nothing() {
    let mesh = TriangleMesh::default();
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY), None);
    assert!(!tree.occluded(&mesh, &ray, f32::INFINITY));
    assert!(Accel::<TriangleMesh>::bounds(&tree).is_empty());
    assert_eq!(Accel::<TriangleMesh>::stats(&tree).nodes, 0);
    assert!(Accel::<TriangleMesh>::boxes_at_depth(&tree, &mesh, 0).is_empty());
}

#[test]
fn kdtree_matches_brute_force_on_random_soup() {
    let mesh = soup(2_000, 7);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    assert_matches_brute(&mesh, &tree, 99, 3_000);
    let stats = Accel::<TriangleMesh>::stats(&tree);
    assert!(stats.nodes > 100 && stats.leaves * 2 == stats.nodes + 1, "{stats:?}");
    assert!(stats.refs_per_prim >= 1.0 && stats.mean_depth > 1.0 && stats.sah_cost > 0.0, "{stats:?}");
    assert!(stats.max_depth < MAX_DEPTH && stats.bytes >= 8 * stats.nodes, "{stats:?}");
}

#[test]
fn kdtree_perfect_splits_keep_references_low() {
    // Long thin diagonal triangles: their boxes overlap many cells, the triangles few.
    let mut rng = Rng(3);
    let tris: Vec<_> = (0..1_000)
        .map(|_| {
            let a = rng.vec3() * 10.0;
            [a, a + Vec3::splat(2.0), a + Vec3::new(2.0, 2.0, 2.05)]
        })
        .collect();
    let mesh = mesh_of(&tris);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    assert_matches_brute(&mesh, &tree, 5, 2_000);
}

#[test]
fn kdtree_drops_non_finite_and_handles_duplicates() {
    let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let nan = [Vec3::splat(f32::NAN); 3];
    let inf = [Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::INFINITY, 0.0)];
    let mesh = mesh_of(&[nan, t, t, inf, t]);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
    assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY).map(|h| h.prim), Some(1));
}

#[test]
fn kdtree_axis_aligned_grid_has_planar_splits_and_ties() {
    // Unit squares on the planes z = 0..8: every split candidate is planar.
    let mut tris = Vec::new();
    for z in 0..8 {
        for i in 0..4 {
            for j in 0..4 {
                let p = |di: u32, dj: u32| Vec3::new((i + di) as f32, (j + dj) as f32, z as f32);
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
            }
        }
    }
    let mesh = mesh_of(&tris);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    let brute = BruteForce::build(&mesh);
    for (o, d) in [
        (Vec3::new(1.0, 1.0, -1.0), Vec3::Z),
        (Vec3::new(2.0, 0.5, 9.0), -Vec3::Z),
        (Vec3::new(0.5, 0.5, 3.0), Vec3::X),
        (Vec3::new(1.0, 1.0, 3.0), Vec3::new(0.0, 0.0, 1.0)),
        (Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 2.0)),
    ] {
        let ray = Ray::new(o, d);
        assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY), brute.intersect(&mesh, &ray, f32::INFINITY));
    }
}

#[test]
fn kdtree_rays_in_and_across_split_planes_match_brute_force() {
    // Unit squares on the planes x = 0..6, and small triangles around them: splits land on the planes.
    let mut tris = Vec::new();
    for x in 0..6 {
        let p = |y: f32, z: f32| Vec3::new(x as f32, y, z);
        tris.push([p(0.0, 0.0), p(4.0, 0.0), p(4.0, 4.0)]);
        tris.push([p(0.0, 0.0), p(4.0, 4.0), p(0.0, 4.0)]);
    }
    let mut rng = Rng(31);
    tris.extend((0..200).map(|_| {
        let c = rng.vec3() * Vec3::new(5.0, 4.0, 4.0);
        [0; 3].map(|_| c + (rng.vec3() - 0.5) * 0.6)
    }));
    let mesh = mesh_of(&tris);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    let brute = BruteForce::build(&mesh);
    // Every split plane of the tree, with rays starting exactly on it: parallel to it (both signs of
    // zero), through it, and along the other axes.
    let mut planes = Vec::new();
    tree.walk(|_, n, _, _| {
        if !n.is_leaf() {
            planes.push((n.axis(), n.split()));
        }
    });
    assert!(planes.len() > 10);
    for &(axis, split) in planes.iter().take(200) {
        for k in 0..20 {
            let mut o = rng.vec3() * 6.0 - 0.5;
            o[axis] = split;
            let mut d = rng.vec3() - 0.5;
            match k % 4 {
                0 => d[axis] = 0.0,
                1 => d[axis] = -0.0,
                2 => d = Vec3::ZERO.with_x(if k % 8 == 2 { 1.0 } else { -1.0 }),
                _ => {}
            }
            let ray = Ray::new(o, d);
            for t_max in [f32::INFINITY, 1.5] {
                let want = brute.intersect(&mesh, &ray, t_max);
                assert_eq!(tree.intersect(&mesh, &ray, t_max), want, "{ray:?} on split {split} axis {axis}");
                assert_eq!(tree.occluded(&mesh, &ray, t_max), want.is_some(), "{ray:?}");
            }
        }
    }
}

#[test]
fn kdtree_presets_match_brute_force_offset_scaled_and_on_vertices() {
    // The conformance suite builds with the defaults; the presets give deeper (pbrt) or shallower trees.
    let mut rng = Rng(37);
    let base: Vec<[Vec3; 3]> = (0..300)
        .map(|_| {
            let c = rng.vec3() * 10.0;
            [0; 3].map(|_| c + (rng.vec3() - 0.5) * 1.5)
        })
        .collect();
    for map in [|p: Vec3| p + Vec3::splat(1e5), |p: Vec3| p * 1e-4] {
        let tris: Vec<_> = base.iter().map(|t| t.map(map)).collect();
        let mesh = mesh_of(&tris);
        let brute = BruteForce::build(&mesh);
        for params in
            [KdTreeParams::default(), KdTreeParams::wald_havran(), KdTreeParams::pbrt(), KdTreeParams::fast_build()]
        {
            let tree = KdTree::build(&mesh, &params);
            tree.validate(&mesh).unwrap();
            let b = Accel::<TriangleMesh>::bounds(&tree);
            for i in 0..2_000 {
                let target = tris[i % tris.len()][i % 3];
                let o = match i % 3 {
                    0 => b.min + (rng.vec3() * 2.0 - 0.5) * b.extent(),
                    1 => tris[(i * 7) % tris.len()][(i + 1) % 3],
                    _ => Aabb::from_points(tris[(i * 3) % tris.len()]).center(),
                };
                let ray = Ray::new(o, if i % 5 == 0 { rng.vec3() - 0.5 } else { target - o });
                let want = brute.intersect(&mesh, &ray, f32::INFINITY);
                assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY), want, "{params:?} {ray:?}");
                assert_eq!(tree.occluded(&mesh, &ray, f32::INFINITY), want.is_some(), "{params:?} {ray:?}");
            }
        }
    }
}

#[test]
fn kdtree_build_is_deterministic() {
    let mesh = soup(1_500, 11);
    let (a, b) = (KdTree::build(&mesh, &KdTreeParams::default()), KdTree::build(&mesh, &KdTreeParams::default()));
    assert_eq!(a.nodes(), b.nodes());
    assert_eq!(a.prim_refs(), b.prim_refs());
}

#[test]
fn kdtree_counted_traversal_reports_work() {
    let mesh = soup(500, 13);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    let ray = Ray::new(Vec3::new(-1.0, 5.0, 5.0), Vec3::X);
    let mut counts = TraversalCounts::default();
    let hit = tree.intersect_counted(&mesh, &ray, f32::INFINITY, &mut counts);
    assert_eq!(hit, tree.intersect(&mesh, &ray, f32::INFINITY));
    assert!(counts.nodes > 0 && counts.prims > 0);
}

#[test]
fn kdtree_boxes_at_depth_tile_the_root() {
    let mesh = soup(800, 17);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    let root = Accel::<TriangleMesh>::bounds(&tree);
    assert_eq!(Accel::<TriangleMesh>::boxes_at_depth(&tree, &mesh, 0), vec![root]);
    let level: Vec<Aabb> = Accel::<TriangleMesh>::boxes_at_depth(&tree, &mesh, 1);
    assert_eq!(level.len(), 2);
    let volume = |b: &Aabb| b.extent().x * b.extent().y * b.extent().z;
    assert!((level.iter().map(volume).sum::<f32>() - volume(&root)).abs() <= 1e-3 * volume(&root));
}

#[test]
fn kdtree_params_parse_and_depth_limit_holds() {
    let config = AccelConfig::from(AccelKind::KdTree)
        .with_pairs(["traversal-cost=10", "intersection-cost=30", "empty-bonus=0.5", "depth=3"])
        .unwrap();
    let AccelConfig::KdTree(p) = config.clone() else { panic!("{config:?}") };
    assert_eq!(p, KdTreeParams { traversal_cost: 10.0, intersection_cost: 30.0, empty_bonus: 0.5, max_depth: Some(3) });
    let bad = AccelConfig::from(AccelKind::KdTree).with_pairs(["bins=3"]).unwrap_err();
    assert!(bad.to_string().contains("no parameter 'bins'"));
    let auto = AccelConfig::from(AccelKind::KdTree).with_pairs(["depth=3", "depth=auto"]).unwrap();
    assert_eq!(auto, AccelConfig::from(AccelKind::KdTree), "depth=auto is the default, pbrt's formula");
    let mesh = soup(1_000, 19);
    let tree = KdTree::build(&mesh, &p);
    assert!(Accel::<TriangleMesh>::stats(&tree).max_depth <= 3);
    assert_matches_brute(&mesh, &tree, 23, 500);
    for preset in [KdTreeParams::fast_build(), KdTreeParams::wald_havran(), KdTreeParams::pbrt()] {
        let tree = KdTree::build(&mesh, &preset);
        tree.validate(&mesh).unwrap();
        assert_matches_brute(&mesh, &tree, 29, 500);
    }
    let silly =
        KdTreeParams { traversal_cost: f32::NAN, intersection_cost: -1.0, empty_bonus: 7.0, max_depth: Some(1000) };
    let tree = KdTree::build(&mesh, &silly);
    tree.validate(&mesh).unwrap();
    assert!(Accel::<TriangleMesh>::stats(&tree).max_depth < MAX_DEPTH);
}

#[test]
fn kdtree_parallel_build_writes_the_sequential_tree() {
    let mesh = soup(3000, 91);
    let params = KdTreeParams::default();
    let sequential = build::build_split_at(&mesh, &params, 20, usize::MAX);
    for parallel_min in [2, 64, 1000] {
        let parallel = build::build_split_at(&mesh, &params, 20, parallel_min);
        assert_eq!(parallel.0, sequential.0, "nodes, parallel below {parallel_min}");
        assert_eq!(parallel.1, sequential.1, "references, parallel below {parallel_min}");
    }
    assert!(sequential.0.len() > 1000 && !sequential.1.is_empty());
}

/// Random triangles lying in the plane z = 0, coordinates in [-5, 5].
fn coplanar(n: usize, seed: u64) -> TriangleMesh {
    let mut rng = Rng(seed);
    let mut point = || Vec3::new(rng.f32() * 10.0 - 5.0, rng.f32() * 10.0 - 5.0, 0.0);
    let tris: Vec<_> = (0..n).map(|_| [point(), point(), point()]).collect();
    mesh_of(&tris)
}

/// Sum of the primitive counts of the leaves and inner nodes at each depth: the inner nodes' counts are
/// those of their subtrees' leaves at that depth, so per depth it is the sum over the nodes' own sets.
fn refs_per_depth(tree: &KdTree) -> Vec<usize> {
    fn count(tree: &KdTree, i: usize, depth: usize, out: &mut Vec<(usize, Vec<u32>)>) -> Vec<u32> {
        let node = tree.nodes[i];
        let prims = if node.is_leaf() {
            node.prims(&tree.refs).to_vec()
        } else {
            let mut p = count(tree, i + 1, depth + 1, out);
            p.extend(count(tree, node.above(), depth + 1, out));
            p.sort_unstable();
            p.dedup();
            p
        };
        out.push((depth, prims.clone()));
        prims
    }
    let mut nodes = Vec::new();
    if !tree.nodes.is_empty() {
        count(tree, 0, 0, &mut nodes);
    }
    let mut per_depth = vec![0; nodes.iter().map(|(d, _)| d + 1).max().unwrap_or(0)];
    for (d, prims) in &nodes {
        per_depth[*d] += prims.len();
    }
    per_depth
}

#[test]
fn kdtree_coplanar_triangles_build_a_small_tree() {
    // Overlapping triangles in one plane: every split the SAH finds copies most of them to both sides,
    // so without the bad-refine limit the tree grows as 2^depth (thousands of references per triangle).
    let n = 300;
    let mesh = coplanar(n, 11);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    tree.validate(&mesh).unwrap();
    assert!(tree.nodes().len() <= 40 * n, "{} nodes", tree.nodes().len());
    assert!(tree.prim_refs().len() <= 40 * n, "{} references", tree.prim_refs().len());
    // The module's bound: at most 2^3 (3/2)^d N references at depth d.
    for (d, &refs) in refs_per_depth(&tree).iter().enumerate() {
        assert!(refs as f64 <= 8.0 * 1.5f64.powi(d as i32) * n as f64, "{refs} references at depth {d}");
    }
    let brute = BruteForce::build(&mesh);
    let mut rng = Rng(12);
    for _ in 0..2_000 {
        let from = Vec3::new(rng.f32() * 12.0 - 6.0, rng.f32() * 12.0 - 6.0, 1.0 + rng.f32());
        let ray = Ray::new(from, rng.vec3() - Vec3::new(0.5, 0.5, 1.0));
        assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY), brute.intersect(&mesh, &ray, f32::INFINITY));
    }
}

#[test]
fn kdtree_reference_bound_holds_on_ordinary_scenes() {
    // The per-depth reference bound holds on ordinary input too.
    let n = 2_000;
    let mesh = soup(n, 23);
    let tree = KdTree::build(&mesh, &KdTreeParams::default());
    for (d, &refs) in refs_per_depth(&tree).iter().enumerate() {
        assert!(refs as f64 <= 8.0 * 1.5f64.powi(d as i32) * n as f64, "{refs} references at depth {d}");
    }
}
