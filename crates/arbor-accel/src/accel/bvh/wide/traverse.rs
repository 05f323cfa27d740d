//! Traversal of the 8-wide tree: one ray against eight boxes at once, nearest child first.
//!
//! Hand-written SIMD (`std::arch`) because this loop is the hot core of every query: the eight slab
//! tests share the ray's broadcast origin and reciprocal direction, and the per-axis choice of the entry
//! plane is precomputed as load offsets, so a node test is about 20 instructions without branches. With
//! AVX2 (detected at run time, once per query) the eight lanes are one register and the whole query is
//! compiled for AVX2; without it, two SSE halves (SSE2 is the x86_64 baseline); elsewhere, scalar code.
//! All three compute the same per-lane arithmetic, so they visit the same nodes (unit test). The stack
//! lives in uninitialised memory so that a query does not pay for clearing it.
//!
//! A batch of closest-hit queries ([`intersect_many`]) runs the same traversal for two rays at once,
//! one node visit of each in turn ([`Walk`]): a visit is a chain of dependent loads and arithmetic, and
//! the other ray's visit fills the wait. The node visit and the pop are shared by both forms
//! ([`visit`], [`pop`]), so they visit the same nodes.
//!
//! Exactness against brute force follows the binary traversal (`../traverse.rs`), whose argument holds
//! lane by lane: the box test is the same conservative test, `near <= far + scale * SLACK` with `scale`
//! the larger slab distance on the ray's major axis; `max`/`min` take the accumulator as the operand
//! that wins over a NaN, as `f32::max`/`min` do; a node at exactly the best `t` is still visited; leaves
//! ask for hits up to the float above the best `t` and keep ties by lowest primitive index.
//! Children are pushed farthest first with their entry distance and slack; a popped entry is skipped
//! when `near > t_far + slack`, which is implied by failing its box test against the current `t_far`
//! (float addition is monotone), so the skip never drops a box that test would keep.

use std::mem::MaybeUninit;

use super::super::traverse::next_up;
use super::super::MAX_DEPTH;
use super::{LeafBlock, Node8, Ref, Wide, WIDTH};
use crate::accel::{Hit, PrimHit, Primitives, TraversalCounts, BOX_SLACK};
use crate::geometry::{intersect_triangles4, RayFrame};
use crate::math::Ray;

/// At most `WIDTH - 1` entries are pushed per level of the current path.
const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// The code that tests a node's boxes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// One 8-lane AVX2 register per axis and side.
    Avx2,
    /// Two 4-lane SSE halves.
    Sse,
    /// A loop over the lanes (used on x86_64 only by the unit test that compares the kernels).
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    Scalar,
}

impl Kernel {
    /// The fastest kernel this processor runs.
    #[inline]
    pub fn detect() -> Kernel {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                Kernel::Avx2
            } else {
                Kernel::Sse
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        Kernel::Scalar
    }
}

/// `Kernel` as a const generic parameter.
const AVX2: u8 = 0;
const SSE: u8 = 1;
const SCALAR: u8 = 2;

#[derive(Clone, Copy)]
struct Entry {
    r: Ref,
    near: f32,
    slack: f32,
}

/// What a node test returns: the lanes whose box the ray meets in `[0, t_far]` (bit per lane), their
/// entry distances and their slacks.
type Tested = (u32, [f32; WIDTH], [f32; WIDTH]);

/// A ray prepared for eight-box tests: per axis, where the entry and exit planes are in a node (as `f32`
/// offsets into it), the broadcast origin and reciprocal direction; and the major axis (the
/// direction's largest component), whose slab distances size the box slack and which the triangle
/// test's frame shears along. (Storing the axes major first, to take the slack without asking which
/// axis it is, made primary rays 5% slower: the permuted setup sits on every query's critical path.)
struct Lanes {
    enter: [usize; 3],
    exit: [usize; 3],
    org: [f32; 3],
    inv: [f32; 3],
    major: usize,
}

