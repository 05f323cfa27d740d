//! Image files through the public API: round trips per format, quantisation, atomic writes, reading
//! foreign layouts (RGBA, grey, 16-bit), file comparison and the environment map built from files.

use std::fs;
use std::path::Path;

use arbor::film::Film;
use arbor::image_io::{compare_files, read_image, read_rgb8, write_image, ImageLimits};
use arbor::math::Color;

/// A film whose every channel is an exact 8-bit level, all levels distinct across the image.
fn level_film(width: u32, height: u32) -> Film {
    let mut film = Film::new(width, height);
    for (i, p) in film.pixels.iter_mut().enumerate() {
        let k = (i * 3) as f32;
        *p = Color::new(k % 256.0, (k + 1.0) % 256.0, (k + 2.0) % 256.0) / 255.0;
    }
    film
}

/// Files in `dir` other than `keep`: a failed write must leave no temporary behind.
fn strays(dir: &Path, keep: &[&str]) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect();
    names.sort();
    names
}

#[test]
fn png_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.png");
    let film = level_film(11, 7);
    write_image(&path, &film).unwrap();
    let (w, h, rgb) = read_rgb8(&path).unwrap();
    assert_eq!((w, h), (11, 7));
    assert_eq!(rgb, film.to_rgb8());
    let back = read_image(&path).unwrap();
    assert_eq!((back.width, back.height), (11, 7));
    for (a, b) in back.pixels.iter().zip(&film.pixels) {
        assert!((*a - *b).abs().max_element() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn ppm_round_trip_is_exact_binary_p6() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.ppm");
    let film = level_film(5, 4);
    write_image(&path, &film).unwrap();
    let bytes = fs::read(&path).unwrap();
    assert!(bytes.starts_with(b"P6"), "not binary PPM: {:?}", &bytes[..2]);
    assert!(bytes.ends_with(&film.to_rgb8()), "pixel data is not the 8-bit film");
    assert_eq!(read_rgb8(&path).unwrap(), (5, 4, film.to_rgb8()));
}

#[test]
fn exr_round_trip_keeps_float_values() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.exr");
    let mut film = Film::new(3, 2);
    film.pixels = vec![
        Color::new(0.0, 0.5, 1.0),
        Color::new(2.5, 1000.0, 1e-4),
        Color::new(-0.25, 0.1, 0.3333),
        Color::new(1.0 / 3.0, 7.0, 65504.0),
        Color::new(123.456, 0.0, 1.5),
        Color::new(0.2, 0.4, 0.6),
    ];
    write_image(&path, &film).unwrap();
    assert_eq!(read_image(&path).unwrap(), film);
}

#[test]
fn exr_files_are_the_same_bytes_for_the_same_pixels() {
    // Blocks are compressed in parallel: written in increasing line order, not as they finish.
    let dir = tempfile::tempdir().unwrap();
    let film = level_film(700, 300);
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    write_image(&a, &film).unwrap();
    write_image(&b, &film).unwrap();
    let bytes = fs::read(&a).unwrap();
    assert!(bytes == fs::read(&b).unwrap(), "two writes of one film differ");
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).unwrap();
    assert_eq!(meta.headers[0].line_order, exr::meta::attribute::LineOrder::Increasing);
}

#[test]
fn write_quantises_half_levels_up_and_clamps() {
    let dir = tempfile::tempdir().unwrap();
    let mut film = Film::new(8, 1);
    film.pixels = [
        0.5,            // 127.5 exactly: half goes up
        100.49 / 255.0, // just below a half level
        100.51 / 255.0, // just above
        0.49 / 255.0,   // rounds to 0
        254.51 / 255.0, // rounds to 255
        1.7,            // clamped
        -0.3,           // clamped
        f32::NAN,       // black
    ]
    .map(Color::splat)
    .to_vec();
    let expected: Vec<u8> = [128u8, 100, 101, 0, 255, 255, 0, 0].iter().flat_map(|&v| [v; 3]).collect();
    for name in ["q.png", "q.ppm"] {
        let path = dir.path().join(name);
        write_image(&path, &film).unwrap();
        assert_eq!(read_rgb8(&path).unwrap().2, expected, "{name}");
    }
}

