//! Debug views (`arbor render --debug VIEW`): what the acceleration structure and the hits look like,
//! rather than what the scene looks like.
//!
//! - `primid`: a colour per hit primitive from a hash of its index (background black). Every structure
//!   returns the same closest hit, and the colour depends on the index only, so the image is
//!   byte-identical across structures and thread counts: a visual conformance test.
//! - `normal`: the shading normal mapped to colour, `n * 0.5 + 0.5` (background black).
//! - `heatmap`: the work of each camera ray (nodes visited plus primitives tested), divided by the
//!   image's maximum and mapped through a turbo-like false-colour ramp, with a legend bar along the
//!   bottom rows (left = 0, right = the maximum).
//! - `boxes[:DEPTH]`: the normal Whitted render with the wireframe of the nodes `DEPTH` levels below the
//!   root of each structure (the top level's and every mesh's: [`crate::scene::SceneGeometry::boxes_at_depth`])
//!   projected over it. The levels are the ones the statistics count (a BVH's binary tree's, not the
//!   8-wide tree's), so depth `max_depth` of `arbor info` shows the deepest leaves.
//!
//! The per-pixel views trace one ray through each pixel centre; the image-wide steps (normalising the
//! heatmap, drawing boxes) run once the film is complete ([`heatmap_finish`], [`overlay_boxes`]).

use std::fmt;
use std::str::FromStr;

use crate::accel::TraversalCounts;
use crate::camera::Camera;
use crate::film::Film;
use crate::math::{Aabb, Color, Ray, Vec3};
use crate::scene::Scene;

/// Depth of the boxes drawn by `--debug boxes` without a depth.
pub const DEFAULT_BOX_DEPTH: usize = 3;

/// The colour of box wireframes: magenta, rare in real renders.
pub const BOX_COLOR: Color = Color::new(1.0, 0.0, 1.0);

/// Which debug view to render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DebugView {
    /// Whitted render with the structures' boxes at `depth` drawn as wireframe.
    Boxes {
        /// Depth below each structure's root (0 = the root's box), as [`crate::accel::AccelStats`] counts it.
        depth: usize,
    },
    /// Traversal cost per pixel in false colour.
    Heatmap,
    /// A colour per hit primitive.
    PrimId,
    /// Shading normal as colour.
    Normal,
}

impl DebugView {
    /// Whether pixels are shaded by the Whitted integrator (the view only adds an overlay).
    pub fn shades(self) -> bool {
        matches!(self, DebugView::Boxes { .. })
    }
}

impl FromStr for DebugView {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let expected = "expected boxes[:DEPTH], heatmap, primid or normal";
        match s {
            "heatmap" => Ok(DebugView::Heatmap),
            "primid" => Ok(DebugView::PrimId),
            "normal" => Ok(DebugView::Normal),
            "boxes" => Ok(DebugView::Boxes { depth: DEFAULT_BOX_DEPTH }),
            _ => match s.strip_prefix("boxes:") {
                Some(d) => d
                    .parse()
                    .map(|depth| DebugView::Boxes { depth })
                    .map_err(|_| format!("debug view '{s}': depth '{d}' is not a whole number")),
                None => Err(format!("unknown debug view '{s}' ({expected})")),
            },
        }
    }
}

impl fmt::Display for DebugView {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DebugView::Boxes { depth } => write!(f, "boxes:{depth}"),
            DebugView::Heatmap => f.write_str("heatmap"),
            DebugView::PrimId => f.write_str("primid"),
            DebugView::Normal => f.write_str("normal"),
        }
    }
}

/// The per-pixel part of the views that do not shade ([`DebugView::shades`] is false).
pub struct DebugIntegrator<'a> {
    scene: &'a Scene,
    view: DebugView,
    cull_backfaces: bool,
}

impl<'a> DebugIntegrator<'a> {
    /// An integrator for `view`; `cull_backfaces` applies to camera rays, as in a normal render.
    pub fn new(scene: &'a Scene, view: DebugView, cull_backfaces: bool) -> Self {
        DebugIntegrator { scene, view, cull_backfaces }
    }

