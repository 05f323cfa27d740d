//! Ray files of the peers' benchmark harness (peerbench `--dump-rays DIR`): the exact rays every peer
//! traced and the reference peer's answers, so that Arbor can trace the same rays without being linked
//! into the harness.
//!
//! Format (peerbench's README): `NAME.rays` holds one record per ray of 8 little-endian `f32`: origin
//! x y z, `t_min`, direction x y z (unit length), `t_max`; `NAME.hits` one record per ray of a
//! little-endian `f32` `t` (`+inf` on a miss) and a `u32` triangle index (`0xFFFFFFFF` on a miss), the
//! triangle index counting the mesh file's triangles after fan triangulation, as Arbor's loaders do.
//!
//! Files are checked before use, and every fault is reported with the file, the byte offset and the
//! record's index, never a panic: a length that is not a whole number of records, a file without rays,
//! two files that disagree on the number of rays; a ray with a `t_min` other than 0 (Arbor's queries
//! cover `(0, t_max)`), a non-finite origin or direction, a zero direction, or a `t_max` that is not
//! positive; a hit whose `t` is not positive and finite, or lies beyond its ray's `t_max`, or whose
//! triangle is not in the mesh, and a miss that is not exactly `(+inf, 0xFFFFFFFF)`. Such rays and
//! hits are no measurement: a NaN ray hits nothing in any structure, and a bad reference counts as a
//! mismatch that is not one.

use std::path::Path;

use crate::math::{Ray, Vec3};
use crate::{Error, Location, Result};

/// Bytes of one ray record.
pub const RAY_RECORD: usize = 32;
/// Bytes of one hit record.
pub const HIT_RECORD: usize = 8;

/// A ray of a ray file, with its query interval's end.
#[derive(Debug, Clone, Copy)]
pub struct FileRay {
    /// The ray.
    pub ray: Ray,
    /// End of the query interval (`+inf` for peerbench's rays).
    pub t_max: f32,
}

/// The reference peer's answer for one ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefHit {
    /// Distance of the hit, `+inf` on a miss.
    pub t: f32,
    /// Triangle hit, `u32::MAX` on a miss.
    pub prim: u32,
}

impl RefHit {
    /// True when the reference found a hit.
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX && self.t.is_finite()
    }
}

/// One ray set of a directory written by `peerbench --dump-rays`.
#[derive(Debug, Clone)]
pub struct RaySetFile {
    /// `primary` or `diffuse`.
    pub name: String,
    /// The rays, in file order.
    pub rays: Vec<FileRay>,
    /// The reference hits, one per ray.
    pub hits: Vec<RefHit>,
}

/// Reads `DIR/NAME.rays` and `DIR/NAME.hits`, for a mesh of `triangles` triangles.
pub fn load_ray_set(dir: &Path, name: &str, triangles: usize) -> Result<RaySetFile> {
    let rays_path = dir.join(format!("{name}.rays"));
    let hits_path = dir.join(format!("{name}.hits"));
    let rays_bytes = crate::input::load_bytes(&rays_path)?;
    let hits_bytes = crate::input::load_bytes(&hits_path)?;
    let rays = parse_rays(&rays_bytes, &rays_path)?;
    let hits = parse_hits(&hits_bytes, &hits_path)?;
    if rays.len() != hits.len() {
        return Err(Error::input(
            Location::file(&hits_path),
            format!("{} hits for {} rays in {}", hits.len(), rays.len(), rays_path.display()),
        ));
    }
    for (i, (hit, ray)) in hits.iter().zip(&rays).enumerate() {
        if !hit.is_hit() {
            continue;
        }
        let at = |field: usize| Location::byte(&hits_path, (i * HIT_RECORD + field) as u64);
        if hit.prim as usize >= triangles {
            let msg = format!("hit {i}: triangle {} is not in the mesh (it has {triangles} triangles)", hit.prim);
            return Err(Error::input(at(4), msg));
        }
        if hit.t > ray.t_max {
            let msg = format!("hit {i}: t {} lies beyond its ray's t_max {}", hit.t, ray.t_max);
            return Err(Error::input(at(0), msg));
        }
    }
    Ok(RaySetFile { name: name.to_string(), rays, hits })
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn whole_records(bytes: &[u8], record: usize, path: &Path) -> Result<usize> {
    if !bytes.len().is_multiple_of(record) {
        let whole = bytes.len() / record * record;
        return Err(Error::input(
            Location::byte(path, whole as u64),
            format!("{} bytes is not a whole number of {record}-byte records", bytes.len()),
        ));
    }
    Ok(bytes.len() / record)
}

/// Parses the bytes of a `.rays` file (`path` names it in errors).
pub fn parse_rays(bytes: &[u8], path: &Path) -> Result<Vec<FileRay>> {
    let n = whole_records(bytes, RAY_RECORD, path)?;
    if n == 0 {
        return Err(Error::input(Location::file(path), "the file holds no rays"));
    }
    let mut out = Vec::with_capacity(n);
    for (i, r) in bytes.chunks_exact(RAY_RECORD).enumerate() {
        let v: [f32; 8] = std::array::from_fn(|k| f32_at(r, 4 * k));
        let at = |field: usize| Location::byte(path, (i * RAY_RECORD + 4 * field) as u64);
        let (origin, dir) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[4], v[5], v[6]));
        let fault = if v[3] != 0.0 {
            Some((3, format!("has t_min {} (only 0 is supported: queries cover (0, t_max))", v[3])))
        } else if !origin.is_finite() {
            Some((0, format!("has a non-finite origin {origin}")))
        } else if !dir.is_finite() {
            Some((4, format!("has a non-finite direction {dir}")))
        } else if dir == Vec3::ZERO {
            Some((4, "has a zero direction".to_string()))
        } else if v[7].is_nan() || v[7] <= 0.0 {
            Some((7, format!("has t_max {} (expected a positive number or +inf)", v[7])))
        } else {
            None
        };
        if let Some((field, what)) = fault {
            return Err(Error::input(at(field), format!("ray {i} {what}")));
        }
        out.push(FileRay { ray: Ray::new(origin, dir), t_max: v[7] });
    }
    Ok(out)
}