#[test]
fn write_extension_is_case_insensitive_and_creates_parent() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a/b/OUT.PNG");
    write_image(&path, &level_film(2, 2)).unwrap();
    assert_eq!(read_rgb8(&path).unwrap().2, level_film(2, 2).to_rgb8());
}

#[test]
fn write_replaces_an_existing_image_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.png");
    write_image(&path, &Film::new(4, 4)).unwrap();
    write_image(&path, &level_film(3, 2)).unwrap();
    assert_eq!(read_rgb8(&path).unwrap(), (3, 2, level_film(3, 2).to_rgb8()));
    assert_eq!(strays(dir.path(), &["out.png"]), Vec::<String>::new());
}

#[test]
fn write_unknown_extension_names_it_and_keeps_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bmp");
    fs::write(&path, b"old contents").unwrap();
    let err = write_image(&path, &level_film(2, 2)).unwrap_err().to_string();
    assert!(err.contains("\".bmp\""), "{err}");
    assert!(err.contains("png, ppm, exr, hdr, jpg, jpeg"), "{err}");
    assert_eq!(fs::read(&path).unwrap(), b"old contents");
    assert_eq!(strays(dir.path(), &["out.bmp"]), Vec::<String>::new());

    let err = write_image(&dir.path().join("noext"), &level_film(1, 1)).unwrap_err();
    assert!(err.to_string().contains("no image extension"), "{err}");
}

#[test]
fn write_onto_a_directory_fails_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("out.png");
    fs::create_dir(&target).unwrap();
    fs::write(target.join("inside.txt"), b"keep me").unwrap();
    let err = write_image(&target, &level_film(2, 2)).unwrap_err();
    assert!(err.is_io(), "{err}");
    assert!(err.to_string().contains("out.png"), "{err}");
    assert_eq!(fs::read(target.join("inside.txt")).unwrap(), b"keep me");
    assert_eq!(strays(dir.path(), &["out.png"]), Vec::<String>::new());
}

#[test]
fn write_inconsistent_film_fails_and_keeps_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.exr");
    write_image(&path, &level_film(2, 2)).unwrap();
    let before = fs::read(&path).unwrap();
    let mut bad = level_film(2, 2);
    bad.pixels.pop();
    assert!(write_image(&path, &bad).is_err());
    assert!(write_image(&path, &Film::new(0, 3)).is_err());
    assert_eq!(fs::read(&path).unwrap(), before);
    assert_eq!(strays(dir.path(), &["out.exr"]), Vec::<String>::new());
}

#[test]
fn read_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.png");
    let err = read_image(&missing).unwrap_err();
    assert!(err.is_io() && err.to_string().contains("missing.png"), "{err}");
    let garbage = dir.path().join("garbage.png");
    fs::write(&garbage, b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let err = read_rgb8(&garbage).unwrap_err();
    assert!(!err.is_io() && err.to_string().contains("garbage.png"), "{err}");
}

#[test]
fn read_converts_rgba_grey_and_16_bit() {
    let dir = tempfile::tempdir().unwrap();
    let rgba = dir.path().join("rgba.png");
    image::RgbaImage::from_raw(2, 1, vec![10, 20, 30, 0, 40, 50, 60, 128]).unwrap().save(&rgba).unwrap();
    assert_eq!(read_rgb8(&rgba).unwrap(), (2, 1, vec![10, 20, 30, 40, 50, 60]));

    let grey = dir.path().join("grey.png");
    image::GrayImage::from_raw(2, 1, vec![7, 200]).unwrap().save(&grey).unwrap();
    assert_eq!(read_rgb8(&grey).unwrap().2, vec![7, 7, 7, 200, 200, 200]);

    let deep = dir.path().join("deep.png");
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(1, 1, vec![0u16, 65535, 13107]).unwrap().save(&deep).unwrap();
    let film = read_image(&deep).unwrap();
    assert!((film.pixels[0] - Color::new(0.0, 1.0, 0.2)).abs().max_element() < 1e-6);
}