    /// The value of a camera ray, in display units. The heatmap stores the raw cost in the red channel
    /// until [`heatmap_finish`] maps it.
    pub fn li_camera(&self, ray: &Ray) -> Color {
        let ray = ray.with_culling(self.cull_backfaces);
        let geometry = &self.scene.geometry;
        match self.view {
            DebugView::Heatmap => {
                let mut counts = TraversalCounts::default();
                geometry.intersect_counted(&ray, f32::INFINITY, &mut counts);
                Color::new(counts.nodes as f32 + counts.prims as f32, 0.0, 0.0)
            }
            DebugView::PrimId => {
                geometry.intersect(&ray, f32::INFINITY).map_or(Color::ZERO, |h| prim_color(geometry.global_prim_id(&h)))
            }
            DebugView::Normal | DebugView::Boxes { .. } => match geometry.intersect(&ray, f32::INFINITY) {
                Some(h) => self.scene.surface(&ray, &h).ns * 0.5 + Color::splat(0.5),
                None => Color::ZERO,
            },
        }
    }
}

/// The colour of primitive `prim`: three bytes of a hash of the index, each at least 48 so that no hit
/// is mistaken for the black background. Exact multiples of 1/255, so 8-bit output is lossless.
pub fn prim_color(prim: u32) -> Color {
    let mut z = (prim as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    let byte = |k: u32| (48 + ((z >> (8 * k)) & 0xff) * 207 / 255) as f32 / 255.0;
    Color::new(byte(0), byte(1), byte(2))
}

/// Turbo-like false colour (after Mikhailov 2019), 9 stops from dark blue (0) to dark red (1).
const RAMP: [[f32; 3]; 9] = [
    [0.190, 0.072, 0.232],
    [0.255, 0.417, 0.881],
    [0.153, 0.680, 0.953],
    [0.125, 0.890, 0.688],
    [0.492, 0.993, 0.312],
    [0.823, 0.910, 0.204],
    [0.990, 0.650, 0.190],
    [0.900, 0.300, 0.060],
    [0.480, 0.016, 0.011],
];

/// The false colour of `x` in `[0, 1]` (clamped; NaN counts as 0).
pub fn false_color(x: f32) -> Color {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) } * (RAMP.len() - 1) as f32;
    let i = (x as usize).min(RAMP.len() - 2);
    let f = x - i as f32;
    Vec3::from(RAMP[i]).lerp(Vec3::from(RAMP[i + 1]), f)
}

/// Rows of the heatmap legend bar for an image `height` rows tall.
pub fn legend_rows(height: u32) -> u32 {
    (height / 16).clamp(1, 24).min(height)
}

/// Maps a film of raw costs (red channel) to false colour normalised by `scale`, else by its maximum,
/// and draws the legend bar over the bottom [`legend_rows`] rows (left = no work, right = the scale).
/// Returns the maximum cost.
pub fn heatmap_finish(film: &mut Film, scale: Option<u32>) -> u32 {
    let max = film.pixels.iter().map(|c| c.x).fold(0.0f32, f32::max);
    let top = scale.map_or(max, |s| s as f32);
    for c in &mut film.pixels {
        *c = false_color(if top > 0.0 { (c.x / top).min(1.0) } else { 0.0 });
    }
    let (w, h) = (film.width, film.height);
    for y in h - legend_rows(h)..h {
        for x in 0..w {
            let t = if w > 1 { x as f32 / (w - 1) as f32 } else { 1.0 };
            film.pixels[(y * w + x) as usize] = false_color(t);
        }
    }
    max as u32
}

/// Draws the 12 edges of every box over `film` in `color`, as seen by `camera` ([`Camera::project_segment`]:
/// the pinhole at the lens centre, edges clipped to the part in front of it); `film` is the camera's
/// full frame. Edges are clipped to the image.
pub fn overlay_boxes(film: &mut Film, camera: &Camera, boxes: &[Aabb], color: Color) {
    for b in boxes.iter().filter(|b| !b.is_empty()) {
        let corner = |k: usize| {
            let pick = |bit: usize, lo: f32, hi: f32| if k & bit != 0 { hi } else { lo };
            Vec3::new(pick(1, b.min.x, b.max.x), pick(2, b.min.y, b.max.y), pick(4, b.min.z, b.max.z))
        };
        // Corners k and k | bit differ along one axis: those pairs are the 12 edges.
        for k in 0..8 {
            for bit in [1, 2, 4] {
                if k & bit == 0 {
                    if let Some((p, q)) = camera.project_segment(corner(k), corner(k | bit)) {
                        draw_line(film, p.to_array(), q.to_array(), color);
                    }
                }
            }
        }
    }
}

