//! The course camera at render time: an eye, an orthonormal frame from gaze and up, and a window on an
//! image plane at distance `near`. Pixel `(i, j)` (row 0 at the top) is sampled at `l + (i + sx)(r - l)/nx`
//! along `u` and `t - (j + sy)(t - b)/ny` along `v`, `(sx, sy) = (0.5, 0.5)` being the pixel centre.
//!
//! [`Camera::ray`] maps a pixel to a world ray and [`Camera::project`] maps a world point back to
//! continuous pixel coordinates with the same frame and window (the boxes debug view draws with it), so
//! a point on the ray through a pixel projects into that pixel. The scene's build step makes cameras
//! from the description; nothing here knows the scene file.

use glam::{DVec2, DVec3};

use crate::math::{orthonormal_basis, Ray, Vec2, Vec3};
use crate::renderer::Renderer;
use crate::tonemap::Tonemap;

/// The window `left right bottom top` on the image plane, `distance` along the gaze from the eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImagePlane {
    /// Left edge (along `u`).
    pub left: f32,
    /// Right edge.
    pub right: f32,
    /// Bottom edge (along `v`).
    pub bottom: f32,
    /// Top edge.
    pub top: f32,
    /// Distance from the eye to the plane.
    pub distance: f32,
}

/// How rays leave the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Every ray starts at the eye.
    Pinhole,
    /// Depth of field: rays start on a square aperture and meet the pinhole ray on the plane in focus.
    ThinLens {
        /// Side of the square aperture.
        aperture: f32,
        /// Distance from the eye to the plane in focus, along the gaze.
        focus_distance: f32,
    },
    /// Parallel rays along the gaze, starting on the image window.
    Orthographic,
}

/// A ray cone (Akenine-Möller et al. 2019, "Texture Level of Detail Strategies for Real-Time Ray
/// Tracing", Ray Tracing Gems ch. 20): the width of a pixel's footprint where a ray starts and the angle
/// it spreads at, so that at distance `t` it is `width + spread * t` wide (small angles).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RayCone {
    /// Width at the ray's origin.
    pub width: f32,
    /// Spread angle, in radians.
    pub spread: f32,
}

impl RayCone {
    /// The cone's width at distance `t` along the ray.
    #[inline]
    pub fn width_at(self, t: f32) -> f32 {
        self.width + self.spread * t
    }

    /// The cone that leaves a surface at distance `t`: as wide as this one there, spreading alike (a
    /// flat mirror's reflection; a curved surface's own spread is left out).
    #[inline]
    pub fn after(self, t: f32) -> RayCone {
        RayCone { width: self.width_at(t), spread: self.spread }
    }
}

/// A camera ready to generate rays, with the image it makes.
#[derive(Debug, Clone)]
pub struct Camera {
    eye: Vec3,
    u: Vec3,
    v: Vec3,
    w: Vec3,
    plane: ImagePlane,
    projection: Projection,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The camera's name (the scene file's id; `--camera` picks it).
    pub id: String,
    /// Output file name, relative to the output folder; its extension picks the format.
    pub image_name: String,
    /// Samples per pixel, at least 1.
    pub num_samples: u32,
    /// How the image is tone mapped for display; none: radiance as it is.
    pub tonemap: Option<Tonemap>,
    /// The integrator of its image.
    pub renderer: Renderer,
}

impl Camera {
    /// A camera at `eye` looking along `gaze` with `up` as the up hint (neither need be unit), making
    /// `width x height` images. `u = up x w`, `v = w x u`, `w = -gaze`, so that an up vector not quite
    /// perpendicular to the gaze is orthogonalised. The id and image name start empty, one sample per
    /// pixel.
    pub fn new(
        eye: Vec3,
        gaze: Vec3,
        up: Vec3,
        plane: ImagePlane,
        projection: Projection,
        width: u32,
        height: u32,
    ) -> Camera {
        let w = -gaze.normalize_or(-Vec3::Z);
        let u = up.cross(w).try_normalize().unwrap_or_else(|| orthonormal_basis(w).0);
        let v = w.cross(u);
        Camera {
            eye,
            u,
            v,
            w,
            plane,
            projection,
            width,
            height,
            id: String::new(),
            image_name: String::new(),
            num_samples: 1,
            tonemap: None,
            renderer: Renderer::Whitted,
        }
    }

