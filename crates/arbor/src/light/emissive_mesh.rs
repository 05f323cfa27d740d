//! Emissive meshes (`LightMesh`, CENG 795 hw6): a mesh object that also emits `radiance` from the front
//! side of its triangles (the counter-clockwise side, the side its geometric normal points to).
//!
//! Sampling is uniform by area over the whole mesh in world space (after the object's transform): a
//! triangle is picked from the cumulative table of the triangles' world areas, then a point uniformly in
//! it (Pharr, Jakob and Humphreys, *Physically Based Rendering*, 3rd ed., section 13.6.5), so the area
//! density is `1 / A` and the solid-angle density at a receiver `d² / (A |cos θ_l|)`. [`Light::pdf`]
//! traces the direction through the mesh's own structure and uses the first point it meets: the only
//! point of the mesh a ray from the receiver can see that way. A sampled point on the back of a triangle
//! emits nothing and gives no sample. The mesh is where it is at time 0 (motion is not sampled).
//!
//! Power: `π L A`, a one-sided Lambertian emitter of area `A`.

use std::sync::Arc;

use super::{Light, LightSample};
use crate::accel::Hit;
use crate::geometry::TriangleMesh;
use crate::math::{Color, Ray, Transform, Vec2, Vec3};
use crate::tonemap::luminance;

/// The geometry a mesh light samples and traces: object-space triangles under a structure (the scene's
/// own mesh, shared).
pub trait EmitterMesh: Send + Sync {
    /// The triangles, object space.
    fn mesh(&self) -> &TriangleMesh;
    /// The closest hit of an object-space ray (`prim` the triangle).
    fn intersect(&self, ray: &Ray) -> Option<Hit>;
}

/// Lights of at most this many triangles find a sample's triangle by counting, not by binary search.
const LINEAR_SEARCH: usize = 32;

/// A mesh light.
pub struct EmissiveMesh {
    /// Emitted radiance (scene units), the same in every direction of the front side.
    pub radiance: Color,
    /// The object the light is, in scene-file order.
    pub object: u32,
    shape: Arc<dyn EmitterMesh>,
    transform: Option<Transform>,
    /// Cumulative world-space triangle areas, from 0; the last entry is the total area.
    cdf: Vec<f32>,
    /// Each triangle's world-space corners and unit normal on its emitting side, as a sample reads them.
    tris: Vec<([Vec3; 3], Vec3)>,
    /// `1 / area`, the density per unit area.
    area_pdf: f32,
}

impl std::fmt::Debug for EmissiveMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EmissiveMesh")
            .field("radiance", &self.radiance)
            .field("object", &self.object)
            .field("triangles", &self.shape.mesh().len())
            .field("area", &self.area())
            .finish()
    }
}

impl EmissiveMesh {
    /// The light of object `object`, the mesh `shape` placed in the world by `transform`; `None` when
    /// the mesh has no area (nothing to sample).
    pub fn new(
        shape: Arc<dyn EmitterMesh>,
        transform: Option<Transform>,
        radiance: Color,
        object: u32,
    ) -> Option<Self> {
        let mut light =
            EmissiveMesh { radiance, object, shape, transform, cdf: vec![0.0], tris: Vec::new(), area_pdf: 0.0 };
        let mut total = 0.0f64;
        for i in 0..light.shape.mesh().len() {
            let [a, b, c] = light.world_triangle(i);
            total += 0.5 * (b - a).cross(c - a).length() as f64;
            light.cdf.push(total as f32);
            light.tris.push(([a, b, c], light.normal([a, b, c])));
        }
        light.area_pdf = 1.0 / light.area();
        (total > 0.0 && total.is_finite()).then_some(light)
    }

    /// Total world-space area.
    pub fn area(&self) -> f32 {
        self.cdf[self.cdf.len() - 1]
    }

    /// The unit normal of the world triangle `[a, b, c]` on its emitting side: the side its object-space
    /// normal is carried to (a mirroring transform reverses the winding, not the side).
    fn normal(&self, [a, b, c]: [Vec3; 3]) -> Vec3 {
        let n = (b - a).cross(c - a).normalize_or_zero();
        if self.transform.is_some_and(|t| t.flips_handedness()) {
            -n
        } else {
            n
        }
    }

    fn world_triangle(&self, i: usize) -> [Vec3; 3] {
        let tri = self.shape.mesh().triangle(i);
        match &self.transform {
            None => tri,
            Some(t) => tri.map(|p| t.point(p)),
        }
    }

    /// The solid-angle density of the point `q` of a triangle of unit normal `n` seen from `p`, and the
    /// unit direction and distance to it; `None` when `q` faces away or coincides with `p`.
    fn towards(&self, p: Vec3, q: Vec3, n: Vec3) -> Option<(Vec3, f32, f32)> {
        super::towards_area_point(p, q, n, self.area_pdf)
    }
}