#[test]
fn compare_files_rgba_reference_equals_rgb_image() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref.png");
    image::RgbaImage::from_raw(2, 1, vec![10, 20, 30, 255, 40, 50, 60, 255]).unwrap().save(&reference).unwrap();
    let image = dir.path().join("image.ppm");
    let mut film = Film::new(2, 1);
    film.pixels = vec![Color::new(10.0, 20.0, 30.0) / 255.0, Color::new(40.0, 50.0, 60.0) / 255.0];
    write_image(&image, &film).unwrap();
    let c = compare_files(&reference, &image, 0, &ImageLimits::DEFAULT).unwrap();
    assert!(c.identical() && c.psnr.is_infinite(), "{}", c.summary());
    assert_eq!((c.width, c.height, c.pixels_off), (2, 1, 0));
}

#[test]
fn compare_files_size_mismatch_error_text() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref.png");
    let image = dir.path().join("image.png");
    write_image(&reference, &Film::new(8, 8)).unwrap();
    write_image(&image, &Film::new(6, 4)).unwrap();
    let err = compare_files(&reference, &image, 0, &ImageLimits::DEFAULT).unwrap_err();
    assert_eq!(err.to_string(), format!("{} is 6x4 but the reference {} is 8x8", image.display(), reference.display()));
}

#[test]
fn compare_files_counts_a_pixel_off_by_nine() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref.png");
    let image = dir.path().join("image.png");
    let film = Film { width: 4, height: 4, pixels: vec![Color::splat(100.0 / 255.0); 16] };
    let mut off = film.clone();
    off.pixels[5].z = 109.0 / 255.0;
    write_image(&reference, &film).unwrap();
    write_image(&image, &off).unwrap();
    let c = compare_files(&reference, &image, 8, &ImageLimits::DEFAULT).unwrap();
    assert_eq!((c.pixels_off, c.max_diff), (1, 9));
    assert_eq!(c.share_off, 1.0 / 16.0);
    assert_eq!(compare_files(&reference, &image, 9, &ImageLimits::DEFAULT).unwrap().pixels_off, 0);
}

fn solid(size: u32, c: Color) -> Film {
    Film { width: size, height: size, pixels: vec![c; (size * size) as usize] }
}

#[test]
fn envmap_loads_cube_faces_by_any_naming_scheme() {
    use arbor::light::environment::EnvMap;
    use arbor::math::Vec3;
    let dir = tempfile::tempdir().unwrap();
    let c = |v: f32| Color::new(v, 1.0 - v, 0.5);
    let files = [
        ("px.png", 0.0),
        ("NEGX.PNG", 0.2),
        ("top.exr", 0.4),
        ("bottom.ppm", 0.6),
        ("posz.png", 0.8),
        ("back.png", 1.0),
    ];
    for (name, v) in files {
        write_image(&dir.path().join(name), &solid(4, c(v))).unwrap();
    }
    fs::write(dir.path().join("readme.txt"), b"not a face").unwrap();
    let map = EnvMap::load(dir.path(), &ImageLimits::DEFAULT).unwrap();
    assert!(map.is_cube_map());
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for (axis, (name, v)) in axes.iter().zip(files) {
        // 8-bit faces come back as levels / 255.
        let want = Color::new(
            arbor::film::quantize(c(v).x) as f32,
            arbor::film::quantize(c(v).y) as f32,
            arbor::film::quantize(c(v).z) as f32,
        ) / 255.0;
        let want = if name.ends_with(".exr") { c(v) } else { want };
        let got = map.eval(*axis);
        assert!((got - want).abs().max_element() < 1e-6, "{name}: {got} vs {want}");
    }
}

