//! Unit tests of the octree: structure, parameters, hostile inputs. Equality with brute force on
//! many rays is the job of `tests/accel_conformance.rs`.

use super::*;
use crate::accel::{AccelConfig, AccelKind, BruteForce};
use crate::geometry::TriangleMesh;

use crate::test_rng::Rng;

fn mesh_of(tris: &[[Vec3; 3]]) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for (i, t) in tris.iter().enumerate() {
        mesh.positions.extend_from_slice(t);
        let k = 3 * i as u32;
        mesh.indices.push([k, k + 1, k + 2]);
    }
    mesh
}

fn soup(n: usize, size: f32, seed: u64) -> TriangleMesh {
    let mut rng = Rng(seed);
    let tris: Vec<[Vec3; 3]> = (0..n)
        .map(|_| {
            let c = rng.vec3() * 10.0;
            [c + (rng.vec3() - 0.5) * size, c + (rng.vec3() - 0.5) * size, c + (rng.vec3() - 0.5) * size]
        })
        .collect();
    mesh_of(&tris)
}

fn assert_matches_brute(mesh: &TriangleMesh, tree: &Octree, rays: usize, seed: u64) {
    let brute = BruteForce::build(mesh);
    let mut rng = Rng(seed);
    for _ in 0..rays {
        let ray = Ray::new(rng.vec3() * 14.0 - 2.0, rng.vec3() - 0.5);
        let expected = brute.intersect(mesh, &ray, f32::INFINITY);
        assert_eq!(tree.intersect(mesh, &ray, f32::INFINITY), expected, "ray {ray:?}");
        let mut counts = TraversalCounts::default();
        assert_eq!(tree.intersect_counted(mesh, &ray, f32::INFINITY, &mut counts), expected);
        assert!(counts.prims > 0 || expected.is_none());
        assert_eq!(tree.occluded(mesh, &ray, 5.0), brute.occluded(mesh, &ray, 5.0));
    }
}

#[test]
fn octree_empty_set_hits_nothing() {
    let mesh = TriangleMesh::default();
    let tree = Octree::build(&mesh, &OctreeParams::default());
    tree.validate(&mesh).unwrap();
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY), None);
    assert!(!tree.occluded(&mesh, &ray, f32::INFINITY));
    assert!(Accel::<TriangleMesh>::bounds(&tree).is_empty());
    assert_eq!(Accel::<TriangleMesh>::stats(&tree).nodes, 0);
    assert!(Accel::<TriangleMesh>::boxes_at_depth(&tree, &mesh, 0).is_empty());
}

#[test]
fn octree_matches_brute_force_on_random_soups() {
    for (size, seed) in [(0.5, 1), (3.0, 2), (12.0, 3)] {
        let mesh = soup(2000, size, seed);
        let tree = Octree::build(&mesh, &OctreeParams::default());
        tree.validate(&mesh).unwrap();
        assert_matches_brute(&mesh, &tree, 3000, seed + 10);
    }
}

#[test]
fn octree_references_a_triangle_on_a_split_plane_on_both_sides() {
    // Many small triangles to force splits, and one lying exactly in the root's mid plane x = 5.
    let mut tris: Vec<[Vec3; 3]> = (0..200)
        .map(|i| {
            let p = Vec3::new((i % 10) as f32, ((i / 10) % 10) as f32, (i / 100) as f32 * 10.0);
            [p, p + Vec3::X * 0.3, p + Vec3::Y * 0.3]
        })
        .collect();
    let mid = split_point(&Octree::build(&mesh_of(&tris), &OctreeParams::default()).root()).x;
    // Inside the other triangles' bounds, so the root does not move.
    tris.push([Vec3::new(mid, 2.0, 2.0), Vec3::new(mid, 7.0, 2.0), Vec3::new(mid, 2.0, 7.0)]);
    let mesh = mesh_of(&tris);
    let tree = Octree::build(&mesh, &OctreeParams { max_leaf_prims: 2, ..Default::default() });
    tree.validate(&mesh).unwrap();
    assert_eq!(split_point(&tree.root()).x, mid);
    let last = (tris.len() - 1) as u32;
    let (mut below, mut above) = (false, false);
    tree.for_each_cell(|node, cell, _| {
        if node.is_leaf() && tree.refs()[node.range()].contains(&last) {
            below |= cell.max.x == mid;
            above |= cell.min.x == mid;
        }
    });
    assert!(below && above, "referenced on one side only");
    for dir in [Vec3::X, -Vec3::X] {
        let ray = Ray::new(Vec3::new(mid, 3.0, 3.0) - 3.0 * dir, dir);
        assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY).map(|h| h.prim), Some(last));
    }
}