impl Lanes {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let inv = ray.inv_dir.to_array();
        let major = crate::geometry::major_axis(ray.dir);
        // `min` is at f32 offset 8a, `max` at 24 + 8a (`Node8` is `repr(C)`).
        let neg = |a: usize| inv[a].is_sign_negative();
        let w = WIDTH;
        Lanes {
            enter: std::array::from_fn(|a| if neg(a) { 3 * w + w * a } else { w * a }),
            exit: std::array::from_fn(|a| if neg(a) { w * a } else { 3 * w + w * a }),
            org: ray.origin.to_array(),
            inv,
            major,
        }
    }

    #[inline(always)]
    fn test<const K: u8>(&self, node: &Node8, t_far: f32) -> Tested {
        #[cfg(target_arch = "x86_64")]
        {
            if K == AVX2 {
                // SAFETY: `AVX2` is only instantiated inside `intersect_avx2`/`occluded_avx2`, which are
                // called only when the processor has AVX2.
                return unsafe { self.test_avx2(node, t_far) };
            }
            if K == SSE {
                return self.test_sse(node, t_far);
            }
        }
        self.test_scalar(node, t_far)
    }

    /// The eight lanes in one AVX register per row.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    unsafe fn test_avx2(&self, node: &Node8, t_far: f32) -> Tested {
        use std::arch::x86_64::*;
        let base = (node as *const Node8).cast::<f32>();
        let mut near_out = [0.0f32; WIDTH];
        let mut slack_out = [0.0f32; WIDTH];
        // Every offset is below 48 floats, inside the 256-byte node, and a multiple of 8 floats from
        // its 64-byte aligned start, as `_mm256_load_ps` requires; the stores go to local arrays.
        let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        let mut near = _mm256_setzero_ps();
        let mut far = _mm256_set1_ps(t_far);
        let mut scale = _mm256_setzero_ps();
        for a in 0..3 {
            let o = _mm256_set1_ps(self.org[a]);
            let inv = _mm256_set1_ps(self.inv[a]);
            let t0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(base.add(self.enter[a])), o), inv);
            let t1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(base.add(self.exit[a])), o), inv);
            // The second operand is returned when either is NaN: the accumulator wins, as in
            // `f32::max`.
            near = _mm256_max_ps(t0, near);
            far = _mm256_min_ps(t1, far);
            if a == self.major {
                scale = _mm256_max_ps(_mm256_and_ps(t0, abs), scale);
                scale = _mm256_max_ps(_mm256_and_ps(t1, abs), scale);
            }
        }
        let slack = _mm256_mul_ps(scale, _mm256_set1_ps(BOX_SLACK));
        _mm256_storeu_ps(near_out.as_mut_ptr(), near);
        _mm256_storeu_ps(slack_out.as_mut_ptr(), slack);
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, _mm256_add_ps(far, slack))) as u32;
        (mask, near_out, slack_out)
    }

    /// The eight lanes as two SSE halves.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn test_sse(&self, node: &Node8, t_far: f32) -> Tested {
        use std::arch::x86_64::*;
        let base = (node as *const Node8).cast::<f32>();
        let mut near_out = [0.0f32; WIDTH];
        let mut slack_out = [0.0f32; WIDTH];
        let mut mask = 0;
        // SAFETY: SSE2 is part of the x86_64 baseline; every offset is below 48 floats, inside the
        // 256-byte node, and a multiple of 4 floats from its 64-byte aligned start, as `_mm_load_ps`
        // requires; the stores go to local arrays of eight floats at offsets 0 and 4.
        unsafe {
            let abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
            for half in [0, 4] {
                let mut near = _mm_setzero_ps();
                let mut far = _mm_set1_ps(t_far);
                let mut scale = _mm_setzero_ps();
                for a in 0..3 {
                    let o = _mm_set1_ps(self.org[a]);
                    let inv = _mm_set1_ps(self.inv[a]);
                    let t0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(base.add(self.enter[a] + half)), o), inv);
                    let t1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(base.add(self.exit[a] + half)), o), inv);
                    near = _mm_max_ps(t0, near);
                    far = _mm_min_ps(t1, far);
                    if a == self.major {
                        scale = _mm_max_ps(_mm_and_ps(t0, abs), scale);
                        scale = _mm_max_ps(_mm_and_ps(t1, abs), scale);
                    }
                }
                let slack = _mm_mul_ps(scale, _mm_set1_ps(BOX_SLACK));
                _mm_storeu_ps(near_out.as_mut_ptr().add(half), near);
                _mm_storeu_ps(slack_out.as_mut_ptr().add(half), slack);
                mask |= (_mm_movemask_ps(_mm_cmple_ps(near, _mm_add_ps(far, slack))) as u32) << half;
            }
        }
        (mask, near_out, slack_out)
    }

    /// The same test one lane at a time.
    #[inline(always)]
    fn test_scalar(&self, node: &Node8, t_far: f32) -> Tested {
        let flat: &[f32; 64] = float_view(node);
        let mut near_out = [0.0f32; WIDTH];
        let mut slack_out = [0.0f32; WIDTH];
        let mut mask = 0;
        for lane in 0..WIDTH {
            let (mut near, mut far, mut scale) = (0.0f32, t_far, 0.0f32);
            for a in 0..3 {
                let t0 = (flat[self.enter[a] + lane] - self.org[a]) * self.inv[a];
                let t1 = (flat[self.exit[a] + lane] - self.org[a]) * self.inv[a];
                near = near.max(t0);
                far = far.min(t1);
                if a == self.major {
                    scale = scale.max(t0.abs()).max(t1.abs());
                }
            }
            let slack = scale * BOX_SLACK;
            near_out[lane] = near;
            slack_out[lane] = slack;
            mask |= ((near <= far + slack) as u32) << lane;
        }
        (mask, near_out, slack_out)
    }
}

