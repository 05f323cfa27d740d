//! The environment map: the radiance arriving from infinitely far away along a direction, seen by every
//! ray that leaves the scene. Either one latitude-longitude image or a cube map of six square faces.
//!
//! Values are in display units, exactly what [`read_image_within`] gives (8-bit files divided by 255, EXR
//! and HDR as stored), and finite: a file holding a NaN or an infinity is refused. Lookups are bilinear.
//! [`EnvMap::eval`] takes any non-zero finite direction, unit or not, and returns black for a zero,
//! infinite or NaN one.
//!
//! # Latitude-longitude (equirectangular) maps
//! World +y is up. For the unit direction `d`:
//! `u = 0.5 + atan2(d.x, -d.z) / (2 pi)`, `v = acos(d.y) / pi`, and `(u, v) = (0, 0)` is the top-left
//! corner of the image (row 0 is +y). So the centre of the image looks down -z, +x is at three quarters of
//! the width, -x at one quarter and +z at the left and right borders, where the map wraps around.
//! Pixel `(i, j)` covers `u` in `[i, i + 1] / width`, its centre at `(i + 0.5) / width`. Filtering wraps
//! horizontally and clamps at the poles.
//!
//! # Light probes (angular maps)
//! Debevec's light probe format (<https://www.pauldebevec.com/Probes/>): a disc filling a square image,
//! its centre looking down -z like a lat-long map's. For the unit direction `d`,
//! `r = acos(-d.z) / (pi sqrt(d.x² + d.y²))` and the image point `(s, t) = (d.x r, d.y r)` in `[-1, 1]²`
//! (`t` up), so the angle from -z grows linearly with the distance from the centre and the rim is +z.
//! Filtering is bilinear, clamped at the border.
//!
//! # Cube maps
//! Six square faces of equal size, oriented as in OpenGL and RenderMan
//! (<https://www.khronos.org/opengl/wiki/Cubemap_Texture>): the face is the axis of the largest component
//! `ma` of `d`, and on it
//!
//! | face | sc    | tc    |
//! |------|-------|-------|
//! | +x   | -d.z  | -d.y  |
//! | -x   | +d.z  | -d.y  |
//! | +y   | +d.x  | +d.z  |
//! | -y   | +d.x  | -d.z  |
//! | +z   | +d.x  | -d.y  |
//! | -z   | -d.x  | -d.y  |
//!
//! with `s = (sc / |ma| + 1) / 2` running along a row left to right and `t = (tc / |ma| + 1) / 2` down the
//! rows from row 0 (the top of the file). Looking at a side face from the centre of the cube, up is +y.
//! Filtering is seamless: a bilinear footprint reaching past a face edge takes the adjacent face's edge
//! texels (as `GL_TEXTURE_CUBE_MAP_SEAMLESS` does), and at a corner the mean of the three texels that meet
//! there, so lookups are continuous across edges.
//!
//! [`EnvMap::load`] on a directory finds the faces by file name (any case, any image extension):
//! `px nx py ny pz nz`, `posx negx posy negy posz negz` or `right left top bottom front back` for
//! `+x -x +y -y +z -z`.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Error, Location, Result};
use crate::film::Film;
use crate::image_io::{check_finite, read_image_within, ImageLimits};
use crate::math::{Color, Vec3};

/// Face labels in storage order, the order of [`EnvMap::from_faces`].
pub const FACE_LABELS: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];

/// File stems accepted for each face, in the order of [`FACE_LABELS`].
const FACE_NAMES: [[&str; 3]; 6] = [
    ["px", "posx", "right"],
    ["nx", "negx", "left"],
    ["py", "posy", "top"],
    ["ny", "negy", "bottom"],
    ["pz", "posz", "front"],
    ["nz", "negz", "back"],
];

/// Extensions of files considered as faces; anything else in the directory is ignored.
const IMAGE_EXTENSIONS: [&str; 9] = ["png", "jpg", "jpeg", "ppm", "pgm", "pnm", "exr", "hdr", "pfm"];

/// Radiance from infinitely far away, by direction. See the module documentation for the conventions.
/// Clones share the images.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvMap {
    kind: Arc<Kind>,
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    LatLong(Film),
    Probe(Film),
    Cube { size: u32, faces: Box<[Film; 6]> },
}