#[test]
fn envmap_cube_directory_lists_missing_and_duplicate_faces() {
    use arbor::light::environment::EnvMap;
    let dir = tempfile::tempdir().unwrap();
    for name in ["px.png", "nx.png", "py.png", "nz.png"] {
        write_image(&dir.path().join(name), &solid(2, Color::ONE)).unwrap();
    }
    let err = EnvMap::load(dir.path(), &ImageLimits::DEFAULT).unwrap_err().to_string();
    assert_eq!(
        err,
        format!("{}: cube map directory lacks faces -y (ny, negy, bottom); +z (pz, posz, front)", dir.path().display())
    );
    write_image(&dir.path().join("ny.png"), &solid(2, Color::ONE)).unwrap();
    write_image(&dir.path().join("front.png"), &solid(2, Color::ONE)).unwrap();
    write_image(&dir.path().join("posz.exr"), &solid(2, Color::ONE)).unwrap();
    let err = EnvMap::load(dir.path(), &ImageLimits::DEFAULT).unwrap_err().to_string();
    assert!(err.contains("two files for cube face +z"), "{err}");
    fs::remove_file(dir.path().join("posz.exr")).unwrap();
    write_image(&dir.path().join("ny.png"), &solid(3, Color::ONE)).unwrap();
    let err = EnvMap::load(dir.path(), &ImageLimits::DEFAULT).unwrap_err().to_string();
    assert!(err.contains("ny.png") && err.contains("is 3x3 but face +x is 2x2"), "{err}");
}

#[test]
fn envmap_loads_latlong_file_and_names_missing_one() {
    use arbor::light::environment::EnvMap;
    use arbor::math::Vec3;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sky.exr");
    let mut film = Film::new(4, 2);
    // Top row bright (+y), bottom row dark.
    for x in 0..4 {
        film.pixels[x] = Color::splat(5.0);
        film.pixels[4 + x] = Color::splat(0.25);
    }
    write_image(&path, &film).unwrap();
    let map = EnvMap::load(&path, &ImageLimits::DEFAULT).unwrap();
    assert!(!map.is_cube_map());
    assert_eq!(map.eval(Vec3::Y), Color::splat(5.0));
    assert_eq!(map.eval(-Vec3::Y), Color::splat(0.25));
    let err = EnvMap::load(&dir.path().join("nope.hdr"), &ImageLimits::DEFAULT).unwrap_err();
    assert!(err.to_string().contains("nope.hdr"), "{err}");
}

#[test]
fn read_jpeg_and_radiance_hdr() {
    let dir = tempfile::tempdir().unwrap();
    let jpeg = dir.path().join("flat.JPG");
    image::RgbImage::from_pixel(8, 8, image::Rgb([200, 100, 50])).save(&jpeg).unwrap();
    let film = read_image(&jpeg).unwrap();
    let want = Color::new(200.0, 100.0, 50.0) / 255.0;
    assert!((film.get(3, 3) - want).abs().max_element() < 4.0 / 255.0, "{}", film.get(3, 3));

    let hdr = dir.path().join("bright.hdr");
    image::Rgb32FImage::from_pixel(2, 2, image::Rgb([4.0, 0.5, 100.0])).save(&hdr).unwrap();
    let film = read_image(&hdr).unwrap();
    let want = Color::new(4.0, 0.5, 100.0);
    // RGBE keeps 8 mantissa bits shared by the three channels.
    assert!(((film.get(1, 1) - want) / want).abs().max_element() < 0.01, "{}", film.get(1, 1));
}

#[test]
fn jpeg_write_is_8_bit_and_close_to_the_film() {
    let dir = tempfile::tempdir().unwrap();
    let mut film = Film::new(16, 8);
    for (i, p) in film.pixels.iter_mut().enumerate() {
        *p = if i % 16 < 8 { Color::new(0.8, 0.2, 0.1) } else { Color::new(0.1, 0.3, 0.9) };
    }
    for name in ["out.jpg", "out.JPEG"] {
        let path = dir.path().join(name);
        write_image(&path, &film).unwrap();
        assert!(fs::read(&path).unwrap().starts_with(&[0xff, 0xd8, 0xff]), "{name} is not a JPEG");
        let (w, h, rgb) = read_rgb8(&path).unwrap();
        assert_eq!((w, h), (16, 8));
        let want = film.to_rgb8();
        let max = rgb.iter().zip(&want).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
        assert!(max <= 24, "{name}: a channel is off by {max} levels");
    }
}

