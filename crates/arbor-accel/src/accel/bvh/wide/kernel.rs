//! The node test: one ray against a wide node's eight boxes at once, in four kernels that compute the
//! same per-lane arithmetic (so they visit the same nodes; a unit test compares them).
//!
//! Hand-written SIMD (`std::arch`) because this test is the hot core of every query: the eight slab
//! tests share the ray's broadcast origin and reciprocal direction, and the per-axis choice of the entry
//! plane is precomputed as load offsets, so a node test is about 20 instructions without branches.
//! - [`Avx2`]: the eight lanes in one register per row. Its value is the proof that the processor runs
//!   AVX2: the only constructor, [`Avx2::detect`], asks the processor, and every path into AVX2 code
//!   takes that value, so no safe function can run AVX2 instructions on a processor without them.
//! - [`Avx512`]: the same arithmetic as [`Avx2`] in the same order, compiled for AVX-512 (F and VL) so
//!   that the comparison writes a mask register (no movemask) and the ray's broadcasts fold into the
//!   arithmetic as embedded broadcasts; its token, as [`Avx2`]'s, only [`Avx512::detect`] makes.
//! - [`Sse`]: two 4-lane halves (SSE2 is part of the x86_64 baseline, so any value will do).
//! - [`Scalar`]: a loop over the lanes (elsewhere than x86_64, and under Miri).
//!
//! The box test is the conservative test of the binary traversal (`../traverse.rs`), lane by lane:
//! `near <= far + scale * SLACK` with `scale` the larger slab distance on the ray's major axis; `max`
//! and `min` take the accumulator as the operand that wins over a NaN, as `f32::max`/`min` do. The
//! major axis' slab distances are never NaN (a finite box or origin minus the other is never NaN, and
//! the axis' reciprocal is finite and not zero: [`Ray::new`] flushes subnormal components, so the
//! largest one is normal), so `scale` is one `max` of the two, with no accumulator to guard: the
//! shortest chain for the slack, which the node's mask waits on.

use super::{Node8, WIDTH};
use crate::accel::BOX_SLACK;
use crate::math::Ray;

/// Proof that this processor runs AVX2; only [`Avx2::detect`] makes one.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Avx2 {
    _detected: (),
}

#[cfg(target_arch = "x86_64")]
impl Avx2 {
    /// The token when the processor runs AVX2, else `None`.
    #[inline]
    pub fn detect() -> Option<Avx2> {
        // Miri does not run the AVX2 kernel: it is left to native tests.
        (!cfg!(miri) && std::is_x86_feature_detected!("avx2")).then_some(Avx2 { _detected: () })
    }
}

/// Proof that this processor runs AVX-512 F and VL (and so AVX2); only [`Avx512::detect`] makes one.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Avx512 {
    _detected: (),
}

#[cfg(target_arch = "x86_64")]
impl Avx512 {
    /// The token when the processor runs AVX-512 F and VL, else `None`.
    #[inline]
    pub fn detect() -> Option<Avx512> {
        // Miri does not run AVX-512 code: it is left to native tests.
        (!cfg!(miri) && std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512vl"))
            .then_some(Avx512 { _detected: () })
    }
}

/// The variable that caps the kernel below the processor's best, to measure Arbor as it runs on an older
/// processor (as oneDNN's `ONEDNN_MAX_CPU_ISA` does): `avx2`, `sse`, or `avx512` (no cap, as unset or
/// empty). Only the node-test kernels use wider instructions than the x86_64 baseline, so under `avx2`
/// the whole program runs as on an AVX2-only processor.
pub const MAX_ISA_VAR: &str = "ARBOR_MAX_ISA";

/// The instruction sets [`MAX_ISA_VAR`] can cap the kernel at, lowest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Isa {
    /// The x86_64 baseline: the two-halves SSE2 kernel.
    Sse,
    /// The AVX2 kernel at most.
    Avx2,
    /// The AVX-512 kernel at most: no cap.
    Avx512,
}