/// The node's floats: boxes first, then the child words reinterpreted (never read as floats).
#[inline(always)]
fn float_view(node: &Node8) -> &[f32; 64] {
    // SAFETY: `Node8` is `repr(C)`, 256 bytes of 4-byte fields, aligned to 64.
    unsafe { &*(node as *const Node8).cast::<[f32; 64]>() }
}

/// What a query does at a leaf: a mesh's leaves are blocks of four triangles tested at once, other
/// primitives are asked one by one. The traversal is compiled once per kind (see [`query`]), so the
/// mesh loop carries no call into other primitives' code.
trait Leaves {
    /// Where leaf `r`'s data starts (its first block, or its primitive indices), to prefetch it.
    fn address(&self, r: Ref) -> *const i8;
    /// Offers leaf `r`'s hits below `best.t_query` to `best`.
    fn closest<const COUNT: bool>(&self, r: Ref, q: &mut LeafRay, best: &mut Best, counts: &mut TraversalCounts);
    /// Whether leaf `r` has a hit in `(0, t_max)`.
    fn any(&self, r: Ref, q: &mut LeafRay, t_max: f32) -> bool;
}

/// The ray as leaves see it: the triangle test's part of it is computed at the first leaf (many rays,
/// such as a primary ray past the mesh, never reach one), from the major axis the box test chose.
struct LeafRay<'a> {
    ray: &'a Ray,
    major: usize,
    frame: Option<RayFrame>,
}

impl LeafRay<'_> {
    #[inline(always)]
    fn frame(&mut self) -> &RayFrame {
        let (ray, major) = (self.ray, self.major);
        self.frame.get_or_insert_with(|| {
            debug_assert_eq!(major, crate::geometry::major_axis(ray.dir));
            RayFrame::with_major(ray, major)
        })
    }
}

/// The closest hit so far; primitives are asked for hits below `t_query`, just above its `t`, to see
/// ties (kept by lowest primitive index).
struct Best {
    hit: Option<Hit>,
    t_far: f32,
    t_query: f32,
}

impl Best {
    #[inline(always)]
    fn offer(&mut self, hit: Hit) {
        if hit.beats(&self.hit) {
            self.t_far = hit.t;
            self.t_query = next_up(hit.t);
            self.hit = Some(hit);
        }
    }
}

struct MeshLeaves<'a> {
    blocks: &'a [LeafBlock],
}