impl EnvMap {
    /// Loads a map: an image file is a latitude-longitude map, a directory a cube map whose faces are
    /// found by name. Each image is held to `limits` and must hold finite values. Errors name the file,
    /// or list the faces a directory lacks.
    pub fn load(spec: &Path, limits: &ImageLimits) -> Result<EnvMap> {
        if spec.is_dir() {
            let paths = find_faces(spec)?;
            let mut faces = Vec::with_capacity(6);
            for path in &paths {
                faces.push(read_map(path, limits)?);
            }
            let faces: [Film; 6] = faces.try_into().expect("six faces");
            if let Err((face, msg)) = check_faces(&faces) {
                return Err(Error::input(Location::file(&paths[face]), msg));
            }
            return Ok(cube(faces));
        }
        let film = read_map(spec, limits)?;
        if film.pixels.is_empty() {
            return Err(Error::input(Location::file(spec), "the environment map is empty"));
        }
        Ok(EnvMap::from_film_latlong(film))
    }

    /// A latitude-longitude map from an image in memory.
    ///
    /// # Panics
    /// When the film is empty or its pixel count is not `width * height` (a caller's bug).
    pub fn from_film_latlong(film: Film) -> EnvMap {
        assert!(
            film.width > 0 && film.pixels.len() == film.width as usize * film.height as usize,
            "latitude-longitude film must be non-empty and consistent"
        );
        EnvMap { kind: Arc::new(Kind::LatLong(film)) }
    }

    /// A light probe (angular map) from a file (see the module documentation), held to `limits`.
    pub fn load_probe(path: &Path, limits: &ImageLimits) -> Result<EnvMap> {
        let film = read_map(path, limits)?;
        if film.pixels.is_empty() {
            return Err(Error::input(Location::file(path), "the environment map is empty"));
        }
        Ok(EnvMap { kind: Arc::new(Kind::Probe(film)) })
    }

    /// A light probe (angular map) from an image in memory.
    ///
    /// # Panics
    /// When the film is empty or its pixel count is not `width * height` (a caller's bug).
    pub fn from_film_probe(film: Film) -> EnvMap {
        assert!(
            film.width > 0 && film.pixels.len() == film.width as usize * film.height as usize,
            "light probe film must be non-empty and consistent"
        );
        EnvMap { kind: Arc::new(Kind::Probe(film)) }
    }

    /// A cube map from six faces in the order `+x -x +y -y +z -z` ([`FACE_LABELS`]). The faces must be
    /// square, non-empty and of one size.
    pub fn from_faces(faces: [Film; 6]) -> Result<EnvMap> {
        check_faces(&faces).map_err(|(face, msg)| Error::Invalid(format!("cube face {}: {msg}", FACE_LABELS[face])))?;
        Ok(cube(faces))
    }

    /// The image of a latitude-longitude map; `None` for the other forms.
    pub fn latlong(&self) -> Option<&Film> {
        match &*self.kind {
            Kind::LatLong(film) => Some(film),
            _ => None,
        }
    }

    /// True for a cube map, false for a latitude-longitude map.
    pub fn is_cube_map(&self) -> bool {
        matches!(*self.kind, Kind::Cube { .. })
    }

    /// The radiance arriving along `-dir`, i.e. seen when looking in direction `dir` (need not be unit).
    pub fn eval(&self, dir: Vec3) -> Color {
        if !dir.is_finite() || dir == Vec3::ZERO {
            return Color::ZERO;
        }
        match &*self.kind {
            Kind::LatLong(film) => eval_latlong(film, dir),
            Kind::Probe(film) => eval_probe(film, dir),
            Kind::Cube { size, faces } => eval_cube(faces, *size, dir),
        }
    }
}

fn cube(faces: [Film; 6]) -> EnvMap {
    EnvMap { kind: Arc::new(Kind::Cube { size: faces[0].width, faces: Box::new(faces) }) }
}

/// An image of a map: radiance, so a NaN or an infinity (which a float file can hold) is refused; it
/// would reach every pixel whose rays see it, and the estimates of every point it lights.
fn read_map(path: &Path, limits: &ImageLimits) -> Result<Film> {
    let film = read_image_within(path, limits)?;
    check_finite(film.pixels.iter().map(|c| c.to_array()), film.width, path)?;
    Ok(film)
}

/// The first face that is not square, empty, inconsistent or of another size than face 0.
fn check_faces(faces: &[Film; 6]) -> std::result::Result<(), (usize, String)> {
    let size = faces[0].width;
    for (i, f) in faces.iter().enumerate() {
        if f.pixels.len() != f.width as usize * f.height as usize {
            return Err((i, format!("{}x{} but {} pixels", f.width, f.height, f.pixels.len())));
        }
        if f.width != f.height || f.width == 0 {
            return Err((i, format!("faces must be square and non-empty, this one is {}x{}", f.width, f.height)));
        }
        if f.width != size {
            return Err((i, format!("is {0}x{0} but face +x is {size}x{size}", f.width)));
        }
    }
    Ok(())
}