#[test]
fn octree_stops_splitting_coincident_triangles() {
    let big = [Vec3::ZERO, Vec3::new(10.0, 0.0, 3.0), Vec3::new(0.0, 10.0, 7.0)];
    let mesh = mesh_of(&vec![big; 500]);
    let tree = Octree::build(&mesh, &OctreeParams::default());
    tree.validate(&mesh).unwrap();
    let stats = Accel::<TriangleMesh>::stats(&tree);
    assert!(stats.nodes <= 9 && stats.refs_per_prim <= 8.0, "{stats:?}");
    let ray = Ray::new(Vec3::new(1.0, 1.0, -5.0), Vec3::Z);
    assert_eq!(tree.intersect(&mesh, &ray, f32::INFINITY).map(|h| h.prim), Some(0));
}

#[test]
fn octree_leaves_out_non_finite_primitives() {
    let ok = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let inf = [Vec3::ZERO, Vec3::splat(f32::INFINITY), Vec3::Y];
    let mesh = mesh_of(&[inf, ok, inf]);
    let tree = Octree::build(&mesh, &OctreeParams::default());
    tree.validate(&mesh).unwrap();
    assert_eq!(tree.refs(), &[1]);
    assert_eq!(Accel::<TriangleMesh>::bounds(&tree), Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)));
}

#[test]
fn octree_params_parse_clamp_and_presets_differ() {
    let config = AccelConfig::from(AccelKind::Octree).with_pairs(["leaf=3", "depth=16", "traversal-cost=2"]).unwrap();
    let AccelConfig::Octree(p) = config.clone() else { panic!("{config:?}") };
    assert_eq!((p.max_leaf_prims, p.max_depth, p.traversal_cost), (3, 16, 2.0));
    let too_deep = AccelConfig::from(AccelKind::Octree).with_pairs(["depth=99"]).unwrap_err();
    assert_eq!(too_deep.to_string(), "parameter 'depth': 99 is outside its range 0..=16");
    // Written directly, past the configuration's checks, the builder still clamps.
    assert_eq!(OctreeParams { max_depth: 99, ..p }.sanitized().max_depth, MAX_DEPTH);
    let bad = AccelConfig::from(AccelKind::Octree).with_pairs(["bins=3"]).unwrap_err();
    assert!(bad.to_string().contains("no parameter 'bins'"));
    let mesh = soup(3000, 0.3, 5);
    let shallow = Accel::<TriangleMesh>::stats(&Octree::build(&mesh, &OctreeParams::fast_build()));
    let deep = Accel::<TriangleMesh>::stats(&Octree::build(&mesh, &OctreeParams::quality()));
    assert!(shallow.nodes < deep.nodes && shallow.max_depth <= 8, "{shallow:?} {deep:?}");
    let one = Octree::build(&mesh, &OctreeParams { max_depth: 1, ..Default::default() });
    assert_eq!(Accel::<TriangleMesh>::stats(&one).max_depth, 1);
    assert!(config.build_accel(&mesh).is_ok());
}

#[test]
fn octree_stats_and_boxes_describe_the_tree() {
    let mesh = soup(5000, 0.4, 9);
    let tree = Octree::build(&mesh, &OctreeParams::default());
    let s = Accel::<TriangleMesh>::stats(&tree);
    assert_eq!((s.kind, s.primitives, s.nodes), ("octree", 5000, tree.nodes().len()));
    assert!(s.leaves > 0 && s.max_depth >= 3 && s.mean_depth > 1.0 && s.mean_depth <= s.max_depth as f64);
    assert!(s.refs_per_prim >= 1.0 && s.mean_leaf_prims > 0.0 && s.sah_cost > 0.0 && s.bytes > 0);
    assert_eq!((s.nodes - 1) % 8, 0);
    let root = tree.root();
    assert_eq!(Accel::<TriangleMesh>::boxes_at_depth(&tree, &mesh, 0), vec![root]);
    let level1 = Accel::<TriangleMesh>::boxes_at_depth(&tree, &mesh, 1);
    assert!(!level1.is_empty() && level1.len() <= 8);
    assert!(level1.iter().all(|b| root.contains(b)));
    let e = root.extent();
    assert!((e.x - e.y).abs() <= 1e-5 * e.x && (e.x - e.z).abs() <= 1e-5 * e.x, "root is a cube");
}

#[test]
fn octree_build_is_deterministic() {
    let mesh = soup(20_000, 0.3, 4);
    let a = Octree::build(&mesh, &OctreeParams::default());
    let b = Octree::build(&mesh, &OctreeParams::default());
    assert_eq!((a.nodes(), a.refs()), (b.nodes(), b.refs()));
}

#[test]
fn octree_validate_catches_a_missing_reference() {
    let mesh = soup(500, 0.5, 6);
    let mut tree = Octree::build(&mesh, &OctreeParams::default());
    tree.validate(&mesh).unwrap();
    let leaf = tree.nodes.iter().position(|n| n.is_leaf() && n.count > 1).unwrap();
    let r = tree.nodes[leaf].range();
    tree.refs[r.start] = tree.refs[r.start + 1];
    assert!(tree.validate(&mesh).is_err());
}