impl Leaves for MeshLeaves<'_> {
    #[inline(always)]
    fn address(&self, r: Ref) -> *const i8 {
        self.blocks.as_ptr().wrapping_add(r.child as usize).cast()
    }

    #[inline(always)]
    fn closest<const COUNT: bool>(&self, r: Ref, q: &mut LeafRay, best: &mut Best, counts: &mut TraversalCounts) {
        if COUNT {
            counts.prims += r.count;
        }
        let frame = q.frame();
        for (block, lanes) in leaf_blocks(self.blocks, r) {
            let h = intersect_triangles4(frame, &block.tris, lanes, best.t_query);
            let mut m = h.mask;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                best.offer(Hit::new(block.prim[l], PrimHit::new(h.t[l], h.b1[l], h.b2[l])));
            }
        }
    }

    #[inline(always)]
    fn any(&self, r: Ref, q: &mut LeafRay, t_max: f32) -> bool {
        let frame = q.frame();
        leaf_blocks(self.blocks, r)
            .any(|(block, lanes)| intersect_triangles4(frame, &block.tris, lanes, t_max).mask != 0)
    }
}

struct PrimLeaves<'a, P: ?Sized> {
    indices: &'a [u32],
    prims: &'a P,
}

impl<P: Primitives + ?Sized> Leaves for PrimLeaves<'_, P> {
    #[inline(always)]
    fn address(&self, r: Ref) -> *const i8 {
        self.indices.as_ptr().wrapping_add(r.child as usize).cast()
    }

    #[inline(always)]
    fn closest<const COUNT: bool>(&self, r: Ref, q: &mut LeafRay, best: &mut Best, counts: &mut TraversalCounts) {
        let (first, ray) = (r.child as usize, q.ray);
        for &prim in &self.indices[first..first + r.count as usize] {
            let h = if COUNT {
                self.prims.intersect_counted(prim as usize, ray, best.t_query, counts)
            } else {
                self.prims.intersect(prim as usize, ray, best.t_query)
            };
            if let Some(h) = h {
                best.offer(Hit::new(prim, h));
            }
        }
    }

    #[inline(always)]
    fn any(&self, r: Ref, q: &mut LeafRay, t_max: f32) -> bool {
        let first = r.child as usize;
        self.indices[first..first + r.count as usize].iter().any(|&p| self.prims.occludes(p as usize, q.ray, t_max))
    }
}

/// Asks the cache for `lines` cache lines from `p`. Most of a query's stalls are the first loads of a
/// node or block: a child pushed now is fetched while its siblings are traversed. The child the query
/// goes on with is fetched too: its box test loads only its first three lines, and without the
/// prefetch the fourth (the child references) would be asked for only after that test, a second
/// trip to memory in a row (diffuse rays on the 1M mesh +10%).
#[inline(always)]
fn prefetch_lines(p: *const i8, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for k in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch never faults, whatever the address (so `p` needs no bounds check).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * k)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, lines);
}

/// Prefetches what `r` refers to: an inner node's four cache lines, or the first four of a leaf's data.
/// The address is selected without a branch: whether a child is a leaf is data that the branch
/// predictor cannot guess on incoherent rays (batches +3-10%, single queries unchanged).
#[inline(always)]
fn prefetch<L: Leaves>(nodes: &[Node8], leaves: &L, r: Ref) {
    let node = nodes.as_ptr().wrapping_add(r.child as usize).cast::<i8>();
    prefetch_lines(std::hint::select_unpredictable(r.count == 0, node, leaves.address(r)), 4);
}

/// The blocks of leaf `leaf` with the lanes to test in each (all four but in the last block).
#[inline(always)]
fn leaf_blocks(blocks: &[LeafBlock], leaf: Ref) -> impl Iterator<Item = (&LeafBlock, u32)> {
    let first = leaf.child as usize;
    let n = leaf.count as usize;
    blocks[first..first + n.div_ceil(4)].iter().enumerate().map(move |(k, b)| {
        let left = n - 4 * k;
        (b, if left >= 4 { 0b1111 } else { (1 << left) - 1 })
    })
}

/// True when no query can hit anything: invalid ray or an empty `(0, t_max)`.
#[inline]
fn trivially_misses(ray: &Ray, t_max: f32) -> bool {
    !ray.is_valid() || t_max.is_nan() || t_max <= 0.0
}