#[test]
fn write_into_a_read_only_folder_names_the_target_not_the_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let locked = dir.path().join("locked");
    fs::create_dir(&locked).unwrap();
    let mut perms = fs::metadata(&locked).unwrap().permissions();
    perms.set_readonly(true);
    fs::set_permissions(&locked, perms).unwrap();
    // Root ignores permission bits: then a folder no one may create files in stands in.
    let folder = if fs::write(locked.join("probe"), b"").is_ok() { Path::new("/sys").to_path_buf() } else { locked };
    let target = folder.join("out.png");
    let err = write_image(&target, &level_film(2, 2)).unwrap_err();
    assert!(err.is_io(), "{err}");
    let msg = err.to_string();
    assert!(msg.starts_with(&format!("{}: ", target.display())) && !msg.contains(".tmp"), "{msg}");
}

#[test]
fn write_outputs_hdr_image_gets_a_tone_mapped_png_beside() {
    use arbor::image_io::write_outputs;
    use arbor::tonemap::Tonemap;
    let dir = tempfile::tempdir().unwrap();
    let film = Film { width: 2, height: 1, pixels: vec![Color::new(0.5, 2.0, 40.0), Color::splat(3.0)] };
    let tm = Tonemap::PREVIEW;
    for ext in ["exr", "hdr"] {
        let path = dir.path().join(format!("out.{ext}"));
        let written = write_outputs(&path, &film, 1.0, Some(&tm)).unwrap();
        assert_eq!(written, vec![path.clone(), dir.path().join("out.png")]);
        let back = read_image(&path).unwrap();
        for (a, b) in back.pixels.iter().zip(&film.pixels) {
            // RGBE keeps 8 bits of mantissa per channel, relative to the largest channel.
            assert!((*a - *b).abs().max_element() <= 0.01 * b.max_element(), "{ext}: {a} vs {b}");
        }
        let (_, _, png) = read_rgb8(&dir.path().join("out.png")).unwrap();
        assert_eq!(png, tm.apply(&film).to_rgb8());
    }
    // Without a tone mapping, only the image asked for; an 8-bit one with it gets the mapped values.
    let plain = dir.path().join("plain.exr");
    assert_eq!(write_outputs(&plain, &film, 1.0, None).unwrap(), vec![plain.clone()]);
    assert!(!dir.path().join("plain.png").exists());
    let ldr = dir.path().join("ldr.png");
    assert_eq!(write_outputs(&ldr, &film, 1.0, Some(&tm)).unwrap(), vec![ldr.clone()]);
    assert_eq!(read_rgb8(&ldr).unwrap().2, tm.apply(&film).to_rgb8());
}

#[test]
fn write_outputs_hdr_images_hold_radiance_in_the_scene_units() {
    use arbor::image_io::write_outputs;
    let dir = tempfile::tempdir().unwrap();
    // A METU film: one unit of radiance is 1/255 of white, so white is radiance 255.
    let film = Film { width: 2, height: 1, pixels: vec![Color::new(1.0, 0.5, 0.0), Color::splat(2.0)] };
    let radiance = [Color::new(255.0, 127.5, 0.0), Color::splat(510.0)];
    for ext in ["exr", "hdr"] {
        let path = dir.path().join(format!("r.{ext}"));
        write_outputs(&path, &film, 1.0 / 255.0, None).unwrap();
        for (a, b) in read_image(&path).unwrap().pixels.iter().zip(&radiance) {
            assert!((*a - *b).abs().max_element() <= 0.01 * b.max_element(), "{ext}: {a} vs {b}");
        }
    }
    // 8-bit images are the film as it is.
    let png = dir.path().join("r.png");
    write_outputs(&png, &film, 1.0 / 255.0, None).unwrap();
    assert_eq!(read_rgb8(&png).unwrap().2, film.to_rgb8());
}