impl Isa {
    /// The cap [`MAX_ISA_VAR`] sets (`None` when unset or empty), or the error that names its value
    /// when it names no instruction set. The kernel's detection reads it once, and takes an unknown
    /// value as no cap: programs check it first (`arbor` refuses to start).
    pub fn cap_from_env() -> Result<Option<Isa>, String> {
        let Some(value) = std::env::var_os(MAX_ISA_VAR) else { return Ok(None) };
        match value.to_str() {
            Some("") => Ok(None),
            Some("avx512") => Ok(Some(Isa::Avx512)),
            Some("avx2") => Ok(Some(Isa::Avx2)),
            Some("sse") => Ok(Some(Isa::Sse)),
            _ => Err(format!("{MAX_ISA_VAR}={:?}: expected avx512, avx2 or sse", value.to_string_lossy())),
        }
    }
}

/// The two-halves kernel (SSE2, the x86_64 baseline).
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sse;

/// The lane-by-lane kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scalar;

/// The code that tests a node's boxes, as a value: the kernels a query may run on this processor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// The AVX2 kernel's arithmetic compiled for AVX-512 F and VL (mask compare, embedded broadcasts).
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512),
    /// One 8-lane AVX2 register per axis and side.
    #[cfg(target_arch = "x86_64")]
    Avx2(Avx2),
    /// Two 4-lane SSE halves.
    #[cfg(target_arch = "x86_64")]
    Sse,
    /// A loop over the lanes (used on x86_64 only by tests: the kernel comparison and Miri).
    #[cfg_attr(all(target_arch = "x86_64", not(test)), allow(dead_code))]
    Scalar,
}

impl Kernel {
    /// The fastest kernel this processor runs, up to the cap of [`MAX_ISA_VAR`] (the scalar one under
    /// Miri).
    #[inline]
    pub fn detect() -> Kernel {
        #[cfg(all(target_arch = "x86_64", not(miri)))]
        {
            // Read once: every query asks, and then costs a load and a comparison.
            static CAP: std::sync::OnceLock<Isa> = std::sync::OnceLock::new();
            let cap = *CAP.get_or_init(|| Isa::cap_from_env().ok().flatten().unwrap_or(Isa::Avx512));
            if let Some(avx512) = Avx512::detect().filter(|_| cap >= Isa::Avx512) {
                return Kernel::Avx512(avx512);
            }
            match Avx2::detect().filter(|_| cap >= Isa::Avx2) {
                Some(avx2) => Kernel::Avx2(avx2),
                None => Kernel::Sse,
            }
        }
        #[cfg(any(not(target_arch = "x86_64"), miri))]
        Kernel::Scalar
    }

    /// The kernel's name, as benchmarks report it: `avx512`, `avx2`, `sse` or `scalar`.
    pub fn name(self) -> &'static str {
        match self {
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512(_) => "avx512",
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2(_) => "avx2",
            #[cfg(target_arch = "x86_64")]
            Kernel::Sse => "sse",
            Kernel::Scalar => "scalar",
        }
    }
}

/// What a node test returns: the lanes whose box the ray meets in `[0, t_far]` (bit per lane), their
/// entry distances and their slacks.
pub(super) type Tested = (u32, [f32; WIDTH], [f32; WIDTH]);

/// A node-test kernel. Implemented by zero-sized values, so a traversal generic over it is compiled once
/// per kernel with the test inlined, and carries the value along at no cost.
pub(super) trait NodeTest: Copy {
    /// The lanes of `node` that `lanes`' ray meets in `[0, t_far]`.
    fn test(self, lanes: &Lanes, node: &Node8, t_far: f32) -> Tested;
}

