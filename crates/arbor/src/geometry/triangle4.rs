//! TEMPORARY scalar stand-in for the 4-wide triangle test (replaced by the SIMD version on merge).

use super::{intersect_triangle_in, RayFrame};
use crate::math::Vec3;

/// Four triangles' corners as structure-of-arrays lanes: `v[corner][axis][lane]`.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
pub struct Tri4 {
    /// Corners.
    pub v: [[[f32; 4]; 3]; 3],
}

impl Tri4 {
    /// Up to four triangles; missing lanes repeat the last one.
    pub fn new(tris: &[[Vec3; 3]]) -> Tri4 {
        assert!(!tris.is_empty() && tris.len() <= 4);
        let mut v = [[[0.0; 4]; 3]; 3];
        for l in 0..4 {
            let t = tris[l.min(tris.len() - 1)];
            for c in 0..3 {
                for a in 0..3 {
                    v[c][a][l] = t[c][a];
                }
            }
        }
        Tri4 { v }
    }

    /// Lane `l`'s corners.
    pub fn lane(&self, l: usize) -> [Vec3; 3] {
        std::array::from_fn(|c| Vec3::new(self.v[c][0][l], self.v[c][1][l], self.v[c][2][l]))
    }
}

/// Which lanes hit, and their hits.
#[derive(Debug, Clone, Copy)]
pub struct Tri4Hits {
    /// Bit per hit lane.
    pub mask: u32,
    /// Distances.
    pub t: [f32; 4],
    /// Weights of corner 1.
    pub b1: [f32; 4],
    /// Weights of corner 2.
    pub b2: [f32; 4],
}

/// The hits of the frame's ray with the lanes of `tris` selected by `lanes`.
#[inline(always)]
pub fn intersect_triangles4(f: &RayFrame, tris: &Tri4, lanes: u32, t_max: f32) -> Tri4Hits {
    let mut out = Tri4Hits { mask: 0, t: [0.0; 4], b1: [0.0; 4], b2: [0.0; 4] };
    for l in 0..4 {
        if lanes & (1 << l) != 0 {
            let [a, b, c] = tris.lane(l);
            if let Some(h) = intersect_triangle_in(f, a, b, c, t_max) {
                out.mask |= 1 << l;
                out.t[l] = h.t;
                out.b1[l] = h.b1;
                out.b2[l] = h.b2;
            }
        }
    }
    out
}