/// The six face files of a cube-map directory, in [`FACE_LABELS`] order.
fn find_faces(dir: &Path) -> Result<[PathBuf; 6]> {
    let mut found: [Option<PathBuf>; 6] = Default::default();
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    for entry in entries {
        let path = entry.map_err(|e| Error::io(dir, e))?.path();
        let (Some(stem), Some(ext)) = (path.file_stem(), path.extension()) else {
            continue;
        };
        let (stem, ext) = (stem.to_string_lossy().to_lowercase(), ext.to_string_lossy().to_lowercase());
        if !IMAGE_EXTENSIONS.contains(&ext.as_str()) {
            continue;
        }
        let Some(face) = FACE_NAMES.iter().position(|names| names.contains(&stem.as_str())) else {
            continue;
        };
        if let Some(other) = &found[face] {
            return Err(Error::input(
                Location::file(dir),
                format!("two files for cube face {}: {} and {}", FACE_LABELS[face], file_name(other), file_name(&path)),
            ));
        }
        found[face] = Some(path);
    }
    if let [Some(a), Some(b), Some(c), Some(d), Some(e), Some(f)] = found {
        return Ok([a, b, c, d, e, f]);
    }
    let missing: Vec<String> = (0..6)
        .filter(|&i| found[i].is_none())
        .map(|i| format!("{} ({})", FACE_LABELS[i], FACE_NAMES[i].join(", ")))
        .collect();
    Err(Error::input(Location::file(dir), format!("cube map directory lacks faces {}", missing.join("; "))))
}

fn file_name(path: &Path) -> String {
    path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

fn eval_latlong(film: &Film, dir: Vec3) -> Color {
    let d = dir.normalize();
    let u = 0.5 + d.x.atan2(-d.z) / (2.0 * PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    let (w, h) = (film.width as i64, film.height as i64);
    let x = u * w as f32 - 0.5;
    let y = v * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    // Wrap in longitude; clamp at the poles, where a row is a single point.
    let px = |i: i64| i.rem_euclid(w) as u32;
    let py = |j: i64| j.clamp(0, h - 1) as u32;
    let row = |j: i64| film.get(px(x0), py(j)).lerp(film.get(px(x0 + 1), py(j)), fx);
    row(y0).lerp(row(y0 + 1), fy)
}

/// Bilinear lookup in a light probe, clamped at the image's border (the disc's rim is one direction).
fn eval_probe(film: &Film, dir: Vec3) -> Color {
    let d = dir.normalize();
    let rho = (d.x * d.x + d.y * d.y).sqrt();
    // Straight behind the centre every point of the rim is the same direction; take the right one.
    let (sx, sy) = if rho > 0.0 {
        let r = (-d.z).clamp(-1.0, 1.0).acos() / (PI * rho);
        (d.x * r, d.y * r)
    } else if d.z < 0.0 {
        (0.0, 0.0)
    } else {
        (1.0, 0.0)
    };
    let x = (sx + 1.0) * 0.5 * film.width as f32 - 0.5;
    let y = (1.0 - sy) * 0.5 * film.height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let px = |i: i64| i.clamp(0, film.width as i64 - 1) as u32;
    let py = |j: i64| j.clamp(0, film.height as i64 - 1) as u32;
    let row = |j: i64| film.get(px(x0), py(j)).lerp(film.get(px(x0 + 1), py(j)), fx);
    row(y0).lerp(row(y0 + 1), fy)
}

/// `(sc, tc, |ma|)` of `d` on `face`, from the table in the module documentation.
fn face_coords(face: usize, d: Vec3) -> (f32, f32, f32) {
    match face {
        0 => (-d.z, -d.y, d.x.abs()),
        1 => (d.z, -d.y, d.x.abs()),
        2 => (d.x, d.z, d.y.abs()),
        3 => (d.x, -d.z, d.y.abs()),
        4 => (d.x, -d.y, d.z.abs()),
        _ => (-d.x, -d.y, d.z.abs()),
    }
}

/// The point of `face`'s plane (at distance 1) with coordinates `(sc, tc)`: the inverse of [`face_coords`].
fn face_point(face: usize, sc: f32, tc: f32) -> Vec3 {
    match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    }
}

/// The face a direction hits: the axis of its largest component (ties go to x, then y).
fn major_face(d: Vec3) -> usize {
    let a = d.abs();
    let (axis, neg) = if a.x >= a.y && a.x >= a.z {
        (0, d.x < 0.0)
    } else if a.y >= a.z {
        (1, d.y < 0.0)
    } else {
        (2, d.z < 0.0)
    };
    2 * axis + usize::from(neg)
}

fn eval_cube(faces: &[Film; 6], size: u32, dir: Vec3) -> Color {
    let face = major_face(dir);
    let (sc, tc, ma) = face_coords(face, dir);
    let n = size as f32;
    let x = (sc / ma + 1.0) * 0.5 * n - 0.5;
    let y = (tc / ma + 1.0) * 0.5 * n - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let cube = Cube { faces, size: size as i64 };
    let row = |j: i64| cube.fetch(face, x0, j).lerp(cube.fetch(face, x0 + 1, j), fx);
    row(y0).lerp(row(y0 + 1), fy)
}

struct Cube<'a> {
    faces: &'a [Film; 6],
    size: i64,
}