/// A ray prepared for eight-box tests: per axis, where the entry and exit planes are in a node (as `f32`
/// offsets into it), the broadcast origin and reciprocal direction; and the major axis (the
/// direction's largest component), whose slab distances size the box slack and which the triangle
/// test's frame shears along. The axes stay in their natural order: the per-query setup is on every
/// query's critical path, and permuting it there costs more than asking which axis is major per node.
pub(super) struct Lanes {
    enter: [usize; 3],
    exit: [usize; 3],
    org: [f32; 3],
    inv: [f32; 3],
    pub(super) major: usize,
}

impl Lanes {
    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> Self {
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
}

/// The node's floats: boxes first, then the child words reinterpreted (never read as floats).
#[inline(always)]
fn float_view(node: &Node8) -> &[f32; 64] {
    bytemuck::cast_ref(node)
}

#[cfg(target_arch = "x86_64")]
impl NodeTest for Avx2 {
    #[inline(always)]
    fn test(self, lanes: &Lanes, node: &Node8, t_far: f32) -> Tested {
        // SAFETY: `self` exists, so `Avx2::detect` found AVX2 on this processor.
        unsafe { test_avx2(lanes, node, t_far) }
    }
}

/// The eight slab tests of [`test_avx2`] and [`test_avx512`], one AVX register per row, written once
/// and expanded inside each (intrinsics inline only into a function compiled for their features):
/// evaluates to the entry distances, the exit bound they are compared with (`far + slack`), and both
/// entry distances and slacks as arrays.
#[cfg(target_arch = "x86_64")]
macro_rules! slabs_avx {
    ($lanes:expr, $node:expr, $t_far:expr) => {{
        let (lanes, node, t_far): (&Lanes, &Node8, f32) = ($lanes, $node, $t_far);
        let base = float_view(node).as_ptr();
        let mut near_out = [0.0f32; WIDTH];
        let mut slack_out = [0.0f32; WIDTH];
        let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        let mut near = _mm256_setzero_ps();
        let mut far = _mm256_set1_ps(t_far);
        let mut scale = _mm256_setzero_ps();
        for a in 0..3 {
            let o = _mm256_set1_ps(lanes.org[a]);
            let inv = _mm256_set1_ps(lanes.inv[a]);
            // SAFETY: `enter` and `exit` are below 48 and multiples of 8 (`Lanes::new`), so each load
            // reads eight floats of the 64 of `node`, 32-byte aligned as `_mm256_load_ps` requires
            // (`Node8` is aligned to 64).
            let e0 = unsafe { _mm256_load_ps(base.add(lanes.enter[a])) };
            // SAFETY: as above.
            let e1 = unsafe { _mm256_load_ps(base.add(lanes.exit[a])) };
            let t0 = _mm256_mul_ps(_mm256_sub_ps(e0, o), inv);
            let t1 = _mm256_mul_ps(_mm256_sub_ps(e1, o), inv);
            // The second operand is returned when either is NaN: the accumulator wins, as in `f32::max`.
            near = _mm256_max_ps(t0, near);
            far = _mm256_min_ps(t1, far);
            if a == lanes.major {
                scale = _mm256_max_ps(_mm256_and_ps(t0, abs), _mm256_and_ps(t1, abs));
            }
        }
        let slack = _mm256_mul_ps(scale, _mm256_set1_ps(BOX_SLACK));
        // SAFETY: each store writes eight floats into a local array of eight.
        unsafe {
            _mm256_storeu_ps(near_out.as_mut_ptr(), near);
            _mm256_storeu_ps(slack_out.as_mut_ptr(), slack);
        }
        (near, _mm256_add_ps(far, slack), near_out, slack_out)
    }};
}

/// The eight lanes in one AVX register per row.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn test_avx2(lanes: &Lanes, node: &Node8, t_far: f32) -> Tested {
    use std::arch::x86_64::*;
    let (near, bound, near_out, slack_out) = slabs_avx!(lanes, node, t_far);
    let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, bound)) as u32;
    (mask, near_out, slack_out)
}