/// The closest hit in `(0, t_max)`, ties to the lowest primitive index; with `COUNT`, the wide nodes
/// visited and primitives tested are added to `counts`.
#[inline]
pub(in crate::accel::bvh) fn intersect<P: Primitives + ?Sized, const COUNT: bool>(
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    // SAFETY: `detect` gives a kernel this processor runs.
    unsafe { intersect_with::<P, COUNT>(Kernel::detect(), wide, indices, prims, ray, t_max, counts) }
}

/// [`intersect`] with the given kernel (tests compare the kernels).
///
/// # Safety
/// The processor must support `kernel` (AVX2 for [`Kernel::Avx2`]).
#[inline]
pub(in crate::accel::bvh) unsafe fn intersect_with<P: Primitives + ?Sized, const COUNT: bool>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    // SAFETY: the caller vouches for the kernel.
    unsafe { run_with(kernel, wide, indices, prims, Closest::<COUNT> { ray, t_max, counts }) }
}

/// A traversal of the tree, compiled once per kernel and kind of leaf by [`run_with`]: the three queries
/// share that dispatch.
trait Traversal {
    type Out;
    /// The answer when the tree is empty.
    fn empty(self) -> Self::Out;
    /// The traversal from `root`.
    fn run<L: Leaves, const K: u8>(self, nodes: &[Node8], leaves: &L, root: Ref) -> Self::Out;
}

/// Runs `t` with `kernel`'s node test over `wide`'s kind of leaf.
///
/// # Safety
/// The processor must support `kernel` (AVX2 for [`Kernel::Avx2`]).
#[inline]
unsafe fn run_with<P: Primitives + ?Sized, T: Traversal>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    t: T,
) -> T::Out {
    match kernel {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the caller vouches for AVX2.
        Kernel::Avx2 => unsafe { run_avx2(wide, indices, prims, t) },
        Kernel::Sse if cfg!(target_arch = "x86_64") => run_kernel::<P, T, SSE>(wide, indices, prims, t),
        _ => run_kernel::<P, T, SCALAR>(wide, indices, prims, t),
    }
}

/// The whole traversal compiled for AVX2, so that the node test inlines.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2<P: Primitives + ?Sized, T: Traversal>(wide: &Wide, indices: &[u32], prims: &P, t: T) -> T::Out {
    run_kernel::<P, T, AVX2>(wide, indices, prims, t)
}

#[inline(always)]
fn run_kernel<P: Primitives + ?Sized, T: Traversal, const K: u8>(
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    t: T,
) -> T::Out {
    let Some(root) = wide.root else { return t.empty() };
    match &wide.blocks {
        Some(blocks) => t.run::<_, K>(&wide.nodes, &MeshLeaves { blocks }, root),
        None => t.run::<_, K>(&wide.nodes, &PrimLeaves { indices, prims }, root),
    }
}

/// The closest-hit query of one ray.
struct Closest<'a, const COUNT: bool> {
    ray: &'a Ray,
    t_max: f32,
    counts: &'a mut TraversalCounts,
}

impl<const COUNT: bool> Traversal for Closest<'_, COUNT> {
    type Out = Option<Hit>;

    fn empty(self) -> Option<Hit> {
        None
    }

    #[inline(always)]
    fn run<L: Leaves, const K: u8>(self, nodes: &[Node8], leaves: &L, root: Ref) -> Option<Hit> {
        if trivially_misses(self.ray, self.t_max) {
            return None;
        }
        query::<L, COUNT, K>(nodes, leaves, root, self.ray, self.t_max, self.counts)
    }
}

/// The closest-hit traversal from `root`.
#[inline(always)]
fn query<L: Leaves, const COUNT: bool, const K: u8>(
    nodes: &[Node8],
    leaves: &L,
    root: Ref,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    let lanes = Lanes::new(ray);
    let mut q = LeafRay { ray, major: lanes.major, frame: None };
    let mut best = Best { hit: None, t_far: t_max, t_query: t_max };
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = root;
    loop {
        if cur.count == 0 {
            if COUNT {
                counts.nodes += 1;
            }
            let node = &nodes[cur.child as usize];
            if let Some(next) = visit::<L, K, false>(nodes, leaves, &lanes, node, best.t_far, &mut stack, &mut sp) {
                cur = next;
                continue;
            }
        } else {
            leaves.closest::<COUNT>(cur, &mut q, &mut best, counts);
        }
        match pop(&stack, &mut sp, best.t_far) {
            Some(next) => cur = next,
            None => return best.hit,
        }
    }
}