/// Parses the bytes of a `.hits` file (`path` names it in errors): each record a hit at a positive,
/// finite `t`, or a miss, `(+inf, 0xFFFFFFFF)`.
pub fn parse_hits(bytes: &[u8], path: &Path) -> Result<Vec<RefHit>> {
    let n = whole_records(bytes, HIT_RECORD, path)?;
    let mut out = Vec::with_capacity(n);
    for (i, r) in bytes.chunks_exact(HIT_RECORD).enumerate() {
        let hit = RefHit { t: f32_at(r, 0), prim: u32::from_le_bytes([r[4], r[5], r[6], r[7]]) };
        let is_miss = hit.prim == u32::MAX;
        let fine = if is_miss { hit.t == f32::INFINITY } else { hit.t.is_finite() && hit.t > 0.0 };
        if !fine {
            let msg = if is_miss {
                format!("hit {i}: a miss (triangle {}) must have t = +inf, not {}", u32::MAX, hit.t)
            } else {
                format!("hit {i}: triangle {} at t {} (a hit's t must be positive and finite)", hit.prim, hit.t)
            };
            return Err(Error::input(Location::byte(path, (i * HIT_RECORD) as u64), msg));
        }
        out.push(hit);
    }
    Ok(out)
}

/// True when a hit at `t` (or a miss, `None`) disagrees with the reference: one hits and the other
/// does not, or the distances differ by more than `1e-4` relative (peerbench's criterion; another
/// triangle at the same distance is a shared edge, not a mismatch).
pub fn disagrees(t: Option<f32>, reference: &RefHit) -> bool {
    match (t, reference.is_hit()) {
        (None, false) => false,
        (Some(t), true) => (t - reference.t).abs() > 1e-4 * reference.t.abs().max(t.abs()),
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray_bytes(v: [f32; 8]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    #[test]
    fn ray_files_parse_rays_and_hits() {
        let mut bytes = ray_bytes([1.0, 2.0, 3.0, 0.0, 0.0, 0.0, -1.0, f32::INFINITY]);
        bytes.extend(ray_bytes([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 5.0]));
        let rays = parse_rays(&bytes, Path::new("p.rays")).unwrap();
        assert_eq!(rays.len(), 2);
        assert_eq!(rays[0].ray.origin, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(rays[0].ray.dir, Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(rays[0].t_max, f32::INFINITY);
        assert_eq!(rays[1].t_max, 5.0);
        let mut hits: Vec<u8> = 2.5f32.to_le_bytes().into_iter().chain(7u32.to_le_bytes()).collect();
        hits.extend(f32::INFINITY.to_le_bytes().into_iter().chain(u32::MAX.to_le_bytes()));
        let hits = parse_hits(&hits, Path::new("p.hits")).unwrap();
        assert_eq!(hits, vec![RefHit { t: 2.5, prim: 7 }, RefHit { t: f32::INFINITY, prim: u32::MAX }]);
        assert!(hits[0].is_hit() && !hits[1].is_hit());
    }

    #[test]
    fn ray_files_reject_truncated_files_and_nonzero_t_min() {
        let bytes = ray_bytes([0.0; 8]);
        let e = parse_rays(&bytes[..30], Path::new("p.rays")).unwrap_err().to_string();
        assert!(e.contains("p.rays") && e.contains("30 bytes is not a whole number of 32-byte records"), "{e}");
        let e = parse_hits(&[0u8; 12], Path::new("p.hits")).unwrap_err().to_string();
        assert!(e.contains("p.hits") && e.contains("byte 8"), "{e}");
        let bytes = ray_bytes([0.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 1.0]);
        let e = parse_rays(&bytes, Path::new("p.rays")).unwrap_err().to_string();
        assert!(e.contains("t_min 0.5") && e.contains("byte 12"), "{e}");
    }

    fn hit_bytes(t: f32, prim: u32) -> Vec<u8> {
        t.to_le_bytes().into_iter().chain(prim.to_le_bytes()).collect()
    }

    #[test]
    fn ray_files_missing_or_mismatched_files_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let e = load_ray_set(dir.path(), "primary", 1).unwrap_err();
        assert!(e.is_io() && e.to_string().contains("primary.rays"), "{e}");
        std::fs::write(dir.path().join("primary.rays"), ray_bytes([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0])).unwrap();
        let misses = [hit_bytes(f32::INFINITY, u32::MAX), hit_bytes(f32::INFINITY, u32::MAX)].concat();
        std::fs::write(dir.path().join("primary.hits"), misses).unwrap();
        let e = load_ray_set(dir.path(), "primary", 1).unwrap_err().to_string();
        assert!(e.contains("2 hits for 1 rays"), "{e}");
    }

    #[test]
    fn ray_files_reject_empty_files_and_rays_that_trace_nothing() {
        let p = Path::new("p.rays");
        let e =
            |v: [f32; 8]| parse_rays(&[ray_bytes([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]), ray_bytes(v)].concat(), p);
        assert_eq!(parse_rays(&[], p).unwrap_err().to_string(), "p.rays: the file holds no rays");
        let nan = f32::NAN;
        assert_eq!(
            e([nan, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]).unwrap_err().to_string(),
            "p.rays: byte 32: ray 1 has a non-finite origin [NaN, 0, 0]"
        );
        assert_eq!(
            e([0.0, 0.0, 0.0, 0.0, 1.0, f32::INFINITY, 0.0, 1.0]).unwrap_err().to_string(),
            "p.rays: byte 48: ray 1 has a non-finite direction [1, inf, 0]"
        );
        assert_eq!(
            e([0.0, 0.0, 0.0, 0.0, 0.0, -0.0, 0.0, 1.0]).unwrap_err().to_string(),
            "p.rays: byte 48: ray 1 has a zero direction"
        );
        for (t_max, shown) in [(nan, "NaN"), (0.0, "0"), (-1.0, "-1")] {
            assert_eq!(
                e([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, t_max]).unwrap_err().to_string(),
                format!("p.rays: byte 60: ray 1 has t_max {shown} (expected a positive number or +inf)")
            );
        }
    }

    #[test]
    fn ray_files_reject_hits_out_of_range() {
        let p = Path::new("p.hits");
        let e = |t: f32, prim: u32| {
            parse_hits(&[hit_bytes(2.0, 0), hit_bytes(t, prim)].concat(), p).unwrap_err().to_string()
        };
        let hit = "(a hit's t must be positive and finite)";
        assert_eq!(e(f32::NAN, 3), format!("p.hits: byte 8: hit 1: triangle 3 at t NaN {hit}"));
        assert_eq!(e(-2.0, 3), format!("p.hits: byte 8: hit 1: triangle 3 at t -2 {hit}"));
        assert_eq!(e(0.0, 3), format!("p.hits: byte 8: hit 1: triangle 3 at t 0 {hit}"));
        assert_eq!(e(f32::INFINITY, 3), format!("p.hits: byte 8: hit 1: triangle 3 at t inf {hit}"));
        assert_eq!(e(2.0, u32::MAX), "p.hits: byte 8: hit 1: a miss (triangle 4294967295) must have t = +inf, not 2");

        // Against the rays and the mesh: a triangle the mesh lacks, a hit beyond its ray's t_max.
        let dir = tempfile::tempdir().unwrap();
        let rays =
            [ray_bytes([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 5.0]), ray_bytes([0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 3.0])];
        std::fs::write(dir.path().join("diffuse.rays"), rays.concat()).unwrap();
        let load = |hits: &[Vec<u8>]| {
            std::fs::write(dir.path().join("diffuse.hits"), hits.concat()).unwrap();
            load_ray_set(dir.path(), "diffuse", 4).map(|s| s.hits.len()).map_err(|e| e.to_string())
        };
        let hits_path = dir.path().join("diffuse.hits");
        assert_eq!(load(&[hit_bytes(2.0, 3), hit_bytes(3.0, 0)]), Ok(2));
        assert_eq!(
            load(&[hit_bytes(2.0, 3), hit_bytes(1.0, 4)]),
            Err(format!("{}: byte 12: hit 1: triangle 4 is not in the mesh (it has 4 triangles)", hits_path.display()))
        );
        assert_eq!(
            load(&[hit_bytes(2.0, 3), hit_bytes(3.5, 0)]),
            Err(format!("{}: byte 8: hit 1: t 3.5 lies beyond its ray's t_max 3", hits_path.display()))
        );
    }

    #[test]
    fn ray_files_mismatch_uses_relative_tolerance() {
        let r = RefHit { t: 100.0, prim: 3 };
        assert!(!disagrees(Some(100.005), &r));
        assert!(disagrees(Some(100.02), &r));
        assert!(disagrees(None, &r));
        let miss = RefHit { t: f32::INFINITY, prim: u32::MAX };
        assert!(!disagrees(None, &miss));
        assert!(disagrees(Some(1.0), &miss));
    }
}
