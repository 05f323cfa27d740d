//! The course camera: an eye, an orthonormal frame from gaze and up, and a window on an image plane at
//! `near_distance`. Pixel `(i, j)` (row 0 at the top) is sampled at `l + (i + sx)(r - l)/nx` along `u` and
//! `t - (j + sy)(t - b)/ny` along `v`, `(sx, sy) = (0.5, 0.5)` being the pixel centre.

use crate::math::{Ray, Vec2, Vec3};
use crate::scene::{CameraDesc, Lens, Window};

/// A camera ready to generate rays.
#[derive(Debug, Clone)]
pub struct Camera {
    eye: Vec3,
    u: Vec3,
    v: Vec3,
    w: Vec3,
    window: Window,
    near: f32,
    orthographic: bool,
    lens: Option<Lens>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// The camera of a description, with its transform applied. `u = up x w`, `v = w x u`, `w = -gaze`,
    /// so that an up vector not quite perpendicular to the gaze is orthogonalised.
    pub fn new(desc: &CameraDesc) -> Camera {
        let t = &desc.transform;
        let eye = t.point(desc.position);
        let w = -t.vector(desc.gaze).normalize_or(-Vec3::Z);
        let up = t.vector(desc.up);
        let u = up.cross(w).try_normalize().unwrap_or_else(|| crate::math::orthonormal_basis(w).0);
        let v = w.cross(u);
        Camera {
            eye,
            u,
            v,
            w,
            window: desc.window,
            near: desc.near_distance,
            orthographic: desc.orthographic,
            lens: desc.lens,
            width: desc.width,
            height: desc.height,
        }
    }

    /// The ray through point `offset` (in `[0,1)²`) of pixel `(x, y)`; `lens` picks the point on the
    /// aperture for depth of field.
    pub fn ray(&self, x: u32, y: u32, offset: Vec2, lens: Vec2) -> Ray {
        let wd = &self.window;
        let su = (x as f32 + offset.x) * (wd.right - wd.left) / self.width as f32;
        let sv = (y as f32 + offset.y) * (wd.top - wd.bottom) / self.height as f32;
        let on_plane = (wd.left + su) * self.u + (wd.top - sv) * self.v - self.near * self.w;
        if self.orthographic {
            return Ray::new(self.eye + on_plane + self.near * self.w, -self.w);
        }
        let dir = on_plane.normalize();
        match self.lens {
            None => Ray::new(self.eye, dir),
            Some(l) => {
                // The thin lens: every ray through the aperture meets the primary ray on the plane in focus.
                let focus = self.eye + dir * (l.focus_distance / dir.dot(-self.w));
                let origin = self.eye + l.aperture * ((lens.x - 0.5) * self.u + (lens.y - 0.5) * self.v);
                Ray::new(origin, (focus - origin).normalize())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;
    use crate::Location;

    fn desc() -> CameraDesc {
        CameraDesc {
            id: "1".into(),
            position: Vec3::new(0.0, 0.0, 20.0),
            gaze: Vec3::new(0.0, 0.0, -1.0),
            up: Vec3::new(0.0, 1.0, 0.0),
            window: Window { left: -10.0, right: 10.0, bottom: -10.0, top: 10.0 },
            near_distance: 10.0,
            orthographic: false,
            width: 800,
            height: 800,
            image_name: "x.png".into(),
            num_samples: 1,
            transform: Transform::IDENTITY,
            lens: None,
            loc: Location::file("x.xml"),
        }
    }

    #[test]
    fn camera_top_left_pixel_centre() {
        let cam = Camera::new(&desc());
        let r = cam.ray(0, 0, Vec2::splat(0.5), Vec2::ZERO);
        let expected = Vec3::new(-10.0 + 0.0125, 10.0 - 0.0125, -10.0).normalize();
        assert!(r.dir.abs_diff_eq(expected, 1e-6));
        assert_eq!(r.origin, Vec3::new(0.0, 0.0, 20.0));
    }

    #[test]
    fn camera_transform_moves_eye_and_turns_gaze() {
        let mut d = desc();
        d.transform = Transform::rotate(90.0, Vec3::Y).unwrap();
        let cam = Camera::new(&d);
        let r = cam.ray(400, 400, Vec2::ZERO, Vec2::ZERO);
        assert!(r.origin.abs_diff_eq(Vec3::new(20.0, 0.0, 0.0), 1e-4));
        assert!(r.dir.abs_diff_eq(-Vec3::X, 1e-6));
    }

    #[test]
    fn camera_lens_rays_meet_on_the_focal_plane() {
        let mut d = desc();
        d.lens = Some(Lens { aperture: 2.0, focus_distance: 15.0 });
        let cam = Camera::new(&d);
        let a = cam.ray(100, 200, Vec2::splat(0.5), Vec2::new(0.1, 0.9));
        let b = cam.ray(100, 200, Vec2::splat(0.5), Vec2::new(0.8, 0.3));
        let pa = a.at((5.0 - a.origin.z) / a.dir.z);
        let pb = b.at((5.0 - b.origin.z) / b.dir.z);
        assert!(pa.abs_diff_eq(pb, 1e-4));
    }
}