/// One node visit: tests `node`'s eight boxes against `[0, t_far]`, pushes every child hit but the
/// nearest (farthest deepest) and returns the nearest; `None` when no box is hit.
///
/// `MERGED` handles one and two children in one path without a branch on which. The batch takes it:
/// a mispredicted branch there throws away both rays' work in flight (batches +1-6%). A single query
/// does not: it was 3-8% slower, as the always-written entry and second prefetch lengthen its chain.
#[inline(always)]
fn visit<L: Leaves, const K: u8, const MERGED: bool>(
    nodes: &[Node8],
    leaves: &L,
    lanes: &Lanes,
    node: &Node8,
    t_far: f32,
    stack: &mut [MaybeUninit<Entry>; STACK],
    sp: &mut usize,
) -> Option<Ref> {
    let (mask, near, slack) = lanes.test::<K>(node, t_far);
    if mask == 0 {
        return None;
    }
    let first = mask.trailing_zeros() as usize;
    let rest = mask & (mask - 1);
    if !MERGED && rest == 0 {
        let cur = Ref { child: node.child[first], count: node.count[first] };
        prefetch(nodes, leaves, cur);
        return Some(cur);
    }
    if rest & rest.wrapping_sub(1) == 0 {
        // Two children, the common case: continue with the nearer, push the other. Merged, one child
        // takes this path too, without a branch: `second` is `first` and the entry written is not kept.
        let two = rest != 0;
        let second = if MERGED {
            std::hint::select_unpredictable(two, rest.trailing_zeros() as usize, first)
        } else {
            rest.trailing_zeros() as usize
        };
        let (go, push) = if near[second] < near[first] { (second, first) } else { (first, second) };
        let r = Ref { child: node.child[push], count: node.count[push] };
        stack[*sp] = MaybeUninit::new(Entry { r, near: near[push], slack: slack[push] });
        *sp += two as usize;
        prefetch(nodes, leaves, r);
        let cur = Ref { child: node.child[go], count: node.count[go] };
        prefetch(nodes, leaves, cur);
        return Some(cur);
    }
    // Three to eight children: push them all, sort the pushed entries so that the nearest is on top
    // (farthest deepest), and continue with the nearest.
    let base = *sp;
    let mut m = mask;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let e = Entry { r: Ref { child: node.child[l], count: node.count[l] }, near: near[l], slack: slack[l] };
        // Insertion by decreasing `near`.
        let mut j = *sp;
        // SAFETY: `base..sp` were written in this loop.
        while j > base && unsafe { stack[j - 1].assume_init_ref() }.near < e.near {
            stack[j] = stack[j - 1];
            j -= 1;
        }
        stack[j] = MaybeUninit::new(e);
        *sp += 1;
        prefetch(nodes, leaves, e.r);
    }
    *sp -= 1;
    // SAFETY: written just above.
    Some(unsafe { stack[*sp].assume_init() }.r)
}

/// Pops the nearest pushed child that may still hold a hit before `t_far`; `None` when none is left.
#[inline(always)]
fn pop(stack: &[MaybeUninit<Entry>; STACK], sp: &mut usize, t_far: f32) -> Option<Ref> {
    while *sp > 0 {
        *sp -= 1;
        // SAFETY: entries below `sp` were written by `visit`.
        let e = unsafe { stack[*sp].assume_init() };
        // Negated so that a NaN (which cannot arise here) would keep the entry, not drop it.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(e.near > t_far + e.slack) {
            return Some(e.r);
        }
    }
    None
}