/// A line between continuous pixel coordinates, clipped to the image (Liang-Barsky), then stepped one
/// pixel at a time along its longer axis.
fn draw_line(film: &mut Film, p: [f64; 2], q: [f64; 2], color: Color) {
    if !(p.iter().chain(&q).all(|v| v.is_finite())) {
        return;
    }
    let (w, h) = (film.width as f64, film.height as f64);
    let d = [q[0] - p[0], q[1] - p[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (num, den) in [(p[0], -d[0]), (w - p[0], d[0]), (p[1], -d[1]), (h - p[1], d[1])] {
        if den == 0.0 {
            if num < 0.0 {
                return;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return;
    }
    let a = [p[0] + t0 * d[0], p[1] + t0 * d[1]];
    let b = [p[0] + t1 * d[0], p[1] + t1 * d[1]];
    let steps = (b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil().max(1.0) as usize;
    for i in 0..=steps {
        let s = i as f64 / steps as f64;
        let (x, y) = ((a[0] + s * (b[0] - a[0])).floor(), (a[1] + s * (b[1] - a[1])).floor());
        // The clipped end may sit exactly on the far image edge.
        let (x, y) = (x.min(w - 1.0), y.min(h - 1.0));
        if x >= 0.0 && y >= 0.0 {
            film.pixels[y as usize * film.width as usize + x as usize] = color;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debug_view_parses_names_and_depths() {
        assert_eq!("boxes".parse(), Ok(DebugView::Boxes { depth: DEFAULT_BOX_DEPTH }));
        assert_eq!("boxes:7".parse(), Ok(DebugView::Boxes { depth: 7 }));
        assert_eq!("primid".parse(), Ok(DebugView::PrimId));
        assert!("boxes:-1".parse::<DebugView>().unwrap_err().contains("'-1'"));
        assert!("depth".parse::<DebugView>().unwrap_err().contains("expected boxes"));
        assert_eq!(DebugView::Boxes { depth: 2 }.to_string(), "boxes:2");
    }

    #[test]
    fn debug_prim_color_is_never_black_and_is_8_bit_exact() {
        for prim in 0..1000 {
            let c = prim_color(prim);
            for v in c.to_array() {
                let byte = crate::film::quantize(v);
                assert!(byte >= 48);
                assert_eq!(byte as f32 / 255.0, v);
            }
        }
        assert_ne!(prim_color(1), prim_color(2));
    }

    #[test]
    fn debug_false_color_runs_from_blue_to_red() {
        assert_eq!(false_color(0.0), Vec3::from(RAMP[0]));
        assert_eq!(false_color(1.0), Vec3::from(RAMP[8]));
        assert_eq!(false_color(f32::NAN), false_color(0.0));
        assert!(false_color(0.0).z > false_color(0.0).x && false_color(1.0).x > false_color(1.0).z);
    }

    #[test]
    fn debug_line_clipped_to_image_never_panics() {
        let mut film = Film::new(8, 8);
        draw_line(&mut film, [-100.0, 4.5], [100.0, 4.5], BOX_COLOR);
        assert!((0..8).all(|x| film.get(x, 4) == BOX_COLOR));
        assert_eq!(film.pixels.iter().filter(|&&c| c == BOX_COLOR).count(), 8);
        draw_line(&mut film, [-5.0, -5.0], [-1.0, 20.0], BOX_COLOR);
        draw_line(&mut film, [f64::NAN, 0.0], [3.0, 3.0], BOX_COLOR);
        draw_line(&mut film, [8.0, 8.0], [8.0, 0.0], BOX_COLOR);
    }
}
