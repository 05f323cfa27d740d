//! Build quality of the structures on a real scanned mesh (the shared Stanford bunny): the bottom-up
//! builders' SAH cost stays within a sane factor of the binned-SAH build's. Lives here rather than in
//! `arbor-accel` because it needs a mesh file loader.

mod common;

use arbor::accel::bvh::{BottomUpMethod, MergeCost};
use arbor::accel::{Accel, BottomUpParams, Bvh, BvhParams};
use arbor::geometry::TriangleMesh;

fn with(method: BottomUpMethod, cost: MergeCost, leaf: usize) -> BottomUpParams {
    BottomUpParams { method, cost, max_leaf_prims: leaf, ..BottomUpParams::default() }
}

fn sah(bvh: &Bvh) -> f64 {
    Accel::<TriangleMesh>::stats(bvh).sah_cost
}

#[test]
fn bottom_up_sah_cost_is_within_a_sane_factor_of_binned_sah_on_a_real_mesh() {
    let Some(dir) = common::meshes_dir() else {
        return;
    };
    let mut mesh = arbor::mesh_io::load_mesh(&dir.join("stanford-bunny.obj")).unwrap();
    let binned = sah(&Bvh::build_sah(&mesh, &BvhParams::default()));
    let ploc = sah(&Bvh::build_bottom_up(&mesh, &with(BottomUpMethod::Ploc, MergeCost::Area, 8)));
    assert!(ploc < 1.3 * binned, "ploc {ploc} vs binned {binned}");
    mesh.indices.truncate(2000);
    let binned = sah(&Bvh::build_sah(&mesh, &BvhParams::default()));
    let greedy = sah(&Bvh::build_bottom_up(&mesh, &with(BottomUpMethod::Greedy, MergeCost::Area, 8)));
    assert!(greedy < 1.3 * binned, "greedy {greedy} vs binned {binned}");
}
