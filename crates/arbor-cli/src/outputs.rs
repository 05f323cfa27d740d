//! Where `arbor render` writes, decided and checked before any rendering starts, so that a mistake in
//! an output path costs seconds, not a finished render.
//!
//! `-o` names a folder (created if missing) into which every camera's image goes under the name the
//! scene gives it, or, when it ends in an image extension, the one image of a scene with one camera (a
//! scene with several is a usage error: `-o` then names a folder). Every target, and the PNG beside an
//! HDR one, is checked: an extension Arbor writes, names and a path within the file system's limits
//! (`NAME_MAX` and `PATH_MAX` as `pathconf` reports them for the nearest existing folder), a folder that
//! exists (images and partial EXRs may also name one that can be created, as their writers create it;
//! `--stats-json` may not) and that accepts a new file (a probe file is created and removed at once,
//! which also answers for root, for whom permission bits say nothing), and a name that is not a folder.
//! A camera's image is refused at its `ImageName` (a name the file system cannot hold is the scene's
//! fault: exit 3; a folder that takes no file, the machine's: exit 4); other errors name the target file.

use std::path::{Component, Path, PathBuf};

use arbor::image_io::SUPPORTED_WRITE_EXTENSIONS;
use arbor::scene::CameraDesc;
use arbor::tonemap::Tonemap;

use crate::Failure;

/// Extensions that make `-o` an image file rather than a folder: those Arbor writes, and common image
/// formats it does not write (refused with the list of those it does, not taken as a folder name).
const IMAGE_LIKE: &[&str] = &["png", "ppm", "exr", "jpg", "jpeg", "hdr", "tif", "tiff", "bmp", "gif", "webp", "tga"];

fn ext_of(path: &Path) -> Option<String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

/// True when `-o` names an image file rather than a folder.
pub fn names_a_file(out: &Path) -> bool {
    ext_of(out).is_some_and(|e| IMAGE_LIKE.contains(&e.as_str()))
}

/// The image file of each camera of `cameras`, checked, with the PNG beside each HDR image when
/// `with_preview` (not for a debug view, which is written as it is).
pub fn image_targets(out: &Path, cameras: &[&CameraDesc], with_preview: bool) -> Result<Vec<PathBuf>, Failure> {
    if names_a_file(out) {
        if cameras.len() != 1 {
            return Err(Failure::Usage(format!(
                "-o {} names one image, but the scene has {} cameras: -o names a folder for them (or pick one \
                 with --camera ID)",
                out.display(),
                cameras.len()
            )));
        }
        check_extension(out).map_err(Failure::Usage)?;
        for file in files_written(out, with_preview) {
            check_writable(&file, true)?;
        }
        return Ok(vec![out.to_path_buf()]);
    }
    let mut targets: Vec<PathBuf> = Vec::with_capacity(cameras.len());
    // Every file written so far and its camera: the image, and the PNG beside an HDR image.
    let mut written: Vec<(PathBuf, &str)> = Vec::new();
    for cam in cameras {
        let at = format!("{}: Camera {}: ImageName '{}'", cam.name_loc, cam.id, shortened(&cam.image_name));
        let refuse = |msg: String| {
            let msg = format!("Camera {}: ImageName '{}': {msg}", cam.id, shortened(&cam.image_name));
            arbor::Error::input(cam.name_loc.clone(), msg)
        };
        if cam.image_name.contains('\0') {
            return Err(refuse("contains a NUL character, which no file name may hold".into()).into());
        }
        // A scene names its images inside the output folder: it may not write elsewhere.
        if !Path::new(&cam.image_name).components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir)) {
            return Err(refuse("must be a name inside the output folder (no absolute path, no '..')".into()).into());
        }
        let path = out.join(&cam.image_name);
        check_extension(&path).map_err(refuse)?;
        let files = files_written(&path, with_preview);
        for file in &files {
            check_lengths(file).map_err(refuse)?;
            if let Some((_, other)) = written.iter().find(|(f, _)| f == file) {
                let msg = format!("{} would also be written by camera {other}", file.display());
                return Err(refuse(msg).into());
            }
        }
        for file in &files {
            check_writable(file, true).map_err(|f| match f {
                Failure::Arbor(e) => Failure::At(at.clone(), e),
                other => other,
            })?;
        }
        written.extend(files.into_iter().map(|f| (f, cam.id.as_str())));
        targets.push(path);
    }
    Ok(targets)
}

/// An extension [`arbor::image_io::write_image`] writes.
pub fn check_extension(path: &Path) -> Result<(), String> {
    match ext_of(path) {
        Some(e) if SUPPORTED_WRITE_EXTENSIONS.contains(&e.as_str()) => Ok(()),
        Some(e) => Err(format!("cannot write .{e} images; supported: {}", SUPPORTED_WRITE_EXTENSIONS.join(", "))),
        None => Err(format!("no image extension; supported: {}", SUPPORTED_WRITE_EXTENSIONS.join(", "))),
    }
}

