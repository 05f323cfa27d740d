//! The one dispatch of every query over the node-test kernel and the kind of leaf: the closest-hit,
//! batch and any-hit queries are [`Traversal`]s, and [`run_with`] compiles each once per kernel and
//! kind of leaf, the AVX2 and AVX-512 ones inside functions compiled for those features so that the
//! node test inlines.
//!
//! Safe by construction: the AVX2 path is reached only through a [`Kernel::Avx2`], which holds an
//! [`Avx2`] token, and only [`Avx2::detect`] makes one; the AVX-512 path likewise through
//! [`Kernel::Avx512`] and [`Avx512::detect`].

#[cfg(target_arch = "x86_64")]
use super::kernel::{Avx2, Avx512, Sse};
use super::kernel::{Kernel, NodeTest, Scalar};
use super::leaves::{Leaves, MeshLeaves, PrimLeaves};
use super::{Node8, Ref, Wide};
use crate::accel::Primitives;

/// A traversal of the tree, compiled once per kernel and kind of leaf by [`run_with`].
pub(super) trait Traversal {
    /// What the query returns.
    type Out;
    /// The answer when the tree is empty.
    fn empty(self) -> Self::Out;
    /// The traversal from `root`, testing nodes with `kernel`.
    fn run<L: Leaves, K: NodeTest>(self, kernel: K, nodes: &[Node8], leaves: &L, root: Ref) -> Self::Out;
}

/// Runs `t` with `kernel`'s node test over `wide`'s kind of leaf.
#[inline]
pub(super) fn run_with<P: Primitives + ?Sized, T: Traversal>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    t: T,
) -> T::Out {
    match kernel {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `run_avx2` needs AVX2, and `avx2` exists, so `Avx2::detect` found it.
        Kernel::Avx2(avx2) => unsafe { run_avx2(avx2, wide, indices, prims, t) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `run_avx512` needs AVX-512 F and VL, and `avx512` exists, so `Avx512::detect` found them.
        Kernel::Avx512(avx512) => unsafe { run_avx512(avx512, wide, indices, prims, t) },
        #[cfg(target_arch = "x86_64")]
        Kernel::Sse => run_kernel(Sse, wide, indices, prims, t),
        Kernel::Scalar => run_kernel(Scalar, wide, indices, prims, t),
    }
}

/// The whole traversal compiled for AVX2, so that the node test inlines.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2<P: Primitives + ?Sized, T: Traversal>(avx2: Avx2, wide: &Wide, indices: &[u32], prims: &P, t: T) -> T::Out {
    run_kernel(avx2, wide, indices, prims, t)
}

/// The whole traversal compiled for AVX-512 F and VL, so that the node test inlines.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
fn run_avx512<P: Primitives + ?Sized, T: Traversal>(
    avx512: Avx512,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    t: T,
) -> T::Out {
    run_kernel(avx512, wide, indices, prims, t)
}

#[inline(always)]
fn run_kernel<P: Primitives + ?Sized, T: Traversal, K: NodeTest>(
    kernel: K,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    t: T,
) -> T::Out {
    let Some(root) = wide.root else { return t.empty() };
    match &wide.blocks {
        Some(blocks) => t.run(kernel, &wide.nodes, &MeshLeaves { blocks }, root),
        None => t.run(kernel, &wide.nodes, &PrimLeaves { indices, prims }, root),
    }
}