/// Closest-hit queries for a batch of rays, `out[i]` for `rays[i]` in `(0, t_max[i])`: the same hits as
/// [`intersect`] ray by ray.
///
/// Two rays are traced at once, one node visit of each in turn (a finished ray's slot takes the
/// batch's next ray): a node visit is a chain of dependent loads and arithmetic that one ray cannot
/// overlap with its next visit, which depends on it, but the other ray's visit can fill that wait
/// (measured in docs/performance.md). The counted query and the any-hit query stay one ray at a time.
pub(in crate::accel::bvh) fn intersect_many<P: Primitives + ?Sized>(
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
) {
    // SAFETY: `detect` gives a kernel this processor runs.
    unsafe { intersect_many_with(Kernel::detect(), wide, indices, prims, rays, t_max, out) }
}

/// [`intersect_many`] with the given kernel.
///
/// # Safety
/// The processor must support `kernel` (AVX2 for [`Kernel::Avx2`]).
pub(in crate::accel::bvh) unsafe fn intersect_many_with<P: Primitives + ?Sized>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
) {
    assert!(rays.len() == t_max.len() && rays.len() == out.len(), "a batch's rays, t_max and hits differ in length");
    // SAFETY: the caller vouches for the kernel.
    unsafe { run_with(kernel, wide, indices, prims, Batch { rays, t_max, out }) }
}

/// The closest-hit queries of a batch.
struct Batch<'a> {
    rays: &'a [Ray],
    t_max: &'a [f32],
    out: &'a mut [Option<Hit>],
}

impl Traversal for Batch<'_> {
    type Out = ();

    fn empty(self) {
        self.out.fill(None);
    }

    #[inline(always)]
    fn run<L: Leaves, const K: u8>(self, nodes: &[Node8], leaves: &L, root: Ref) {
        many::<L, K>(nodes, leaves, root, self.rays, self.t_max, self.out)
    }
}

/// The interleaved closest-hit traversals of a batch, from `root`: two rays at once. (Three or four
/// at once were slower: their states no longer fit the registers. The two slots are named rather than
/// an array, 1-2% faster.)
#[inline(always)]
fn many<L: Leaves, const K: u8>(
    nodes: &[Node8],
    leaves: &L,
    root: Ref,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
) {
    let mut next = 0;
    let Some(i) = next_ray(rays, t_max, out, &mut next) else { return };
    let (mut ia, mut a) = (i, Walk::new(root, &rays[i], t_max[i]));
    let Some(i) = next_ray(rays, t_max, out, &mut next) else {
        out[ia] = a.finish::<L, K>(nodes, leaves);
        return;
    };
    let (mut ib, mut b) = (i, Walk::new(root, &rays[i], t_max[i]));
    // Both slots busy: step each in turn; a finished one takes the next ray, until none is left.
    loop {
        a.step::<L, K>(nodes, leaves);
        b.step::<L, K>(nodes, leaves);
        if a.done && !refill(&mut a, &mut ia, root, rays, t_max, out, &mut next) {
            out[ib] = b.finish::<L, K>(nodes, leaves);
            return;
        }
        if b.done && !refill(&mut b, &mut ib, root, rays, t_max, out, &mut next) {
            out[ia] = a.finish::<L, K>(nodes, leaves);
            return;
        }
    }
}

/// Hands finished walk `w`'s hit to `out[*i]` and starts it on the batch's next ray (its index into
/// `*i`); false when no ray is left.
#[inline(always)]
fn refill<'r>(
    w: &mut Walk<'r>,
    i: &mut usize,
    root: Ref,
    rays: &'r [Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
    next: &mut usize,
) -> bool {
    out[*i] = w.best.hit;
    let Some(k) = next_ray(rays, t_max, out, next) else { return false };
    *i = k;
    w.restart(root, &rays[k], t_max[k]);
    true
}

/// The index of the batch's next ray from `*next` on that needs a traversal; the rays skipped on the
/// way trivially miss and get `None`.
#[inline(always)]
fn next_ray(rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>], next: &mut usize) -> Option<usize> {
    while *next < rays.len() {
        let i = *next;
        *next += 1;
        if !trivially_misses(&rays[i], t_max[i]) {
            return Some(i);
        }
        out[i] = None;
    }
    None
}

/// One ray's closest-hit traversal as a state advanced one step at a time: a node visit, or a leaf and
/// the pops after it. [`query`] is the same traversal run to its end in one loop, which keeps its state
/// in registers.
struct Walk<'r> {
    lanes: Lanes,
    q: LeafRay<'r>,
    best: Best,
    stack: [MaybeUninit<Entry>; STACK],
    sp: usize,
    cur: Ref,
    done: bool,
}