impl Light for EmissiveMesh {
    fn sample(&self, p: Vec3, _n: Vec3, u: Vec2) -> Option<LightSample> {
        let area = self.area();
        let x = u.x * area;
        // The first triangle whose upper end exceeds x: never one of zero area. The upper ends are
        // sorted, so that is how many of them are at most x; a small light counts them without the
        // binary search's unpredictable branches.
        let ends = &self.cdf[1..];
        let below = if ends.len() <= LINEAR_SEARCH {
            ends.iter().filter(|&&c| c <= x).count()
        } else {
            ends.partition_point(|&c| c <= x)
        };
        let i = below.min(self.cdf.len() - 2);
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let ux = if hi > lo { ((x - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.5 };
        let ([a, b, c], n) = self.tris[i];
        // Uniform on the triangle: barycentrics (1 - √ux, uy √ux).
        let s = ux.sqrt();
        let (b1, b2) = (1.0 - s, u.y * s);
        let q = b1 * a + b2 * b + (1.0 - b1 - b2) * c;
        let (wi, dist, pdf) = self.towards(p, q, n)?;
        Some(LightSample { wi, dist, irradiance: self.radiance / pdf, pdf })
    }

    fn pdf(&self, p: Vec3, wi: Vec3) -> f32 {
        let ray = match &self.transform {
            None => Ray::new(p, wi),
            Some(t) => Ray::new(t.inv.transform_point3(p), t.inv.transform_vector3(wi)),
        };
        let Some(hit) = self.shape.intersect(&ray) else { return 0.0 };
        let n = self.tris[hit.prim as usize].1;
        self.towards(p, p + hit.t * wi, n).map_or(0.0, |(_, _, pdf)| pdf)
    }

    fn power(&self) -> f32 {
        std::f32::consts::PI * luminance(self.radiance) * self.area()
    }

    fn object(&self) -> Option<u32> {
        Some(self.object)
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::{PI, TAU};

    use super::*;
    use crate::accel::AccelConfig;
    use crate::scene::MeshShape;

    /// A square of side `s` centred above the origin at height `h`, facing down.
    fn square(s: f32, h: f32, transform: Option<Transform>) -> EmissiveMesh {
        let k = s / 2.0;
        let mesh = TriangleMesh {
            positions: vec![Vec3::new(-k, h, -k), Vec3::new(k, h, -k), Vec3::new(k, h, k), Vec3::new(-k, h, k)],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..TriangleMesh::default()
        };
        assert_eq!(mesh.len(), 2);
        let accel = AccelConfig::default().build_accel(&mesh).unwrap();
        EmissiveMesh::new(Arc::new(MeshShape { mesh, accel }), transform, Color::splat(3.0), 4).unwrap()
    }

    fn grid(k: usize) -> impl Iterator<Item = Vec2> {
        (0..k * k).map(move |i| Vec2::new(((i % k) as f32 + 0.5) / k as f32, ((i / k) as f32 + 0.5) / k as f32))
    }

    #[test]
    fn emissive_mesh_irradiance_of_a_square_matches_the_analytic_value() {
        // A point under the centre of a square of side s at height h, facing it: four rectangles of
        // sides a = b = s/2 with a corner above the point, each of form factor (Howell's catalogue B-3)
        // F = (X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))) / 2π, X = a/h, Y = b/h;
        // E = π L · 4F.
        let (s, h) = (1.0f32, 2.0f32);
        let l = square(s, h, None);
        let k = 64;
        let e: f64 = grid(k)
            .filter_map(|u| l.sample(Vec3::ZERO, Vec3::Y, u))
            .map(|x| (x.irradiance.x * x.wi.y.max(0.0)) as f64)
            .sum::<f64>()
            / (k * k) as f64;
        let (x, y) = (0.5 / h as f64, 0.5 / h as f64);
        let (rx, ry) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        let form = 4.0 * (x / rx * (y / rx).atan() + y / ry * (x / ry).atan()) / (2.0 * std::f64::consts::PI);
        let exact = 3.0 * std::f64::consts::PI * form;
        assert!((e / exact - 1.0).abs() < 2e-3, "{e} vs {exact}");
        assert!((l.power() - PI * 3.0 * 1.0).abs() < 1e-4);
    }

    #[test]
    fn emissive_mesh_pdf_integrates_to_one_and_matches_its_samples() {
        let t = Transform::rotate(20.0, Vec3::X).unwrap().then(&Transform::translate(Vec3::new(0.2, 0.0, 0.1)));
        for transform in [None, Some(t)] {
            let l = square(1.0, 1.0, transform);
            let p = Vec3::new(0.1, -0.2, 0.05);
            let k = 800;
            let total: f64 = grid(k)
                .map(|u| {
                    let z = 1.0 - 2.0 * u.x;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    l.pdf(p, Vec3::new(r * (TAU * u.y).cos(), z, r * (TAU * u.y).sin())) as f64
                })
                .sum::<f64>()
                * 4.0
                * std::f64::consts::PI
                / (k * k) as f64;
            assert!((total - 1.0).abs() < 0.01, "∫ pdf = {total}");
            for u in grid(10) {
                let s = l.sample(p, Vec3::Y, u).unwrap();
                assert!((l.pdf(p, s.wi) / s.pdf - 1.0).abs() < 1e-3);
            }
            // Seen from above (its back) the square gives nothing.
            assert!(l.sample(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y, Vec2::splat(0.5)).is_none());
            assert_eq!(l.pdf(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y), 0.0);
        }
    }
}
