//! The closest-point query on the 8-wide tree: nearest child first, a stack of the others with their
//! box distances, a popped child skipped when its box is farther than the best candidate
//! (`accel/nearest.rs` says why that is exact: the tree's boxes hold their primitives' points).
//!
//! The eight box distances of a node are computed in `f64` with the shared expression; lanes of an
//! unused slot (an inverted box) are told by their box, not by their distance, which a query without a
//! bound could otherwise accept. A mesh's leaves are read from their blocks' copies of the corners, put
//! through the same triangle function as the mesh itself, so the numbers are those of brute force.

use super::leaves::leaf_blocks;
use super::visit::STACK;
use super::{Node8, Ref, Wide, WIDTH};
use crate::accel::mesh_prims::triangle_point;
use crate::accel::nearest::{box_dist2, NearestSoFar};
use crate::accel::Primitives;
use crate::math::{DVec3, Vec3};

/// Offers `best` the primitives of `wide` that may be nearer than its bound, nearest boxes first.
/// `indices` are the leaves' primitive indices when the tree has no triangle blocks.
pub(in crate::accel::bvh) fn closest_point<P: Primitives + ?Sized>(
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    best: &mut NearestSoFar,
) {
    let Some(root) = wide.root else { return };
    let mut stack = [(Ref { child: 0, count: 0 }, 0.0f64); STACK];
    let mut sp = 0usize;
    let mut cur = root;
    loop {
        if cur.count == 0 {
            let node = &wide.nodes[cur.child as usize];
            let (kids, n) = near_children(node, best.point(), best.bound());
            if n > 0 {
                // Farthest deepest; go on with the nearest.
                for &k in kids[1..n].iter().rev() {
                    stack[sp] = k;
                    sp += 1;
                }
                cur = kids[0].0;
                continue;
            }
        } else {
            leaf(wide, indices, prims, cur, best);
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let (r, d2) = stack[sp];
            if d2 <= best.bound() {
                cur = r;
                break;
            }
        }
    }
}

/// The children of `node` whose boxes are within squared distance `bound` of `p`, nearest first.
#[inline(always)]
fn near_children(node: &Node8, p: DVec3, bound: f64) -> ([(Ref, f64); WIDTH], usize) {
    let mut out = [(Ref { child: 0, count: 0 }, 0.0f64); WIDTH];
    let mut n = 0;
    for l in 0..WIDTH {
        let min = Vec3::new(node.min[0][l], node.min[1][l], node.min[2][l]);
        let max = Vec3::new(node.max[0][l], node.max[1][l], node.max[2][l]);
        if !min.cmple(max).all() {
            continue; // an unused slot
        }
        let d2 = box_dist2(p, min.as_dvec3(), max.as_dvec3());
        if d2 > bound {
            continue;
        }
        let e = (Ref { child: node.child[l], count: node.count[l] }, d2);
        let mut j = n;
        while j > 0 && out[j - 1].1 > d2 {
            out[j] = out[j - 1];
            j -= 1;
        }
        out[j] = e;
        n += 1;
    }
    (out, n)
}

/// Offers leaf `r`'s primitives to `best`.
#[inline(always)]
fn leaf<P: Primitives + ?Sized>(wide: &Wide, indices: &[u32], prims: &P, r: Ref, best: &mut NearestSoFar) {
    let p = best.point();
    match &wide.blocks {
        Some(blocks) => {
            for (block, lanes) in leaf_blocks(blocks, r) {
                let v = &block.tris.v;
                for l in (0..4).filter(|l| lanes & (1 << l) != 0) {
                    let corner = |k: usize| Vec3::new(v[k][0][l], v[k][1][l], v[k][2][l]);
                    best.offer(block.prim[l], triangle_point(p, [corner(0), corner(1), corner(2)]));
                }
            }
        }
        None => {
            let first = r.child as usize;
            for &prim in &indices[first..first + r.count as usize] {
                best.offer(prim, prims.closest_point(prim as usize, p));
            }
        }
    }
}