    /// The ray through point `offset` (in `[0,1)²`) of pixel `(x, y)`; `lens` picks the point on the
    /// aperture for depth of field.
    pub fn ray(&self, x: u32, y: u32, offset: Vec2, lens: Vec2) -> Ray {
        let wd = &self.plane;
        let su = (x as f32 + offset.x) * (wd.right - wd.left) / self.width as f32;
        let sv = (y as f32 + offset.y) * (wd.top - wd.bottom) / self.height as f32;
        let on_plane = (wd.left + su) * self.u + (wd.top - sv) * self.v - wd.distance * self.w;
        match self.projection {
            Projection::Orthographic => Ray::new(self.eye + on_plane + wd.distance * self.w, -self.w),
            Projection::Pinhole => Ray::new(self.eye, on_plane.normalize()),
            Projection::ThinLens { aperture, focus_distance } => {
                // Every ray through the aperture meets the pinhole ray on the plane in focus.
                let dir = on_plane.normalize();
                let focus = self.eye + dir * (focus_distance / dir.dot(-self.w));
                let origin = self.eye + aperture * ((lens.x - 0.5) * self.u + (lens.y - 0.5) * self.v);
                Ray::new(origin, (focus - origin).normalize())
            }
        }
    }

    /// The cone of a pixel's rays: a pinhole's spreads at the angle a pixel subtends at the eye (the
    /// geometric mean of its sides, for a pixel that is not square) from a point; an orthographic
    /// camera's starts a pixel wide and does not spread. A thin lens is taken as its pinhole.
    pub fn pixel_cone(&self) -> RayCone {
        let wd = &self.plane;
        let side = ((wd.right - wd.left) / self.width as f32 * (wd.top - wd.bottom) / self.height as f32).abs().sqrt();
        match self.projection {
            Projection::Orthographic => RayCone { width: side, spread: 0.0 },
            Projection::Pinhole | Projection::ThinLens { .. } => {
                RayCone { width: 0.0, spread: (side / wd.distance).atan() }
            }
        }
    }

    /// Where the camera is.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The unit direction it looks in.
    pub fn gaze(&self) -> Vec3 {
        -self.w
    }

    /// Its unit up vector (at right angles to the gaze).
    pub fn up(&self) -> Vec3 {
        self.v
    }

    /// The same camera (window, lens, settings) moved to look from `eye` along `gaze` with `up`, making a
    /// `width` x `height` image: a live view's camera, moved by the user, at a resolution of its own.
    pub fn posed(&self, eye: Vec3, gaze: Vec3, up: Vec3, width: u32, height: u32) -> Camera {
        // The camera's own pose keeps its basis to the bit (rebuilt, it could differ in the last bits),
        // so that an unmoved view renders exactly as `arbor render` does.
        if (eye, gaze, up) == (self.eye, self.gaze(), self.up()) {
            return Camera { width, height, ..self.clone() };
        }
        Camera {
            id: self.id.clone(),
            image_name: self.image_name.clone(),
            num_samples: self.num_samples,
            tonemap: self.tonemap,
            renderer: self.renderer,
            ..Camera::new(eye, gaze, up, self.plane, self.projection, width, height)
        }
    }

    /// Continuous pixel coordinates of world point `p` (pixel `(x, y)` spans `[x, x+1) x [y, y+1)`), as
    /// the pinhole at the lens centre sees it; `None` when `p` is not in front of the camera.
    pub fn project(&self, p: Vec3) -> Option<DVec2> {
        let c = self.view_point(p);
        (c.z >= self.min_depth() && (self.projection == Projection::Orthographic || c.z > 0.0))
            .then(|| self.view_to_pixel(c))
    }