/// Checks that a new file can be created beside `path`. With `create`, missing folders are allowed when
/// the nearest existing one accepts files (the write creates them); without, the folder must exist.
pub fn check_writable(path: &Path, create: bool) -> Result<(), Failure> {
    let fail = |why: String| {
        let shown = PathBuf::from(shortened(&path.to_string_lossy()));
        Failure::Arbor(arbor::Error::io(shown, std::io::Error::other(why)))
    };
    check_lengths(path).map_err(|why| fail(format!("cannot write it: {why}")))?;
    if path.is_dir() {
        return Err(fail("cannot write it: it is a folder".into()));
    }
    let dir = folder_of(path);
    if !create && !dir.is_dir() {
        return Err(fail(format!("cannot write it: the folder {} does not exist", dir.display())));
    }
    let dir = nearest_existing(&dir);
    if !dir.is_dir() {
        return Err(fail(format!("cannot write it: {} is not a folder", dir.display())));
    }
    let probe = dir.join(format!(".arbor-write-probe.{}.tmp", std::process::id()));
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(file) => {
            drop(file);
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(fail(format!("cannot write it: {e}"))),
    }
}

/// The folder `path` is in (`.` for a bare name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// `dir`, or its nearest ancestor that exists (`.` at the end of a relative path).
fn nearest_existing(dir: &Path) -> PathBuf {
    let mut dir = dir.to_path_buf();
    while !dir.exists() {
        dir = folder_of(&dir);
        if dir == Path::new(".") {
            break;
        }
    }
    dir
}

/// Checks that every name in `path` and the path itself fit the file system's limits, `NAME_MAX` and
/// `PATH_MAX` (counting its final NUL), as the system reports them for the nearest existing folder; the
/// write would fail on them only after the render. The writer's temporary names fit whenever the
/// target's does (`arbor::image_io` cuts the name they keep).
fn check_lengths(path: &Path) -> Result<(), String> {
    let dir = nearest_existing(&folder_of(path));
    if let Some(max) = pathconf(&dir, libc::_PC_NAME_MAX) {
        let longest = path.components().map(|c| c.as_os_str().len()).max().unwrap_or(0);
        if longest > max {
            return Err(format!(
                "a file or folder name in it is {longest} bytes long, more than the {max} this file system takes \
                 (NAME_MAX)"
            ));
        }
    }
    if let Some(max) = pathconf(&dir, libc::_PC_PATH_MAX) {
        let n = path.as_os_str().len();
        if n >= max {
            return Err(format!("the path is {n} bytes long, more than the {} this system takes (PATH_MAX)", max - 1));
        }
    }
    Ok(())
}

/// `pathconf(dir, name)`: a limit of the file system `dir` is on; `None` when it has none or says nothing.
fn pathconf(dir: &Path, name: libc::c_int) -> Option<usize> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: `c` is a NUL-terminated string that lives across the call, which only reads it.
    let v = unsafe { libc::pathconf(c.as_ptr(), name) };
    usize::try_from(v).ok().filter(|&v| v > 0)
}

/// `s` for a message: control characters escaped (`\u{0}`), and when long only its start and end
/// around an ellipsis, so that a message about a name of 150,000 characters stays one line.
fn shortened(s: &str) -> String {
    let shown = |part: &mut dyn Iterator<Item = char>| -> String {
        part.map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() }).collect()
    };
    let n = s.chars().count();
    if n <= 64 {
        return shown(&mut s.chars());
    }
    format!("{}…{}", shown(&mut s.chars().take(40)), shown(&mut s.chars().skip(n - 16)))
}

/// The files that writing the image `path` makes: the image, and with `with_preview` beside a
/// high-dynamic-range one its tone-mapped PNG (every rendered HDR image gets one: [`hdr_preview`]).
pub fn files_written(path: &Path, with_preview: bool) -> Vec<PathBuf> {
    let beside =
        (with_preview && arbor::image_io::is_hdr_path(path)).then(|| arbor::image_io::tone_mapped_beside(path));
    std::iter::once(path.to_path_buf()).chain(beside).collect()
}

/// The tone mapping of the PNG beside a high-dynamic-range image `path` whose camera names none, for a
/// film holding `unit` per unit of scene radiance: every HDR image gets its PNG, by the course's
/// settings ([`Tonemap::PREVIEW`]); `None` for other formats.
pub fn hdr_preview(path: &Path, unit: f32) -> Option<Tonemap> {
    arbor::image_io::is_hdr_path(path).then_some(Tonemap::PREVIEW.in_units(unit))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_o_is_a_file_only_with_an_image_extension() {
        assert!(names_a_file(Path::new("out.jpg")) && names_a_file(Path::new("a/b.PNG")));
        assert!(names_a_file(Path::new("out.tiff")), "refused later, not taken for a folder");
        assert!(!names_a_file(Path::new("renders.v2")) && !names_a_file(Path::new("out")));
    }

    #[test]
    fn outputs_extension_checked_against_the_writers() {
        assert_eq!(check_extension(Path::new("a.jpeg")), Ok(()));
        assert_eq!(
            check_extension(Path::new("a.bmp")),
            Err("cannot write .bmp images; supported: png, ppm, exr, hdr, jpg, jpeg".into())
        );
    }

    #[test]
    fn outputs_missing_folder_is_an_error_unless_it_can_be_made() {
        let tmp = tempfile::tempdir().unwrap();
        let deep = tmp.path().join("a/b/img.png");
        assert!(check_writable(&deep, true).is_ok());
        assert!(!tmp.path().join("a").exists(), "checking creates nothing");
        let Err(Failure::Arbor(e)) = check_writable(&deep, false) else { panic!("a missing folder passed") };
        let want = format!(
            "{}: cannot write it: the folder {} does not exist",
            deep.display(),
            deep.parent().unwrap().display()
        );
        assert_eq!(e.to_string(), want);
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0, "the probe file is removed");
    }
}