impl<'r> Walk<'r> {
    #[inline(always)]
    fn new(root: Ref, ray: &'r Ray, t_max: f32) -> Self {
        let lanes = Lanes::new(ray);
        let major = lanes.major;
        Walk {
            lanes,
            q: LeafRay { ray, major, frame: None },
            best: Best { hit: None, t_far: t_max, t_query: t_max },
            stack: [const { MaybeUninit::<Entry>::uninit() }; STACK],
            sp: 0,
            cur: root,
            done: false,
        }
    }

    /// Starts over with another ray (in place: the stack is not moved).
    #[inline(always)]
    fn restart(&mut self, root: Ref, ray: &'r Ray, t_max: f32) {
        self.lanes = Lanes::new(ray);
        self.q = LeafRay { ray, major: self.lanes.major, frame: None };
        self.best = Best { hit: None, t_far: t_max, t_query: t_max };
        self.sp = 0;
        self.cur = root;
        self.done = false;
    }

    #[inline(always)]
    fn step<L: Leaves, const K: u8>(&mut self, nodes: &[Node8], leaves: &L) {
        if self.cur.count == 0 {
            let node = &nodes[self.cur.child as usize];
            if let Some(next) =
                visit::<L, K, true>(nodes, leaves, &self.lanes, node, self.best.t_far, &mut self.stack, &mut self.sp)
            {
                self.cur = next;
                return;
            }
        } else {
            leaves.closest::<false>(self.cur, &mut self.q, &mut self.best, &mut TraversalCounts::default());
        }
        match pop(&self.stack, &mut self.sp, self.best.t_far) {
            Some(next) => self.cur = next,
            None => self.done = true,
        }
    }

    /// Runs the traversal to its end and returns its hit.
    #[inline(always)]
    fn finish<L: Leaves, const K: u8>(&mut self, nodes: &[Node8], leaves: &L) -> Option<Hit> {
        while !self.done {
            self.step::<L, K>(nodes, leaves);
        }
        self.best.hit
    }
}

/// Whether anything is hit in `(0, t_max)`; stops at the first hit, visits children in any order.
#[inline]
pub(in crate::accel::bvh) fn occluded<P: Primitives + ?Sized>(
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
) -> bool {
    // SAFETY: `detect` gives a kernel this processor runs.
    unsafe { run_with(Kernel::detect(), wide, indices, prims, AnyHit { ray, t_max }) }
}

/// The any-hit query of one ray.
struct AnyHit<'a> {
    ray: &'a Ray,
    t_max: f32,
}

impl Traversal for AnyHit<'_> {
    type Out = bool;

    fn empty(self) -> bool {
        false
    }

    #[inline(always)]
    fn run<L: Leaves, const K: u8>(self, nodes: &[Node8], leaves: &L, root: Ref) -> bool {
        !trivially_misses(self.ray, self.t_max) && any_hit::<L, K>(nodes, leaves, root, self.ray, self.t_max)
    }
}

/// The any-hit traversal from `root`.
#[inline(always)]
fn any_hit<L: Leaves, const K: u8>(nodes: &[Node8], leaves: &L, root: Ref, ray: &Ray, t_max: f32) -> bool {
    let lanes = Lanes::new(ray);
    let mut q = LeafRay { ray, major: lanes.major, frame: None };
    let mut stack = [const { MaybeUninit::<Ref>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = root;
    loop {
        if cur.count == 0 {
            let node = &nodes[cur.child as usize];
            let (mut mask, _, _) = lanes.test::<K>(node, t_max);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                while mask != 0 {
                    let l = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack[sp] = MaybeUninit::new(Ref { child: node.child[l], count: node.count[l] });
                    sp += 1;
                }
                cur = Ref { child: node.child[first], count: node.count[first] };
                continue;
            }
        } else if leaves.any(cur, &mut q, t_max) {
            return true;
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        // SAFETY: entries below `sp` were written by the pushes above.
        cur = unsafe { stack[sp].assume_init() };
    }
}
