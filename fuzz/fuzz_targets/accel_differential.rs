//! Every acceleration structure against brute force on fuzzed triangles and rays.
//!
//! The bytes are read as a small scene (see [`Input`]): up to 16 vertices, up to 32 triangles over them
//! (so shared edges, duplicates and degenerate triangles are common), and up to 16 rays with their
//! `t_max`. Coordinates are mostly small multiples of 1/4 (exact hits on edges and vertices), sometimes
//! any f32 at all (NaN, infinities, huge, subnormal). Every kind of `AccelKind::ALL` is built with its
//! default parameters (and validated: this target is built with debug assertions) and must answer
//! exactly as brute force does: the same `Option`, the same primitive, the same `t` bits, the same
//! `occluded`; and for a hit at `t`, `occluded` at `t` must be false. The rays traced as one batch
//! (`intersect_many`) must each get the hit of their own query.
//!
//! With `ARBOR_FUZZ_T_ABOVE=1` it also asks that `occluded` just above a hit's `t` be true. That check
//! was off by default while a bug of `intersect_triangle` broke it (now fixed: the regression test
//! `fuzz_triangle_hit_below_t_max_is_reported_at_t_max` in crates/arbor/tests/fuzz_regressions.rs);
//! the runs recorded in docs/robustness.md since then have it on.

#![no_main]

use arbor::accel::{build, AccelKind, Hit};
use arbor::geometry::TriangleMesh;
use arbor::math::{Ray, Vec3};
use libfuzzer_sys::fuzz_target;

/// A cursor over the input that yields zeros once the bytes run out.
struct Input<'a>(&'a [u8]);

impl Input<'_> {
    fn byte(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }
    /// One coordinate: bytes below 0xF0 are the small grid value (b - 120) / 4; 0xF0..=0xFF are
    /// followed by any 4-byte f32 (little-endian).
    fn coord(&mut self) -> f32 {
        let b = self.byte();
        if b < 0xF0 {
            (f32::from(b) - 120.0) / 4.0
        } else {
            f32::from_le_bytes([self.byte(), self.byte(), self.byte(), self.byte()])
        }
    }
    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.coord(), self.coord(), self.coord())
    }
    /// `t_max`: infinity, a grid value, or any f32 (through [`Input::coord`]).
    fn t_max(&mut self) -> f32 {
        match self.byte() % 4 {
            0 | 1 => f32::INFINITY,
            _ => self.coord(),
        }
    }
}

static T_ABOVE: std::sync::LazyLock<bool> =
    std::sync::LazyLock::new(|| std::env::var_os("ARBOR_FUZZ_T_ABOVE").is_some_and(|v| v == "1"));

/// A hit as bits, so that two identical hits compare equal even with a NaN in them.
fn bits(h: &Option<Hit>) -> Option<(u32, u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits(), h.sub))
}

fn same_hit(a: &Option<Hit>, b: &Option<Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.prim == b.prim && a.t.to_bits() == b.t.to_bits(),
        _ => false,
    }
}

fuzz_target!(|data: &[u8]| {
    let t_above_check = *T_ABOVE;
    let mut input = Input(data);
    let head = input.byte();
    let n_verts = 3 + usize::from(head % 14);
    let n_tris = 1 + usize::from(input.byte() % 32);
    let n_rays = 1 + usize::from(input.byte() % 16);
    let positions: Vec<Vec3> = (0..n_verts).map(|_| input.vec3()).collect();
    let indices: Vec<[u32; 3]> =
        (0..n_tris).map(|_| [0; 3].map(|_: u32| u32::from(input.byte()) % n_verts as u32)).collect();
    let mesh = TriangleMesh { positions, indices, ..Default::default() };
    let rays: Vec<(Ray, f32)> = (0..n_rays)
        .map(|_| {
            let flags = input.byte();
            let origin = input.vec3();
            let mut dir = input.vec3();
            if flags & 1 != 0 {
                // Aim at a vertex: rays through shared vertices and along edges.
                dir = mesh.positions[usize::from(flags >> 1) % n_verts] - origin;
            }
            (Ray::new(origin, dir).with_culling(flags & 0x80 != 0), input.t_max())
        })
        .collect();

    let brute = build(AccelKind::Brute, &mesh);
    let expected: Vec<(Option<Hit>, bool)> =
        rays.iter().map(|(r, t)| (brute.intersect(&mesh, r, *t), brute.occluded(&mesh, r, *t))).collect();
    for &kind in AccelKind::ALL {
        let accel = build(kind, &mesh);
        for ((ray, t_max), (hit, occluded)) in rays.iter().zip(&expected) {
            let got = accel.intersect(&mesh, ray, *t_max);
            assert!(same_hit(&got, hit), "{kind}: {ray:?} t_max {t_max}: hit {got:?}, brute force {hit:?}");
            let got = accel.occluded(&mesh, ray, *t_max);
            assert_eq!(got, *occluded, "{kind}: {ray:?} t_max {t_max}: occluded {got}, brute force {occluded}");
            if let Some(h) = hit {
                assert!(!accel.occluded(&mesh, ray, h.t), "{kind}: {ray:?}: occluded at the hit t {}", h.t);
                let above = f32::from_bits(h.t.to_bits() + 1);
                if t_above_check {
                    assert!(accel.occluded(&mesh, ray, above), "{kind}: {ray:?}: not occluded above the hit t {}", h.t);
                }
            }
        }
        // All the rays as one batch: each must get the hit of its own query.
        let (batch, t_max): (Vec<Ray>, Vec<f32>) = rays.iter().copied().unzip();
        let mut got = vec![None; rays.len()];
        accel.intersect_many(&mesh, &batch, &t_max, &mut got);
        for (k, ((ray, t), g)) in rays.iter().zip(&got).enumerate() {
            let own = accel.intersect(&mesh, ray, *t);
            assert_eq!(bits(g), bits(&own), "{kind}: batch ray {k} {ray:?} t_max {t}: {g:?}, own query {own:?}");
        }
    }
});
