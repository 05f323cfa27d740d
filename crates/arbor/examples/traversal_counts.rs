//! Work per ray and memory of Arbor's default structure (`bvh-sah`) on the rays that `peerbench
//! --dump-rays DIR` wrote for a mesh: wide-node visits (each one test of up to eight child boxes) and
//! triangles tested per ray, one query per ray, counted by `Accel::intersect_counted` (the counting
//! copy of `intersect`, which visits the same nodes); and the structure's bytes per triangle, split
//! into its parts, next to the bytes of the mesh itself. Not timed: docs/performance.md uses it for the
//! per-ray breakdown against Embree.
//!
//! ```sh
//! cargo run --release -p arbor --example traversal_counts -- MESH RAY_DIR
//! ```

use std::path::Path;

use arbor::accel::bvh::{query_kernel, Bvh, BvhParams};
use arbor::accel::{build, Accel, AccelKind, TraversalCounts};
use arbor::bench::ray_files::{disagrees, load_ray_set};
use arbor::geometry::TriangleMesh;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, mesh_path, dir] = &args[..] else {
        eprintln!("usage: traversal_counts MESH RAY_DIR");
        std::process::exit(2);
    };
    let mesh = arbor::mesh_io::load_mesh(Path::new(mesh_path)).unwrap_or_else(|e| {
        eprintln!("{mesh_path}: {e}");
        std::process::exit(1);
    });
    let tris = mesh.len();
    let per_tri = |b: usize| b as f64 / tris.max(1) as f64;
    let accel = build(AccelKind::BvhSah, &mesh);
    let stats = accel.stats();

    // The same build, concrete, for the split of its bytes.
    let bvh = Bvh::build_sah(&mesh, &BvhParams::default());
    assert_eq!(
        Accel::<TriangleMesh>::stats(&bvh).bytes,
        stats.bytes,
        "the default bvh-sah is Bvh::build_sah with default parameters"
    );
    // Empty for a mesh once the build has dropped them; printed so that a structure that keeps them shows.
    let binary = std::mem::size_of_val(bvh.nodes());
    let indices = std::mem::size_of_val(bvh.prim_indices());
    let blocks = bvh.wide().blocks().len();
    let block_bytes = std::mem::size_of_val(bvh.wide().blocks());
    let wide_nodes = std::mem::size_of_val(bvh.wide().nodes());
    assert_eq!(stats.bytes, binary + indices + block_bytes + wide_nodes + std::mem::size_of::<Bvh>());
    let mesh_bytes = std::mem::size_of_val(&mesh.positions[..])
        + std::mem::size_of_val(&mesh.indices[..])
        + mesh.normals.as_ref().map_or(0, |n| std::mem::size_of_val(&n[..]))
        + mesh.uvs.as_ref().map_or(0, |u| std::mem::size_of_val(&u[..]));
    println!("# mesh={mesh_path} tris={tris} vertices={} kernel={}", mesh.positions.len(), query_kernel());
    println!(
        "memory structure_bytes={} ({:.1} B/tri): wide_nodes={} ({:.1}) triangle_blocks={} ({:.1}, {blocks} blocks) \
         binary_nodes={} ({:.1}) prim_indices={} ({:.1}); mesh_bytes={} ({:.1} B/tri: positions, indices, normals, uvs)",
        stats.bytes,
        per_tri(stats.bytes),
        wide_nodes,
        per_tri(wide_nodes),
        block_bytes,
        per_tri(block_bytes),
        binary,
        per_tri(binary),
        indices,
        per_tri(indices),
        mesh_bytes,
        per_tri(mesh_bytes)
    );

    for set in ["primary", "diffuse"] {
        let file = load_ray_set(Path::new(dir), set, mesh.len()).unwrap_or_else(|e| {
            eprintln!("{dir}: {e}");
            std::process::exit(1);
        });
        // Totals over all rays, over the rays that hit and over those that miss.
        let mut all = (0u64, 0u64);
        let mut hit = (0u64, 0u64, 0u64);
        let mut wrong = 0usize;
        for (r, reference) in file.rays.iter().zip(&file.hits) {
            let mut c = TraversalCounts::default();
            let h = accel.intersect_counted(&mesh, &r.ray, r.t_max, &mut c);
            wrong += usize::from(h != accel.intersect(&mesh, &r.ray, r.t_max) || disagrees(h.map(|h| h.t), reference));
            all.0 += u64::from(c.nodes);
            all.1 += u64::from(c.prims);
            if h.is_some() {
                hit.0 += 1;
                hit.1 += u64::from(c.nodes);
                hit.2 += u64::from(c.prims);
            }
        }
        let n = file.rays.len().max(1) as f64;
        let misses = (file.rays.len() as u64 - hit.0).max(1) as f64;
        println!(
            "counts set={set} rays={} hits={} nodes_per_ray={:.2} box_lanes_per_ray={:.1} tris_per_ray={:.2} \
             hit_nodes={:.2} hit_tris={:.2} miss_nodes={:.2} miss_tris={:.2} mismatch={wrong}",
            file.rays.len(),
            hit.0,
            all.0 as f64 / n,
            8.0 * all.0 as f64 / n,
            all.1 as f64 / n,
            hit.1 as f64 / hit.0.max(1) as f64,
            hit.2 as f64 / hit.0.max(1) as f64,
            (all.0 - hit.1) as f64 / misses,
            (all.1 - hit.2) as f64 / misses,
        );
    }
}