#[test]
fn write_outputs_hdr_pair_is_written_whole_or_not_at_all() {
    use arbor::image_io::write_outputs;
    use arbor::tonemap::Tonemap;
    let dir = tempfile::tempdir().unwrap();
    let film = level_film(2, 2);
    let (exr, png) = (dir.path().join("out.exr"), dir.path().join("out.png"));
    // A folder holds the PNG's name: its rename fails after the EXR's has been made.
    fs::create_dir(&png).unwrap();
    let refused = format!("{}: Is a directory (os error 21)", png.display());
    let err = write_outputs(&exr, &film, 1.0, Some(&Tonemap::PREVIEW)).unwrap_err();
    assert_eq!(err.to_string(), refused);
    assert_eq!(strays(dir.path(), &[]), ["out.png"], "a new EXR without its PNG, or a temporary file");
    // An older EXR is given back its contents.
    fs::write(&exr, b"older image").unwrap();
    let err = write_outputs(&exr, &film, 1.0, Some(&Tonemap::PREVIEW)).unwrap_err();
    assert_eq!(err.to_string(), refused);
    assert_eq!(fs::read(&exr).unwrap(), b"older image");
    assert_eq!(strays(dir.path(), &[]), ["out.exr", "out.png"]);
    // Once the name is free, both files are replaced and nothing else is left.
    fs::remove_dir(&png).unwrap();
    fs::write(&png, b"older preview").unwrap();
    let written = write_outputs(&exr, &film, 1.0, Some(&Tonemap::PREVIEW)).unwrap();
    assert_eq!(written, [exr.clone(), png.clone()]);
    assert_eq!(read_image(&exr).unwrap(), film);
    assert_eq!(read_rgb8(&png).unwrap().2, Tonemap::PREVIEW.apply(&film).to_rgb8());
    assert_eq!(strays(dir.path(), &[]), ["out.exr", "out.png"]);
}

#[test]
fn write_files_of_several_cameras_are_written_all_or_none() {
    use arbor::image_io::{encode_outputs, write_files};
    let dir = tempfile::tempdir().unwrap();
    let film = level_film(2, 2);
    let names = ["a.png", "b.ppm", "c.exr"];
    let mut files = Vec::new();
    for n in names {
        files.extend(encode_outputs(&dir.path().join(n), &film, 1.0, None).unwrap());
    }
    fs::write(dir.path().join("a.png"), b"older a").unwrap();
    fs::write(dir.path().join("b.ppm"), b"older b").unwrap();
    // The last target is a folder: its rename fails after the first two were made, and they are undone.
    fs::create_dir(dir.path().join("c.exr")).unwrap();
    let err = write_files(&files).unwrap_err();
    assert_eq!(err.to_string(), format!("{}: Is a directory (os error 21)", dir.path().join("c.exr").display()));
    assert_eq!(fs::read(dir.path().join("a.png")).unwrap(), b"older a");
    assert_eq!(fs::read(dir.path().join("b.ppm")).unwrap(), b"older b");
    assert_eq!(strays(dir.path(), &[]), ["a.png", "b.ppm", "c.exr"]);
    fs::remove_dir(dir.path().join("c.exr")).unwrap();
    write_files(&files).unwrap();
    for n in names {
        assert_eq!(read_image(&dir.path().join(n)).unwrap().to_rgb8(), film.to_rgb8(), "{n}");
    }
    assert_eq!(strays(dir.path(), &[]), names);
}

#[test]
fn write_temporary_names_fit_the_file_system_whenever_the_target_does() {
    // A 255-byte name (the usual NAME_MAX): its temporary file, `.<name>.<pid>.<n>.tmp`, would not fit.
    let dir = tempfile::tempdir().unwrap();
    // The cut the temporary name makes (at 200 bytes) falls inside the two bytes of 'é'.
    let target = dir.path().join(format!("{}é{}.png", "a".repeat(199), "a".repeat(50)));
    assert_eq!(target.file_name().unwrap().len(), 255);
    arbor::image_io::write_image(&target, &level_film(2, 2)).unwrap();
    assert_eq!(strays(dir.path(), &[]), [target.file_name().unwrap().to_str().unwrap()]);
}
