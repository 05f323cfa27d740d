//! METU cameras: the image-plane window from `NearPlane`, or for `type="lookAt"` from `FovY` and the
//! image's aspect ratio (`top = NearDistance·tan(FovY/2)`, `right = top·width/height`), the camera's
//! transformations and its thin lens. The image plane lies in front of the eye (`NearDistance` > 0)
//! and its window is neither empty nor inverted (left < right, bottom < top; `FovY` in (0, 180)) nor so
//! wide that its width or height overflows `f32`.

use super::Reader;
use crate::renderer::{PathOptions, Renderer, Roulette};
use crate::scene::desc::{CameraDesc, Lens, Window};
use crate::scene::readers::tree::Node;
use crate::tonemap::{Operator, Tonemap};
use crate::{Error, Result};

/// How a window's size that leaves the range of `f32` is said.
const OVERFLOWS: &str = "overflows to infinity (beyond the range of 32-bit floats)";

/// `width` or `height` when that side of `w` is not a finite number: the pixel grid would be NaN.
fn overflowing_side(w: &Window) -> Option<&'static str> {
    if !(w.right - w.left).is_finite() {
        Some("width")
    } else if !(w.top - w.bottom).is_finite() {
        Some("height")
    } else {
        None
    }
}

impl Reader<'_> {
    /// One `Camera`; `index` (from 0) names it when it has no id.
    pub(super) fn camera(&mut self, c: &Node, index: usize) -> Result<CameraDesc> {
        let p = self.path;
        let id = c.attr("id").map_or_else(|| (index + 1).to_string(), |a| a.trimmed().to_string());
        let look_at = match c.attr("type").map(|a| (a, a.trimmed())) {
            None => false,
            Some((_, "lookAt")) => true,
            Some((a, other)) => {
                let msg = format!("Camera {id}: unknown type '{other}' (expected lookAt)");
                return Err(Error::input(a.loc(p), msg));
            }
        };
        let left_handed = match c.attr("handedness").map(|h| (h, h.trimmed())) {
            None | Some((_, "right")) => false,
            Some((_, "left")) => true,
            Some((h, other)) => {
                let msg = format!("Camera {id}: handedness must be right or left, not '{other}'");
                return Err(Error::input(h.loc(p), msg));
            }
        };
        let position = self.req(c, "Position")?.vec3(p)?;
        let up = self.req(c, "Up")?.vec3(p)?;
        let near_node = self.req(c, "NearDistance")?;
        let near_distance = near_node.float(p)?;
        // The image plane must lie in front of the eye: at 0 every pixel's ray runs along the gaze, and
        // behind the eye the camera would look backwards.
        if near_distance <= 0.0 {
            return Err(self.err(near_node, format!("Camera {id}: NearDistance {near_distance} must be positive")));
        }
        let res_node = self.req(c, "ImageResolution")?;
        let res = res_node.ints(p)?;
        let (width, height) = match res[..] {
            [w, h] if w > 0 && h > 0 && w <= u32::MAX as i64 && h <= u32::MAX as i64 => (w as u32, h as u32),
            _ => return Err(self.err(res_node, "<ImageResolution>: expected two positive integers")),
        };
        let name_node = self.req(c, "ImageName")?;
        let image_name = name_node.trimmed().to_string();
        if image_name.is_empty() {
            return Err(self.err(name_node, "<ImageName>: empty file name"));
        }
        let num_samples = match self.one(c, "NumSamples") {
            Some(n) => self.num_samples(n, &id)?,
            None => 1,
        };
        let (gaze, window) = if look_at {
            let gaze = match self.one(c, "GazePoint") {
                Some(g) => g.vec3(p)? - position,
                None => self.req(c, "Gaze")?.vec3(p)?,
            };
            let fov_node = self.req(c, "FovY")?;
            let fov_deg = fov_node.float(p)?;
            if !(fov_deg > 0.0 && fov_deg < 180.0) {
                return Err(self.err(fov_node, format!("Camera {id}: FovY {fov_deg} must be in (0, 180) degrees")));
            }
            let top = near_distance * (fov_deg.to_radians() / 2.0).tan();
            let right = top * width as f32 / height as f32;
            let window = Window { left: -right, right, bottom: -top, top };
            if let Some(side) = overflowing_side(&window) {
                // Only a huge distance can overflow (tan of FovY below 180 stays under 1e7 in f32).
                let msg = format!(
                    "Camera {id}: the window of NearDistance {near_distance:e} and FovY {fov_deg} has a {side} that \
                     {OVERFLOWS}"
                );
                return Err(self.err(fov_node, msg));
            }
            (gaze, window)
        } else {
            let gaze = self.req(c, "Gaze")?.vec3(p)?;
            let np = self.req(c, "NearPlane")?;
            let v = np.floats_n(4, true, p)?;
            let extra = np.trimmed().split_whitespace().count();
            if extra > 4 {
                let msg = format!("<NearPlane> has {extra} numbers; only the first 4 are used");
                self.notes.plain(np.loc(p), msg);
            }
            // An empty window sends a whole row or column of pixels along one ray; an inverted one
            // mirrors the image, which the format asks for with handedness="left" instead.
            for (low, high, (a, b)) in [(v[0], v[1], ("left", "right")), (v[2], v[3], ("bottom", "top"))] {
                if low >= high {
                    return Err(self.err(np, format!("Camera {id}: NearPlane {a} {low} must be less than {b} {high}")));
                }
            }
            let window = Window { left: v[0], right: v[1], bottom: v[2], top: v[3] };
            if let Some(side) = overflowing_side(&window) {
                return Err(self.err(np, format!("Camera {id}: the NearPlane window's {side} {OVERFLOWS}")));
            }
            (gaze, window)
        };
        if gaze.length_squared() == 0.0 {
            return Err(self.err(c, format!("Camera {id}: zero gaze direction")));
        }
        // A left-handed camera's u is gaze x up instead of up x gaze: the same camera with its image-plane
        // window mirrored along u.
        let window = if left_handed { Window { left: -window.left, right: -window.right, ..window } } else { window };
        let lens = match (self.one(c, "FocusDistance"), self.one(c, "ApertureSize")) {
            (None, None) => None,
            (Some(f), Some(a)) => self.lens(f, a, &id)?,
            (Some(_), None) => return Err(self.err(c, "<Camera>: missing <ApertureSize>")),
            (None, Some(_)) => return Err(self.err(c, "<Camera>: missing <FocusDistance>")),
        };
        let transform = self.transform_of(c)?;
        let tonemap = match self.one(c, "Tonemap") {
            Some(t) => Some(self.tonemap(t, &id)?),
            None => None,
        };
        let renderer = self.renderer(c, &id)?;
        Ok(CameraDesc {
            id,
            position,
            gaze,
            up,
            window,
            near_distance,
            orthographic: false,
            width,
            height,
            image_name,
            name_loc: name_node.loc(p),
            num_samples,
            transform,
            lens,
            tonemap,
            renderer,
            loc: c.loc(p),
        })
    }

    /// `NumSamples`: at least 1, and a perfect square, so that the jittered grid of a pixel is square
    /// (the assignment texts only use squares). Another count becomes the nearest square,
    /// `round(sqrt n)²`, with a warning; for integers that is also the square nearest to `n`.
    fn num_samples(&mut self, n: &Node, id: &str) -> Result<u32> {
        let p = self.path;
        if let Ok(v) = n.trimmed().parse::<i64>() {
            if v < 1 {
                return Err(self.err(n, format!("Camera {id}: NumSamples {v} must be at least 1")));
            }
        }
        let v = n.uint(p)?;
        // 65535² is the largest square that fits a u32.
        let side = ((v as f64).sqrt().round() as u32).clamp(1, 65535);
        let square = side * side;
        if square != v {
            let msg = format!("Camera {id}: NumSamples {v} is not a perfect square; using {square} ({side}x{side})");
            self.notes.plain(n.loc(p), msg);
        }
        Ok(square)
    }

    /// `Renderer` (only `PathTracing`; Whitted when absent) and its `RendererParams`, any of
    /// `NextEventEstimation`, `ImportanceSampling`, `RussianRoulette` and `MIS` (hw6).
    fn renderer(&mut self, c: &Node, id: &str) -> Result<Renderer> {
        let p = self.path;
        let params = self.one(c, "RendererParams");
        match self.one(c, "Renderer").map(|n| (n, n.trimmed())) {
            None => {
                if let Some(n) = params {
                    let msg = format!("Camera {id}: RendererParams without <Renderer>PathTracing</Renderer>; ignored");
                    self.notes.plain(n.loc(p), msg);
                }
                Ok(Renderer::Whitted)
            }
            Some((n, "PathTracing")) => {
                // The course's renderer splits at refractive surfaces.
                let mut o = PathOptions { split_refraction: true, ..PathOptions::default() };
                for word in params.map_or("", |n| n.trimmed()).split_whitespace() {
                    let flag = match word {
                        "NextEventEstimation" => &mut o.next_event,
                        "ImportanceSampling" => &mut o.importance_sampling,
                        // The element means what the course's renderer does with it.
                        "RussianRoulette" => {
                            o.roulette = Roulette::Course;
                            continue;
                        }
                        "MIS" => &mut o.mis,
                        other => {
                            let msg = format!(
                                "Camera {id}: unknown RendererParams '{other}' (expected NextEventEstimation, \
                                 ImportanceSampling, RussianRoulette or MIS)"
                            );
                            return Err(self.err(params.unwrap_or(c), msg));
                        }
                    };
                    *flag = true;
                }
                let o = o.implied();
                if self.desc.max_depth == 0 && o.roulette == Roulette::Off {
                    let msg = format!(
                        "Camera {id}: path tracing with MaxRecursionDepth 0 follows no bounce: emitters and, with \
                         NextEventEstimation, direct light only"
                    );
                    self.notes.plain(n.loc(p), msg);
                }
                Ok(Renderer::PathTracing(o))
            }
            Some((n, other)) => {
                Err(self.err(n, format!("Camera {id}: unknown Renderer '{other}' (expected PathTracing)")))
            }
        }
    }

    /// A `Tonemap` (hw5): `TMO` (only `Photographic`), `TMOOptions` (key value and burn-out percentage),
    /// `Saturation` (default 1) and `Gamma` (default 2.2). The key must be positive (0 maps every pixel to
    /// black), the burn-out a percentage, the saturation not negative and the gamma positive.
    fn tonemap(&mut self, t: &Node, id: &str) -> Result<Tonemap> {
        let p = self.path;
        let tmo = self.req(t, "TMO")?;
        let operator = match tmo.trimmed() {
            "Photographic" => Operator::Photographic,
            other => {
                let msg = format!("Camera {id}: unknown TMO '{other}' (expected Photographic)");
                return Err(self.err(tmo, msg));
            }
        };
        let options = self.req(t, "TMOOptions")?;
        let v = options.floats_n(2, false, p)?;
        let (key, burn_percent) = (v[0], v[1]);
        if key <= 0.0 {
            return Err(self.err(options, format!("Camera {id}: TMOOptions key value {key} must be positive")));
        }
        if !(0.0..=100.0).contains(&burn_percent) {
            let msg = format!("Camera {id}: TMOOptions burn-out percentage {burn_percent} must be in [0, 100]");
            return Err(self.err(options, msg));
        }
        let saturation_node = self.one(t, "Saturation");
        let saturation = match saturation_node {
            Some(s) => s.float(p)?,
            None => 1.0,
        };
        if saturation < 0.0 {
            let msg = format!("Camera {id}: Saturation {saturation} must not be negative");
            return Err(self.err(saturation_node.unwrap_or(t), msg));
        }
        let gamma_node = self.one(t, "Gamma");
        let gamma = match gamma_node {
            Some(g) => g.float(p)?,
            None => 2.2,
        };
        if gamma <= 0.0 {
            return Err(self.err(gamma_node.unwrap_or(t), format!("Camera {id}: Gamma {gamma} must be positive")));
        }
        t.mark_used();
        Ok(Tonemap { operator, key, burn_percent, saturation, gamma, unit: 1.0 })
    }

    /// The thin lens of `FocusDistance` `f` and `ApertureSize` `a`; none (a pinhole) when the aperture
    /// is 0. Both must be finite (the number reader sees to that) and not negative, and the plane in
    /// focus must lie in front of a real lens.
    fn lens(&mut self, f: &Node, a: &Node, id: &str) -> Result<Option<Lens>> {
        let p = self.path;
        let (aperture, focus_distance) = (a.float(p)?, f.float(p)?);
        if aperture < 0.0 {
            return Err(self.err(a, format!("Camera {id}: ApertureSize {aperture} is negative (0 is a pinhole)")));
        }
        if focus_distance < 0.0 || (focus_distance == 0.0 && aperture > 0.0) {
            let msg = format!("Camera {id}: FocusDistance {focus_distance} must be positive");
            return Err(self.err(f, msg));
        }
        Ok((aperture > 0.0).then_some(Lens { aperture, focus_distance }))
    }
}
