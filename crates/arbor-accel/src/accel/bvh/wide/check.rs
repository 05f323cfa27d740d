//! What remains of a mesh BVH once its binary tree is dropped, checked for
//! [`Accel::validate`](crate::accel::Accel::validate): the checks of `../validate.rs` restated for the
//! wide tree and its triangle blocks. O(n) time and memory.

use super::super::{LEAF_HARD_MAX, MAX_DEPTH};
use super::{Node8, Ref, Wide, WIDTH};
use crate::accel::bvh::build::usable;
use crate::accel::Primitives;
use crate::geometry::{Tri4, TriangleMesh};
use crate::math::{Aabb, Vec3};

/// Lane `l` of `node`, or `None` for an unused lane.
fn lane(node: &Node8, l: usize) -> Option<(Aabb, Ref)> {
    (node.child[l] != u32::MAX).then(|| {
        let min = Vec3::new(node.min[0][l], node.min[1][l], node.min[2][l]);
        let max = Vec3::new(node.max[0][l], node.max[1][l], node.max[2][l]);
        (Aabb::new(min, max), Ref { child: node.child[l], count: node.count[l] })
    })
}

impl Wide {
    /// True when the leaves are triangle blocks (the primitives were a mesh).
    pub(in crate::accel::bvh) fn has_blocks(&self) -> bool {
        self.blocks.is_some()
    }

    /// Checks the wide tree over `mesh` built from `primitives` primitives of which `live` are in the
    /// tree: every node is reached once and within the stack's depth, every lane's box encloses what it
    /// refers to, every block is used once and holds the corners of its primitives, and every live
    /// primitive is in exactly one block lane (the others cannot be hit).
    pub(in crate::accel::bvh) fn validate(
        &self,
        mesh: &TriangleMesh,
        primitives: usize,
        live: usize,
        bounds: Aabb,
    ) -> Result<(), String> {
        let n = Primitives::len(mesh);
        if primitives != n {
            return Err(format!("built over {primitives} primitives, queried with {n}"));
        }
        let blocks = self.blocks.as_deref().unwrap_or(&[]);
        let mut seen = vec![false; n];
        let mut block_used = vec![false; blocks.len()];
        let mut node_seen = vec![false; self.nodes.len()];
        let mut leaf = |b: Aabb, r: Ref| -> Result<(), String> {
            let count = r.count as usize;
            if count > LEAF_HARD_MAX {
                return Err(format!("leaf at block {} holds {count} primitives", r.child));
            }
            let first = r.child as usize;
            let range = first..first + count.div_ceil(4);
            let Some(used) = block_used.get_mut(range.clone()) else {
                return Err(format!("leaf blocks {range:?} out of {}", blocks.len()));
            };
            if used.iter().any(|&u| u) {
                return Err(format!("a block of {range:?} belongs to two leaves"));
            }
            used.fill(true);
            for (k, block) in blocks[range].iter().enumerate() {
                let lanes = (count - 4 * k).min(4);
                let prims = &block.prim[..lanes];
                let mut tris = Vec::with_capacity(lanes);
                for &p in prims {
                    let slot = seen.get_mut(p as usize).ok_or_else(|| format!("primitive index {p} out of range"))?;
                    if std::mem::replace(slot, true) {
                        return Err(format!("primitive {p} appears twice"));
                    }
                    if !b.contains(&Primitives::bounds(mesh, p as usize)) {
                        return Err(format!("primitive {p} sticks out of its leaf box"));
                    }
                    tris.push(mesh.triangle(p as usize));
                }
                if Tri4::new(&tris).v.map(|c| c.map(|a| a.map(f32::to_bits)))
                    != block.tris.v.map(|c| c.map(|a| a.map(f32::to_bits)))
                {
                    return Err(format!("block {} does not hold its primitives' corners", first + k));
                }
            }
            Ok(())
        };
        match self.root {
            None => {}
            Some(r) if r.count > 0 => leaf(bounds, r)?,
            Some(_) => {
                let mut stack = vec![(0usize, bounds, 0usize)];
                while let Some((i, parent, depth)) = stack.pop() {
                    if depth >= MAX_DEPTH {
                        return Err(format!("wide node {i} at depth {depth} would overflow the traversal stack"));
                    }
                    let reached = node_seen.get_mut(i).ok_or_else(|| format!("wide node {i} out of range"))?;
                    if std::mem::replace(reached, true) {
                        return Err(format!("wide node {i} is reachable twice"));
                    }
                    for (b, r) in (0..WIDTH).filter_map(|l| lane(&self.nodes[i], l)) {
                        if !parent.contains(&b) {
                            return Err(format!("a lane of wide node {i} is not inside its parent's box"));
                        }
                        if r.count == 0 {
                            stack.push((r.child as usize, b, depth + 1));
                        } else {
                            leaf(b, r)?;
                        }
                    }
                }
            }
        }
        if node_seen.iter().any(|&s| !s) || block_used.iter().any(|&u| !u) {
            return Err("a wide node or block is not reachable".into());
        }
        let reached = seen.iter().filter(|&&s| s).count();
        if reached != live {
            return Err(format!("{reached} of {live} live primitives are reachable"));
        }
        if let Some(p) = (0..n).find(|&p| !seen[p] && usable(&Primitives::bounds(mesh, p))) {
            return Err(format!("primitive {p} has finite bounds but is not in the tree"));
        }
        Ok(())
    }
}

#[cfg(test)]
impl Wide {
    /// The triangle blocks, to corrupt in tests of [`Wide::validate`].
    pub(in crate::accel::bvh) fn blocks_mut(&mut self) -> &mut Vec<super::LeafBlock> {
        self.blocks.as_mut().expect("a mesh's wide tree")
    }
}