impl Cube<'_> {
    /// Texel `(i, j)` of `face`, where `i` and `j` may be one step outside the face: then the adjacent
    /// face's edge texel stands in, and at a corner the mean of the three texels meeting there.
    fn fetch(&self, face: usize, i: i64, j: i64) -> Color {
        let inside = |k: i64| (0..self.size).contains(&k);
        let clamp = |k: i64| k.clamp(0, self.size - 1);
        match (inside(i), inside(j)) {
            (true, true) => self.texel(face, i, j),
            (false, false) => {
                (self.across(face, clamp(i), j) + self.across(face, i, clamp(j)) + self.texel(face, clamp(i), clamp(j)))
                    / 3.0
            }
            _ => self.across(face, i, j),
        }
    }

    fn texel(&self, face: usize, i: i64, j: i64) -> Color {
        self.faces[face].get(i as u32, j as u32)
    }

    /// The texel of the adjacent face that borders `face`'s edge texel next to `(i, j)`, where exactly one
    /// of `i`, `j` is just outside `face`.
    fn across(&self, face: usize, i: i64, j: i64) -> Color {
        let n = self.size as f32;
        let centre = |k: i64| (2 * k + 1) as f32 / n - 1.0;
        let edge = |k: i64| if k < 0 { -1.0 } else { 1.0 };
        let outside = |k: i64| !(0..self.size).contains(&k);
        let (sc, tc) = (if outside(i) { edge(i) } else { centre(i) }, if outside(j) { edge(j) } else { centre(j) });
        // On the shared edge both faces tie for the major axis; pushing the point a little past the edge
        // picks the neighbour. Its coordinates come from the exact edge point so the texel along the edge
        // is found at its centre, far from any rounding boundary.
        let on_edge = face_point(face, sc, tc);
        let beyond = face_point(face, if outside(i) { sc * 1.01 } else { sc }, if outside(j) { tc * 1.01 } else { tc });
        let next = major_face(beyond);
        let (nsc, ntc, nma) = face_coords(next, on_edge);
        let index = |c: f32| (((c / nma + 1.0) * 0.5 * n).floor() as i64).clamp(0, self.size - 1);
        self.texel(next, index(nsc), index(ntc))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(w: u32, h: u32, f: impl Fn(u32, u32) -> Color) -> Film {
        let mut film = Film::new(w, h);
        for y in 0..h {
            for x in 0..w {
                film.pixels[(y * w + x) as usize] = f(x, y);
            }
        }
        film
    }

    fn close(a: Color, b: Color, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol
    }

    const PX: Color = Color::new(1.0, 0.0, 0.0);
    const NX: Color = Color::new(0.0, 1.0, 0.0);
    const PY: Color = Color::new(0.0, 0.0, 1.0);
    const NY: Color = Color::new(1.0, 1.0, 0.0);
    const PZ: Color = Color::new(0.0, 1.0, 1.0);
    const NZ: Color = Color::new(1.0, 0.0, 1.0);

    /// 8x4: row 0 is +y, row 3 is -y; rows 1-2 in column pairs {7,0} +z, {1,2} -x, {3,4} -z, {5,6} +x,
    /// so that each axis lands between two texels of its own colour.
    fn axis_latlong() -> EnvMap {
        EnvMap::from_film_latlong(film(8, 4, |x, y| match (y, x) {
            (0, _) => PY,
            (3, _) => NY,
            (_, 7 | 0) => PZ,
            (_, 1 | 2) => NX,
            (_, 3 | 4) => NZ,
            _ => PX,
        }))
    }

    #[test]
    fn latlong_axes_hit_expected_pixels() {
        let map = axis_latlong();
        let cases = [(Vec3::X, PX), (-Vec3::X, NX), (Vec3::Y, PY), (-Vec3::Y, NY), (Vec3::Z, PZ), (-Vec3::Z, NZ)];
        for (dir, want) in cases {
            assert_eq!(map.eval(dir * 3.0), want, "direction {dir}");
        }
    }

    #[test]
    fn latlong_bilinear_between_pixel_centres() {
        // A gradient along the columns: -z looks at u = 0.5, halfway between columns 1 and 2 of 4.
        let map = EnvMap::from_film_latlong(film(4, 2, |x, _| Color::splat(x as f32)));
        assert!(close(map.eval(-Vec3::Z), Color::splat(1.5), 1e-5));
        // +z looks at the wrap-around: halfway between the last column and the first.
        assert!(close(map.eval(Vec3::Z), Color::splat(1.5), 1e-5));
        // Just left of +z (towards -x) and just right (towards +x) are close to each other.
        let a = map.eval(Vec3::new(-1e-3, 0.0, 1.0));
        let b = map.eval(Vec3::new(1e-3, 0.0, 1.0));
        assert!(close(a, b, 0.01), "{a} vs {b}");
    }

    #[test]
    fn eval_degenerate_direction_is_black() {
        let map = axis_latlong();
        for d in [Vec3::ZERO, Vec3::NAN, Vec3::new(f32::INFINITY, 0.0, 0.0)] {
            assert_eq!(map.eval(d), Color::ZERO);
        }
    }

    fn solid_faces(size: u32) -> [Film; 6] {
        [PX, NX, PY, NY, PZ, NZ].map(|c| film(size, size, |_, _| c))
    }

    #[test]
    fn cube_axes_return_their_face_colour() {
        let map = EnvMap::from_faces(solid_faces(4)).unwrap();
        assert!(map.is_cube_map());
        let cases = [(Vec3::X, PX), (-Vec3::X, NX), (Vec3::Y, PY), (-Vec3::Y, NY), (Vec3::Z, PZ), (-Vec3::Z, NZ)];
        for (dir, want) in cases {
            assert_eq!(map.eval(dir * 0.5), want, "direction {dir}");
        }
    }

    #[test]
    fn cube_texel_positions_match_hand_computed_table() {
        // 2x2 faces, one colour per (face, column, row); each direction below hits a texel centre exactly,
        // its texel worked out by hand from the Khronos table (s = column, t = row from the top).
        let code = |face: usize, x: u32, y: u32| Color::new(face as f32, x as f32, y as f32);
        let faces: [Film; 6] = std::array::from_fn(|f| film(2, 2, |x, y| code(f, x, y)));
        let map = EnvMap::from_faces(faces).unwrap();
        let cases = [
            (Vec3::new(1.0, 0.5, -0.5), 0, 1, 0),  // +x: sc = -z = 0.5, tc = -y = -0.5
            (Vec3::new(-1.0, 0.5, -0.5), 1, 0, 0), // -x: sc = z = -0.5, tc = -y = -0.5
            (Vec3::new(0.5, 1.0, 0.5), 2, 1, 1),   // +y: sc = x = 0.5, tc = z = 0.5
            (Vec3::new(0.5, -1.0, 0.5), 3, 1, 0),  // -y: sc = x = 0.5, tc = -z = -0.5
            (Vec3::new(-0.5, -0.5, 1.0), 4, 0, 1), // +z: sc = x = -0.5, tc = -y = 0.5
            (Vec3::new(0.5, 0.5, -1.0), 5, 0, 0),  // -z: sc = -x = -0.5, tc = -y = -0.5
        ];
        for (d, face, x, y) in cases {
            assert_eq!(map.eval(d * 2.0), code(face, x, y), "direction {d}");
        }
    }

    /// Faces painted with the direction of each texel centre, so a seamless lookup approximates the
    /// smooth function `0.5 + 0.5 * normalize(d)` everywhere, edges included.
    fn direction_faces(size: u32) -> [Film; 6] {
        let n = size as f32;
        std::array::from_fn(|face| {
            film(size, size, |x, y| {
                let (sc, tc) = ((2 * x + 1) as f32 / n - 1.0, (2 * y + 1) as f32 / n - 1.0);
                0.5 + 0.5 * face_point(face, sc, tc).normalize()
            })
        })
    }

    #[test]
    fn cube_face_orientation_follows_opengl_table() {
        // Looking along d, the map must return roughly 0.5 + 0.5 d if every face is oriented as documented.
        let map = EnvMap::from_faces(direction_faces(16)).unwrap();
        for d in [
            Vec3::new(1.0, 0.4, -0.3),
            Vec3::new(-1.0, -0.5, 0.2),
            Vec3::new(0.3, 1.0, 0.6),
            Vec3::new(-0.2, -1.0, 0.7),
            Vec3::new(0.45, -0.35, 1.0),
            Vec3::new(-0.6, 0.25, -1.0),
        ] {
            let want = 0.5 + 0.5 * d.normalize();
            assert!(close(map.eval(d), want, 0.03), "{d}: {} vs {want}", map.eval(d));
        }
    }

    #[test]
    fn cube_lookups_are_continuous_across_edges_and_corners() {
        let map = EnvMap::from_faces(direction_faces(8)).unwrap();
        let e = 1e-4;
        // Pairs of directions on either side of an edge (or next to a corner), from several faces.
        let pairs = [
            (Vec3::new(1.0, 0.3, 1.0 - e), Vec3::new(1.0 - e, 0.3, 1.0)), // +x | +z
            (Vec3::new(1.0, 0.7, -1.0 + e), Vec3::new(1.0 - e, 0.7, -1.0)), // +x | -z
            (Vec3::new(-0.2, 1.0, 1.0 - e), Vec3::new(-0.2, 1.0 - e, 1.0)), // +y | +z
            (Vec3::new(-1.0, -1.0 + e, 0.6), Vec3::new(-1.0 + e, -1.0, 0.6)), // -x | -y
            (Vec3::new(0.9, -1.0, -1.0 + e), Vec3::new(0.9, -1.0 + e, -1.0)), // -y | -z
            (Vec3::new(1.0, 1.0 - e, 1.0 - e), Vec3::new(1.0 - e, 1.0, 1.0 - e)), // corner +x +y +z
            (Vec3::new(1.0 - e, 1.0 - e, 1.0), Vec3::new(1.0, 1.0 - e, 1.0 - e)),
        ];
        for (a, b) in pairs {
            let (ca, cb) = (map.eval(a), map.eval(b));
            assert!(close(ca, cb, 2e-3), "{a} -> {ca} but {b} -> {cb}");
        }
    }

    #[test]
    fn cube_faces_must_be_square_and_equal() {
        let mut faces = solid_faces(4);
        faces[3] = film(4, 3, |_, _| NY);
        let err = EnvMap::from_faces(faces).unwrap_err().to_string();
        assert!(err.contains("cube face -y") && err.contains("4x3"), "{err}");
        let mut faces = solid_faces(4);
        faces[5] = film(2, 2, |_, _| NZ);
        let err = EnvMap::from_faces(faces).unwrap_err().to_string();
        assert!(err.contains("cube face -z") && err.contains("is 2x2 but face +x is 4x4"), "{err}");
    }

    #[test]
    fn probe_centre_looks_down_minus_z_and_angle_grows_linearly_to_the_rim() {
        // 4x4 probe, pixel (i, j) holds 4 j + i.
        let film = Film { width: 4, height: 4, pixels: (0..16).map(|k| Color::splat(k as f32)).collect() };
        let map = EnvMap::from_film_probe(film);
        // -z is the centre, (s, t) = (0, 0): pixel coordinates (1.5, 1.5), the mean of 5, 6, 9, 10.
        assert_eq!(map.eval(-Vec3::Z), Color::splat(7.5));
        // 45° from -z towards +x: a quarter of the way to the rim, (0.25, 0): (2.0, 1.5), pixels 6 and 10.
        assert_eq!(map.eval(Vec3::new(1.0, 0.0, -1.0)), Color::splat(8.0));
        // +x, 90° away: half way, (0.5, 0): (2.5, 1.5), pixels 6, 7, 10, 11. +y: (0, 0.5): (1.5, 0.5),
        // pixels 1, 2, 5, 6.
        assert_eq!(map.eval(Vec3::X), Color::splat(8.5));
        assert_eq!(map.eval(Vec3::Y), Color::splat(3.5));
        // +z is the rim: (1, 0), (3.5, 1.5) clamped to column 3, pixels 7 and 11.
        assert_eq!(map.eval(Vec3::Z), Color::splat(9.0));
    }
}