    /// The part of the world segment `p..q` in front of the camera, in continuous pixel coordinates
    /// (clipped in camera space, so a segment passing beside the eye projects correctly); `None` when it
    /// lies wholly behind.
    pub fn project_segment(&self, p: Vec3, q: Vec3) -> Option<(DVec2, DVec2)> {
        let (mut p, mut q) = (self.view_point(p), self.view_point(q));
        let min = self.min_depth();
        if p.z < min && q.z < min {
            return None;
        }
        let cut = |a: DVec3, b: DVec3| {
            let s = (min - a.z) / (b.z - a.z);
            DVec3::new(a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), min)
        };
        if p.z < min {
            p = cut(p, q);
        } else if q.z < min {
            q = cut(q, p);
        }
        Some((self.view_to_pixel(p), self.view_to_pixel(q)))
    }

    /// `(right, up, depth along the gaze)` of a world point.
    fn view_point(&self, p: Vec3) -> DVec3 {
        let d = p - self.eye;
        DVec3::new(d.dot(self.u) as f64, d.dot(self.v) as f64, -d.dot(self.w) as f64)
    }

    /// The smallest depth drawn: a perspective projection divides by depth, so keep a sliver in front
    /// of the eye.
    fn min_depth(&self) -> f64 {
        match self.projection {
            Projection::Orthographic => 0.0,
            _ => self.plane.distance as f64 * 1e-3,
        }
    }

    /// Continuous pixel coordinates of a camera-space point in front of the camera.
    fn view_to_pixel(&self, c: DVec3) -> DVec2 {
        let near = self.plane.distance as f64;
        let (pu, pv) = match self.projection {
            Projection::Orthographic => (c.x, c.y),
            _ => (c.x * near / c.z, c.y * near / c.z),
        };
        let wd = &self.plane;
        let x = (pu - wd.left as f64) / (wd.right - wd.left) as f64 * self.width as f64;
        let y = (wd.top as f64 - pv) / (wd.top - wd.bottom) as f64 * self.height as f64;
        DVec2::new(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PLANE: ImagePlane = ImagePlane { left: -10.0, right: 10.0, bottom: -10.0, top: 10.0, distance: 10.0 };

    fn camera(projection: Projection) -> Camera {
        Camera::new(Vec3::new(0.0, 0.0, 20.0), -Vec3::Z, Vec3::Y, PLANE, projection, 800, 600)
    }

    #[test]
    fn camera_top_left_pixel_centre() {
        let cam = Camera::new(Vec3::new(0.0, 0.0, 20.0), -Vec3::Z, Vec3::Y, PLANE, Projection::Pinhole, 800, 800);
        let r = cam.ray(0, 0, Vec2::splat(0.5), Vec2::ZERO);
        let expected = Vec3::new(-10.0 + 0.0125, 10.0 - 0.0125, -10.0).normalize();
        assert!(r.dir.abs_diff_eq(expected, 1e-6));
        assert_eq!(r.origin, Vec3::new(0.0, 0.0, 20.0));
    }

    #[test]
    fn camera_up_not_perpendicular_to_gaze_is_orthogonalised() {
        let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::new(0.0, 1.0, 0.5), PLANE, Projection::Pinhole, 8, 8);
        let r = cam.ray(4, 4, Vec2::ZERO, Vec2::ZERO);
        assert!(r.dir.abs_diff_eq(-Vec3::Z, 1e-6));
    }

    #[test]
    fn camera_lens_rays_meet_on_the_focal_plane() {
        let cam = camera(Projection::ThinLens { aperture: 2.0, focus_distance: 15.0 });
        let a = cam.ray(100, 200, Vec2::splat(0.5), Vec2::new(0.1, 0.9));
        let b = cam.ray(100, 200, Vec2::splat(0.5), Vec2::new(0.8, 0.3));
        let pa = a.at((5.0 - a.origin.z) / a.dir.z);
        let pb = b.at((5.0 - b.origin.z) / b.dir.z);
        assert!(pa.abs_diff_eq(pb, 1e-4));
    }

    /// A point along the ray through `offset` of pixel `(x, y)` projects back to that point of the pixel.
    fn assert_projects_back(cam: &Camera, x: u32, y: u32, offset: Vec2, t: f32) {
        let r = cam.ray(x, y, offset, Vec2::splat(0.5));
        let got = cam.project(r.at(t)).unwrap_or_else(|| panic!("({x}, {y}) at t {t}: not in front"));
        let want = DVec2::new(x as f64 + offset.x as f64, y as f64 + offset.y as f64);
        assert!((got - want).abs().max_element() < 1e-3, "({x}, {y}) at t {t}: projected to {got}, want {want}");
    }

    #[test]
    fn camera_project_inverts_ray_for_every_projection() {
        let turned = Camera::new(
            Vec3::new(3.0, -2.0, 7.0),
            Vec3::new(-1.0, 0.5, -2.0),
            Vec3::new(0.2, 1.0, 0.1),
            ImagePlane { left: -1.5, right: 0.5, bottom: -0.4, top: 0.8, distance: 1.3 },
            Projection::Pinhole,
            320,
            200,
        );
        let cameras = [
            camera(Projection::Pinhole),
            camera(Projection::Orthographic),
            camera(Projection::ThinLens { aperture: 0.0, focus_distance: 15.0 }),
            turned,
        ];
        for cam in &cameras {
            for (x, y) in [(0, 0), (799, 0), (0, 599), (400, 300), (123, 456)] {
                let (x, y) = (x.min(cam.width - 1), y.min(cam.height - 1));
                for t in [0.5, 10.0, 35.0] {
                    assert_projects_back(cam, x, y, Vec2::splat(0.5), t);
                    assert_projects_back(cam, x, y, Vec2::new(0.1, 0.8), t);
                }
            }
        }
    }

    #[test]
    fn camera_pixel_cone_spans_a_pixel_at_the_image_plane() {
        // The window is 20 x 20 at distance 10 over 800 x 800 pixels: pixels 0.025 wide on the plane.
        let square = |p| Camera::new(Vec3::new(0.0, 0.0, 20.0), -Vec3::Z, Vec3::Y, PLANE, p, 800, 800);
        let cone = square(Projection::Pinhole).pixel_cone();
        assert_eq!(cone.width, 0.0);
        assert!((cone.width_at(10.0) - 0.025).abs() < 1e-6, "{cone:?}");
        assert!((cone.after(20.0).width_at(20.0) - 0.1).abs() < 1e-5);
        assert_eq!(square(Projection::Orthographic).pixel_cone(), RayCone { width: 0.025, spread: 0.0 });
        // 800 x 600: pixels 0.025 x 0.0333 on the plane, the side of a square of their area.
        let cone = camera(Projection::Pinhole).pixel_cone();
        assert!((cone.width_at(10.0) - (0.025f32 * 20.0 / 600.0).sqrt()).abs() < 1e-6, "{cone:?}");
    }

    #[test]
    fn camera_project_rejects_points_behind() {
        let cam = camera(Projection::Pinhole);
        assert!(cam.project(Vec3::new(0.0, 0.0, 25.0)).is_none());
        assert!(cam.project(Vec3::new(0.0, 0.0, 20.0)).is_none(), "the eye itself has no pixel");
        assert_eq!(cam.project(Vec3::ZERO), Some(DVec2::new(400.0, 300.0)));
    }

    #[test]
    fn camera_project_segment_clips_the_part_behind() {
        let cam = camera(Projection::Pinhole);
        assert!(cam.project_segment(Vec3::new(0.0, 0.0, 21.0), Vec3::new(5.0, 0.0, 30.0)).is_none());
        // From straight ahead to behind the eye: the visible end stays, the other runs off the image.
        let (a, b) = cam.project_segment(Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 40.0)).unwrap();
        assert_eq!(Some(a), cam.project(Vec3::new(1.0, 0.0, 0.0)));
        assert!(b.x > 1e4 && (b.y - 300.0).abs() < 1e-6, "clipped end {b}");
        let whole = cam.project_segment(Vec3::new(-1.0, 1.0, 0.0), Vec3::new(2.0, -3.0, 5.0)).unwrap();
        assert_eq!(
            whole,
            (cam.project(Vec3::new(-1.0, 1.0, 0.0)).unwrap(), cam.project(Vec3::new(2.0, -3.0, 5.0)).unwrap())
        );
    }
}