#[cfg(target_arch = "x86_64")]
impl NodeTest for Avx512 {
    #[inline(always)]
    fn test(self, lanes: &Lanes, node: &Node8, t_far: f32) -> Tested {
        // SAFETY: `self` exists, so `Avx512::detect` found AVX-512 F and VL on this processor.
        unsafe { test_avx512(lanes, node, t_far) }
    }
}

/// [`test_avx2`]'s operations in its order (so its results bit for bit), the comparison into a mask
/// register.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
fn test_avx512(lanes: &Lanes, node: &Node8, t_far: f32) -> Tested {
    use std::arch::x86_64::*;
    let (near, bound, near_out, slack_out) = slabs_avx!(lanes, node, t_far);
    let mask = _mm256_cmp_ps_mask::<_CMP_LE_OQ>(near, bound) as u32;
    (mask, near_out, slack_out)
}

#[cfg(target_arch = "x86_64")]
impl NodeTest for Sse {
    /// The eight lanes as two SSE halves.
    #[inline(always)]
    fn test(self, lanes: &Lanes, node: &Node8, t_far: f32) -> Tested {
        use std::arch::x86_64::*;
        let base = float_view(node).as_ptr();
        let mut near_out = [0.0f32; WIDTH];
        let mut slack_out = [0.0f32; WIDTH];
        let mut mask = 0;
        // SAFETY: SSE and SSE2 are part of the x86_64 baseline; `enter + half` and `exit + half` are
        // below 52 and multiples of 4 (`Lanes::new`), so each load reads four floats of the 64 of
        // `node`, 16-byte aligned as `_mm_load_ps` requires (`Node8` is aligned to 64); each store
        // writes four floats at offset 0 or 4 of a local array of eight.
        unsafe {
            let abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
            for half in [0, 4] {
                let mut near = _mm_setzero_ps();
                let mut far = _mm_set1_ps(t_far);
                let mut scale = _mm_setzero_ps();
                for a in 0..3 {
                    let o = _mm_set1_ps(lanes.org[a]);
                    let inv = _mm_set1_ps(lanes.inv[a]);
                    let t0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(base.add(lanes.enter[a] + half)), o), inv);
                    let t1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(base.add(lanes.exit[a] + half)), o), inv);
                    near = _mm_max_ps(t0, near);
                    far = _mm_min_ps(t1, far);
                    if a == lanes.major {
                        scale = _mm_max_ps(_mm_and_ps(t0, abs), _mm_and_ps(t1, abs));
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
}

impl NodeTest for Scalar {
    /// The same test one lane at a time.
    #[inline(always)]
    fn test(self, lanes: &Lanes, node: &Node8, t_far: f32) -> Tested {
        let mut near_out = [0.0f32; WIDTH];
        let mut slack_out = [0.0f32; WIDTH];
        let mut mask = 0;
        for lane in 0..WIDTH {
            let (hit, near, slack) = lane_test(lanes, node, lane, t_far);
            near_out[lane] = near;
            slack_out[lane] = slack;
            mask |= (hit as u32) << lane;
        }
        (mask, near_out, slack_out)
    }
}

/// One lane of the node test: whether `lanes`' ray meets the box of `node`'s lane `lane` in
/// `[0, t_far]`, its entry distance and its slack; the arithmetic of every kernel, lane by lane.
#[inline(always)]
pub(super) fn lane_test(lanes: &Lanes, node: &Node8, lane: usize, t_far: f32) -> (bool, f32, f32) {
    let flat = float_view(node);
    let (mut near, mut far, mut scale) = (0.0f32, t_far, 0.0f32);
    for a in 0..3 {
        let t0 = (flat[lanes.enter[a] + lane] - lanes.org[a]) * lanes.inv[a];
        let t1 = (flat[lanes.exit[a] + lane] - lanes.org[a]) * lanes.inv[a];
        near = near.max(t0);
        far = far.min(t1);
        if a == lanes.major {
            scale = t0.abs().max(t1.abs());
        }
    }
    let slack = scale * BOX_SLACK;
    (near <= far + slack, near, slack)
}
