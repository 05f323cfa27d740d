//! The `arbor` binary as a user runs it: outputs, summary lines and exit codes.

mod common;

use std::path::Path;
use std::process::Command;
use std::sync::LazyLock;

use common::{arbor, stderr, stdout};

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The shared sphere seen by one camera of 24x16 pixels whose image is `tiny.IMAGE_EXT` (tests put in
/// the extension).
static TINY: LazyLock<String> = LazyLock::new(|| {
    common::sphere_scene(
        r#"        <Camera id="1">
            <Position>0 0 5</Position>
            <Gaze>0 0 -1</Gaze>
            <Up>0 1 0</Up>
            <NearPlane>-1 1 -1 1</NearPlane>
            <NearDistance>2</NearDistance>
            <ImageResolution>24 16</ImageResolution>
            <ImageName>tiny.IMAGE_EXT</ImageName>
        </Camera>"#,
    )
});

#[test]
fn cli_renders_builtin_example_with_summary_line() {
    let tmp = tempfile::tempdir().unwrap();
    let o = arbor(&["render", "-o", "out", "--spp", "1"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let png = tmp.path().join("out/cornell_box.png");
    assert!(png.is_file());
    let out = stdout(&o);
    assert!(out.contains("cornell_box.png") && out.contains("Mrays/s") && out.contains("triangles"), "{out}");
}

#[test]
fn cli_writes_the_format_the_scene_names() {
    let tmp = tempfile::tempdir().unwrap();
    for ext in ["png", "ppm", "exr"] {
        let scene = write(tmp.path(), &format!("s_{ext}.xml"), &TINY.replace("IMAGE_EXT", ext));
        let o = arbor(&["render", "--quiet", scene.to_str().unwrap()], tmp.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let bytes = std::fs::read(tmp.path().join(format!("tiny.{ext}"))).unwrap();
        let magic: &[u8] = match ext {
            "png" => b"\x89PNG",
            "ppm" => b"P6",
            _ => b"\x76\x2f\x31\x01",
        };
        assert!(bytes.starts_with(magic), "{ext} output has the wrong signature");
    }
}

#[test]
fn cli_hdr_image_with_a_tonemap_gets_a_tone_mapped_png_beside_it() {
    let tmp = tempfile::tempdir().unwrap();
    let tonemap = "<ImageName>tiny.IMAGE_EXT</ImageName>\n<Tonemap><TMO>Photographic</TMO>\
                   <TMOOptions>0.18 1</TMOOptions><Saturation>1</Saturation><Gamma>2.2</Gamma></Tonemap>";
    for ext in ["exr", "hdr"] {
        let text = TINY.replace("<ImageName>tiny.IMAGE_EXT</ImageName>", tonemap).replace("IMAGE_EXT", ext);
        let scene = write(tmp.path(), &format!("t_{ext}.xml"), &text);
        let o = arbor(&["render", "-q", scene.to_str().unwrap(), "-o", ext], tmp.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let (image, png) = (tmp.path().join(format!("{ext}/tiny.{ext}")), tmp.path().join(format!("{ext}/tiny.png")));
        assert_eq!(
            stdout(&o),
            format!(
                "Saved: {}\nSaved: {}\n",
                Path::new(ext).join(format!("tiny.{ext}")).display(),
                Path::new(ext).join("tiny.png").display()
            )
        );
        let magic: &[u8] = if ext == "exr" { b"\x76\x2f\x31\x01" } else { b"#?RADIANCE" };
        assert!(std::fs::read(&image).unwrap().starts_with(magic), "{ext} output has the wrong signature");
        assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
        let names: Vec<_> = std::fs::read_dir(tmp.path().join(ext)).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 2, "no temporary files left: {names:?}");
    }
}

#[test]
fn cli_hdr_image_without_a_tonemap_gets_the_course_tone_mapping_beside_it() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = write(tmp.path(), "t.xml", &TINY.replace("IMAGE_EXT", "exr"));
    let o = arbor(&["render", "-q", scene.to_str().unwrap()], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), "Saved: ./tiny.exr\nSaved: ./tiny.png\n");
    // The EXR holds radiance in the scene's units (a METU file's 255 is white): the PNG is its tone
    // mapping with one unit of radiance worth 1.
    let hdr = arbor::image_io::read_image(&tmp.path().join("tiny.exr")).unwrap();
    let expected = (hdr.width, hdr.height, arbor::tonemap::Tonemap::PREVIEW.apply(&hdr).to_rgb8());
    assert_eq!(arbor::image_io::read_rgb8(&tmp.path().join("tiny.png")).unwrap(), expected);
    // A debug view is written as it is, alone.
    let debug = arbor(&["render", "-q", scene.to_str().unwrap(), "--debug", "normal", "-o", "d"], tmp.path());
    assert!(debug.status.success(), "{}", stderr(&debug));
    assert!(!tmp.path().join("d/tiny.png").exists());
}

#[test]
fn cli_usage_error_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(arbor(&["render", "--spp", "zero"], tmp.path()).status.code(), Some(2));
    assert_eq!(arbor(&["frobnicate"], tmp.path()).status.code(), Some(2));
    assert_eq!(arbor(&["render", "--accel", "quadtree"], tmp.path()).status.code(), Some(2));
    assert_eq!(arbor(&["render", "--path-options", "mis,fast"], tmp.path()).status.code(), Some(2));
    let o = arbor(&["render", "--roulette", "fair"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("[possible values: course, unbiased]"), "{}", stderr(&o));
    let o = arbor(&["render", "--integrator", "whitted", "--path-options", "mis"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--path-options sets the path tracer's options"), "{}", stderr(&o));
    assert!(!tmp.path().join("cornell_box.png").exists(), "a usage error renders nothing");
}

#[test]
fn cli_info_accels_lists_every_parameter_with_range_and_default_in_columns() {
    let tmp = tempfile::tempdir().unwrap();
    let o = arbor(&["info", "--accels"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().collect();
    let header = lines[0];
    let (range_col, default_col, meaning_col) =
        (header.find("range").unwrap(), header.find("default").unwrap(), header.find("meaning").unwrap());
    let params: Vec<&str> = lines.iter().copied().filter(|l| l.starts_with("    ")).collect();
    assert_eq!(params.len(), 3 + 4 + 1 + 5 + 5, "{out}");
    for l in &params {
        // Every column starts where its heading does, after at least two spaces.
        for col in [range_col, default_col, meaning_col] {
            assert!(l[..col].ends_with("  ") && !l[col..].starts_with(' '), "misaligned at {col}: {l:?}\n{out}");
        }
    }
    let row = |key: &str, kind: &str| {
        let start = lines.iter().position(|l| *l == kind).unwrap_or_else(|| panic!("no {kind} in\n{out}"));
        let l = lines[start + 1..].iter().find(|l| l.trim_start().starts_with(key)).unwrap();
        l.split("  ").map(str::trim).filter(|s| !s.is_empty()).collect::<Vec<_>>()
    };
    assert_eq!(row("leaf=", "bvh-sah")[..3], ["leaf=VALUE", "1..=64", "8"]);
    assert_eq!(row("depth=", "octree")[..3], ["depth=VALUE", "0..=16", "10"]);
    assert_eq!(row("empty-bonus=", "kdtree")[..3], ["empty-bonus=VALUE", "0..=1", "0.2"]);
    assert_eq!(row("depth=", "kdtree")[..3], ["depth=VALUE", "auto or 0..=63", "auto"]);
    assert_eq!(row("method=", "bvh-bottom-up")[..3], ["method=VALUE", "auto|greedy|ploc", "auto"]);
    assert!(out.contains("brute  (no parameters)"), "{out}");
}

#[test]
fn cli_missing_scene_exits_4_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let o = arbor(&["render", "nowhere.xml"], tmp.path());
    assert_eq!(o.status.code(), Some(4));
    assert!(stderr(&o).contains("nowhere.xml"), "{}", stderr(&o));
}

#[test]
fn cli_bad_scene_exits_3_with_location_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = write(tmp.path(), "bad.xml", &TINY.replace("IMAGE_EXT", "png").replace("<Radius>1<", "<Radius>one<"));
    let o = arbor(&["render", scene.to_str().unwrap()], tmp.path());
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("bad.xml:") && err.contains("'one'"), "{err}");
    assert!(!tmp.path().join("tiny.png").exists());
    let leftovers: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().flatten().map(|e| e.file_name()).collect();
    assert_eq!(leftovers.len(), 1, "unexpected files: {leftovers:?}");
}

#[test]
fn cli_missing_mesh_file_exits_3_naming_scene_and_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    let text = TINY.replace("IMAGE_EXT", "png").replace(
        "<Sphere id=\"1\"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere>",
        "<Mesh id=\"1\"><Material>1</Material><Faces plyFile=\"gone.ply\"/></Mesh>",
    );
    let scene = write(tmp.path(), "mesh.xml", &text);
    let o = arbor(&["render", scene.to_str().unwrap()], tmp.path());
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("mesh.xml:") && err.contains("gone.ply"), "{err}");
}

#[test]
fn cli_diff_passes_identical_and_fails_different_images() {
    let tmp = tempfile::tempdir().unwrap();
    let a = write(tmp.path(), "a.xml", &TINY.replace("IMAGE_EXT", "png"));
    assert!(arbor(&["render", "-q", "-o", "a", a.to_str().unwrap()], tmp.path()).status.success());
    let brighter = TINY.replace("IMAGE_EXT", "png").replace("<AmbientLight>30 30 30", "<AmbientLight>90 90 90");
    let b = write(tmp.path(), "b.xml", &brighter);
    assert!(arbor(&["render", "-q", "-o", "b", b.to_str().unwrap()], tmp.path()).status.success());
    let same = arbor(&["diff", "a/tiny.png", "a/tiny.png"], tmp.path());
    assert_eq!(same.status.code(), Some(0), "{}", stdout(&same));
    let want = "PSNR inf (identical), RMSE 0.000 levels, 0 of 384 pixels off (0.000%), max diff 0
bias (image minus reference): R +0.000, G +0.000, B +0.000 levels
OK: 0.000% of pixels off by more than 8 levels (limit 0.5%)
";
    assert_eq!(stdout(&same), want);
    let differ = arbor(&["diff", "a/tiny.png", "b/tiny.png"], tmp.path());
    assert_eq!(differ.status.code(), Some(1), "{}", stdout(&differ));
    assert!(stdout(&differ).contains("PSNR"), "{}", stdout(&differ));
}

/// What a failed pixel-by-pixel diff says after its verdict when its 16x16 blocks agree.
const HINT: &str = "hint: 0.000% of its 16x16-pixel blocks are off; if the image is a render of random samples \
                    (path tracing, soft shadows, glossy reflections), compare block means (--block 16) or measure \
                    the noise with a second seed's render (--noise IMAGE_OTHER_SEED)\n";

/// Writes a binary PPM of `width` x `height` pixels whose pixel (x, y) is `f(x, y)`.
fn ppm(dir: &Path, name: &str, width: u32, height: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    let mut bytes = format!("P6\n{width} {height}\n255\n").into_bytes();
    bytes.extend((0..height).flat_map(|y| (0..width).map(move |x| (x, y))).flat_map(|(x, y)| f(x, y)));
    std::fs::write(dir.join(name), bytes).unwrap();
}

#[test]
fn cli_diff_blocks_pass_noise_that_pixels_fail() {
    let tmp = tempfile::tempdir().unwrap();
    // Grey 100 against a checkerboard of +-20 that cancels in every 2x2 block, with a bias of R +1, B -2.
    let noise = |x: u32, y: u32| if (x + y).is_multiple_of(2) { [121, 120, 118] } else { [81, 80, 78] };
    ppm(tmp.path(), "ref.ppm", 4, 2, |_, _| [100; 3]);
    ppm(tmp.path(), "noisy.ppm", 4, 2, noise);
    let bias = "bias (image minus reference): R +1.000, G +0.000, B -2.000 levels\n";
    let o = arbor(&["diff", "ref.ppm", "noisy.ppm"], tmp.path());
    let want = format!(
        "PSNR 22.09 dB, RMSE 20.042 levels, 8 of 8 pixels off (100.000%), max diff 22\n{bias}\
         FAIL: 100.000% of pixels off by more than 8 levels (limit 0.5%)\n{HINT}"
    );
    assert_eq!((o.status.code(), stdout(&o), stderr(&o)), (Some(1), want, String::new()));
    let o = arbor(&["diff", "ref.ppm", "noisy.ppm", "--block", "2"], tmp.path());
    let want = format!(
        "0 of 2 blocks of 2x2 pixels off (0.000%), max block diff 2.000 levels\n{bias}\
         OK: 0.000% of blocks of 2x2 pixels off by more than 8 levels (limit 0.5%)\n"
    );
    assert_eq!((o.status.code(), stdout(&o), stderr(&o)), (Some(0), want, String::new()));
    // The bias itself is off when nothing is tolerated.
    let o = arbor(&["diff", "ref.ppm", "noisy.ppm", "--block", "2", "--threshold", "0"], tmp.path());
    let want = format!(
        "2 of 2 blocks of 2x2 pixels off (100.000%), max block diff 2.000 levels\n{bias}\
         FAIL: 100.000% of blocks of 2x2 pixels off by more than 0 levels (limit 0.5%)\n"
    );
    assert_eq!((o.status.code(), stdout(&o)), (Some(1), want));
}

#[test]
fn cli_diff_blocks_fail_an_error_the_noise_does_not_hide() {
    let tmp = tempfile::tempdir().unwrap();
    // 5x4 pixels in 2x2 blocks, the right column of blocks 1 pixel wide: noise of +-20 that cancels in
    // every block, and G 12 levels too bright in the 2x2 block at x 2..4, y 2..4.
    let wrong = |x: u32, y: u32| {
        let v = if (x + y).is_multiple_of(2) { 120 } else { 80 };
        [v, if x / 2 == 1 && y / 2 == 1 { v + 12 } else { v }, v]
    };
    ppm(tmp.path(), "ref.ppm", 5, 4, |_, _| [100; 3]);
    ppm(tmp.path(), "wrong.ppm", 5, 4, wrong);
    let found = "1 of 6 blocks of 2x2 pixels off (16.667%), max block diff 12.000 levels
bias (image minus reference): R +0.000, G +2.400, B +0.000 levels
";
    let o = arbor(&["diff", "ref.ppm", "wrong.ppm", "--block", "2"], tmp.path());
    let want = format!("{found}FAIL: 16.667% of blocks of 2x2 pixels off by more than 8 levels (limit 0.5%)\n");
    assert_eq!((o.status.code(), stdout(&o)), (Some(1), want));
    let o = arbor(&["diff", "ref.ppm", "wrong.ppm", "--block", "2", "--max-off", "20"], tmp.path());
    let want = format!("{found}OK: 16.667% of blocks of 2x2 pixels off by more than 8 levels (limit 20%)\n");
    assert_eq!((o.status.code(), stdout(&o)), (Some(0), want));
}

#[test]
fn cli_diff_noise_judges_a_render_by_its_second_seed() {
    let tmp = tempfile::tempdir().unwrap();
    // Reference 100; a render 1 level off (then 9 in blue), its second seed 4 levels above it.
    ppm(tmp.path(), "ref.ppm", 4, 4, |_, _| [100; 3]);
    ppm(tmp.path(), "good.ppm", 4, 4, |_, _| [101, 100, 99]);
    ppm(tmp.path(), "good_seed2.ppm", 4, 4, |_, _| [105, 104, 103]);
    ppm(tmp.path(), "far.ppm", 4, 4, |_, _| [100, 100, 109]);
    ppm(tmp.path(), "far_seed2.ppm", 4, 4, |_, _| [104, 104, 113]);
    let o = arbor(&["diff", "ref.ppm", "good.ppm", "--noise", "good_seed2.ppm", "--block", "2"], tmp.path());
    let want = "2x2 blocks: render vs reference 0.67 levels, seed vs seed 4.00 (limit 5.00); bias +1.00 +0.00 \
                -1.00 (limit ±2): OK\n";
    assert_eq!((o.status.code(), stdout(&o)), (Some(0), want.to_string()));
    let o = arbor(&["diff", "ref.ppm", "far.ppm", "--noise", "far_seed2.ppm"], tmp.path());
    let want = "16x16 blocks: render vs reference 3.00 levels, seed vs seed 4.00 (limit 5.00); bias +0.00 +0.00 \
                +9.00 (limit ±2): FAIL\n";
    assert_eq!((o.status.code(), stdout(&o)), (Some(1), want.to_string()));
}

/// Writes an EXR of radiance `f(x, y)` (grey) of `width` x `height` pixels.
fn exr(dir: &Path, name: &str, width: u32, height: u32, f: impl Fn(u32, u32) -> f32) {
    let pixels =
        (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| arbor::math::Color::splat(f(x, y)));
    let film = arbor::film::Film { width, height, pixels: pixels.collect() };
    arbor::image_io::write_image(&dir.join(name), &film).unwrap();
}

#[test]
fn cli_diff_hdr_images_in_the_reference_curve() {
    let tmp = tempfile::tempdir().unwrap();
    // Radiance far above 1 (a METU scene's units): an 8-bit reading would clip all of it to white.
    exr(tmp.path(), "ref.exr", 4, 4, |x, _| 200.0 + 100.0 * x as f32);
    exr(tmp.path(), "same.exr", 4, 4, |x, _| 200.0 + 100.0 * x as f32);
    exr(tmp.path(), "double.exr", 4, 4, |x, _| 400.0 + 200.0 * x as f32);
    // Noise of +-50% that cancels in each 2x2 block.
    exr(tmp.path(), "noisy.exr", 4, 4, |x, y| {
        (200.0 + 100.0 * (x - x % 2) as f32 + 50.0) * if (x + y) % 2 == 0 { 1.5 } else { 0.5 }
    });
    let curve =
        "HDR images: compared in 8-bit levels under the reference's curve (key 0.18 of its log-average, gamma 2.2)\n";
    let o = arbor(&["diff", "ref.exr", "same.exr"], tmp.path());
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).starts_with(curve) && stdout(&o).contains("PSNR inf"), "{}", stdout(&o));
    // Twice the radiance: the reference's curve shows it brighter (its own curve would not).
    let o = arbor(&["diff", "ref.exr", "double.exr"], tmp.path());
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("16 of 16 pixels off"), "{}", stdout(&o));
    // Blocks average radiance before the curve: the noise is gone.
    let o = arbor(&["diff", "ref.exr", "noisy.exr", "--block", "2"], tmp.path());
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).contains("0 of 4 blocks of 2x2 pixels off"), "{}", stdout(&o));
    // Radiance against 8-bit values compares nothing meaningful: a usage error.
    ppm(tmp.path(), "ldr.ppm", 4, 4, |_, _| [100; 3]);
    let o = arbor(&["diff", "ref.exr", "ldr.ppm"], tmp.path());
    let want = "error: ldr.ppm is an 8-bit image but the reference ref.exr is an HDR one: compare radiance with \
                radiance (.exr, .hdr) or 8-bit images with 8-bit ones\n";
    assert_eq!((o.status.code(), stderr(&o)), (Some(2), want.to_string()));
}

#[test]
fn cli_diff_noise_tonemap_shows_radiance_under_the_exposure_an_8bit_reference_implies() {
    use arbor::tonemap::Tonemap;
    let tmp = tempfile::tempdir().unwrap();
    // A ramp of radiance, and the course's curve of it at 1.3 times its own exposure as the reference.
    let ramp = |x: u32, y: u32| 0.05 + (x + 32 * y) as f32 / 256.0;
    exr(tmp.path(), "seed1.exr", 32, 32, ramp);
    exr(tmp.path(), "seed2.exr", 32, 32, ramp);
    exr(tmp.path(), "moved.exr", 32, 32, |x, y| ramp(x, y) * if x < 16 { 1.0 } else { 1.5 });
    let tm = Tonemap { key: 0.18, burn_percent: 1.0, saturation: 1.0, gamma: 2.2, ..Tonemap::PREVIEW };
    let film = arbor::image_io::read_image(&tmp.path().join("seed1.exr")).unwrap();
    let own = tm.exposure(&film);
    let shown = tm.apply_exposure(&film, own.scaled(1.3));
    let px = shown.to_rgb8();
    ppm(tmp.path(), "ref.ppm", 32, 32, |x, y| {
        let i = 3 * (32 * y + x) as usize;
        [px[i], px[i + 1], px[i + 2]]
    });
    let args = |image: &'static str, other: &'static str| {
        ["diff", "ref.ppm", image, "--noise", other, "--tonemap", "0.18,1,1,2.2"]
    };
    let o = arbor(&args("seed1.exr", "seed2.exr"), tmp.path());
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("16x16 blocks at 1.3") && stdout(&o).ends_with(": OK\n"), "{}", stdout(&o));
    // Light moved between the halves is no exposure: no factor brings it back.
    let o = arbor(&args("moved.exr", "moved.exr"), tmp.path());
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    // The wrong kinds of image, and a curve that is not one.
    let o = arbor(&["diff", "seed1.exr", "seed1.exr", "--noise", "seed2.exr", "--tonemap", "0.18,1,1,2.2"], tmp.path());
    let want = "error: --tonemap is for an 8-bit reference, and seed1.exr is an HDR one: leave --tonemap out\n";
    assert_eq!((o.status.code(), stderr(&o)), (Some(2), want.to_string()));
    let o = arbor(&["diff", "ref.ppm", "ref.ppm", "--noise", "seed2.exr", "--tonemap", "0.18,1,1,2.2"], tmp.path());
    let want = "error: ref.ppm is an 8-bit image: with --tonemap the two renders are radiance (.exr, .hdr)\n";
    assert_eq!((o.status.code(), stderr(&o)), (Some(2), want.to_string()));
    exr(tmp.path(), "small.exr", 16, 16, ramp);
    let o = arbor(&args("seed1.exr", "small.exr"), tmp.path());
    let want = "error: small.exr is 16x16 but the reference is 32x32\n";
    assert_eq!((o.status.code(), stderr(&o)), (Some(3), want.to_string()));
    let o = arbor(&["diff", "ref.ppm", "seed1.exr", "--noise", "seed2.exr", "--tonemap", "0.18,1,1,0"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("the key and gamma must be positive"), "{}", stderr(&o));
    let o = arbor(&["diff", "ref.ppm", "seed1.exr", "--tonemap", "0.18,1,1,2.2"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--noise"), "{}", stderr(&o));
}

#[test]
fn cli_diff_block_zero_is_a_usage_error() {
    let tmp = tempfile::tempdir().unwrap();
    ppm(tmp.path(), "ref.ppm", 2, 2, |_, _| [100; 3]);
    let o = arbor(&["diff", "ref.ppm", "ref.ppm", "--block", "0"], tmp.path());
    let want = "error: invalid value '0' for '--block <K>': a block is at least 1 pixel wide\n\n\
                For more information, try '--help'.\n";
    assert_eq!((o.status.code(), stdout(&o), stderr(&o)), (Some(2), String::new(), want.to_string()));
}

#[test]
fn cli_info_describes_the_scene() {
    let tmp = tempfile::tempdir().unwrap();
    let a = write(tmp.path(), "a.xml", &TINY.replace("IMAGE_EXT", "png"));
    let o = arbor(&["info", a.to_str().unwrap()], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("24x16") && out.contains("sphere") && out.contains("bvh-sah"), "{out}");
    // Which roulette each path-traced camera gets.
    let camera = "<ImageName>tiny.png</ImageName><Renderer>PathTracing</Renderer>";
    let with = |params: &str| TINY.replace("<ImageName>tiny.IMAGE_EXT</ImageName>", &format!("{camera}{params}"));
    for (params, line) in [
        (
            "",
            "  renderer path tracing; paths end at MaxRecursionDepth; both lobes of refractive surfaces followed, \
             as the course's renderer does\n",
        ),
        (
            "<RendererParams>NextEventEstimation RussianRoulette</RendererParams>",
            "  renderer path tracing, next event estimation; the course's Russian roulette (biased: brighter than \
             the converged answer; --roulette unbiased for Arbor's); both lobes of refractive surfaces followed, \
             as the course's renderer does\n",
        ),
    ] {
        let b = write(tmp.path(), "b.xml", &with(params));
        let o = arbor(&["info", b.to_str().unwrap()], tmp.path());
        assert!(stdout(&o).contains(line), "{}", stdout(&o));
    }
}

#[test]
fn cli_json_form_culls_by_default_and_no_cull_turns_it_off() {
    // A wall filling the view with its back to the camera, lit by ambient light only (30 levels):
    // culled, the image is the black background; unculled, the wall.
    let files = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs");
    let tmp = tempfile::tempdir().unwrap();
    let level = |scene: &str, flags: &[&str]| {
        let out = tmp.path().join(format!("{scene}{}.png", flags.join("")));
        let (scene, out_s) = (files.join(scene), out.to_str().unwrap().to_string());
        let mut args = vec!["render", "-q", scene.to_str().unwrap(), "-o", &out_s];
        args.extend(flags);
        let o = arbor(&args, tmp.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let (_, _, px) = arbor::image_io::read_rgb8(&out).unwrap();
        assert!(px.iter().all(|&v| v == px[0]), "one colour");
        px[0]
    };
    assert_eq!(level("back_faces.json", &[]), 0);
    assert_eq!(level("back_faces.json", &["--no-cull"]), 30);
    assert_eq!(level("back_faces.json", &["--cull"]), 0);
    assert_eq!(level("back_faces.xml", &[]), 30);
    assert_eq!(level("back_faces.xml", &["--cull"]), 0);
    // `info` says which default applies, and gives the render's warning.
    let info = |scene: &str| stdout(&arbor(&["info", files.join(scene).to_str().unwrap()], tmp.path()));
    let json = info("back_faces.json");
    assert!(json.contains("back-face culling on") && !json.contains("meet back faces"), "{json}");
    let xml = info("back_faces.xml");
    assert!(xml.contains("back-face culling off (unless render --cull)"), "{xml}");
    assert!(
        xml.contains(
            "Camera 1: 100% of camera rays meet back faces; if the scene expects back-face culling, render with --cull"
        ),
        "{xml}"
    );
}

/// A scene of eight inline meshes (bumpy grids of 2x60x60 triangles), built in parallel.
fn eight_meshes() -> String {
    let n = 60;
    let mut vertices = String::new();
    let mut meshes = String::new();
    for k in 0..8 {
        for j in 0..=n {
            for i in 0..=n {
                vertices += &format!("{i} {j} {}\n", k as f32 + ((i * 7 + j * 13) % 5) as f32 * 0.3);
            }
        }
        let v = |i: u32, j: u32| k * (n + 1) * (n + 1) + j * (n + 1) + i + 1;
        let faces: Vec<String> = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| {
                format!(
                    "{} {} {} {} {} {}",
                    v(i, j),
                    v(i + 1, j),
                    v(i + 1, j + 1),
                    v(i, j),
                    v(i + 1, j + 1),
                    v(i, j + 1)
                )
            })
            .collect();
        meshes += &format!("<Mesh id=\"{}\"><Material>1</Material><Faces>{}</Faces></Mesh>\n", k + 1, faces.join(" "));
    }
    TINY.replace("IMAGE_EXT", "png")
        .replace("<VertexData>0 0 0</VertexData>", &format!("<VertexData>{vertices}</VertexData>"))
        .replace("<Sphere id=\"1\"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere>", &meshes)
}

#[test]
fn cli_build_times_are_wall_times() {
    // Not a speed check: the build time each command reports is no more than the wall time of the
    // whole process (the meshes' structures, built in parallel, once counted their time per thread).
    let tmp = tempfile::tempdir().unwrap();
    let scene = write(tmp.path(), "eight.xml", &eight_meshes());
    let timed = |args: &[&str]| {
        let start = std::time::Instant::now();
        let o = arbor(args, tmp.path());
        let elapsed_ms = start.elapsed().as_secs_f64() * 1e3;
        assert!(o.status.success(), "{}", stderr(&o));
        (stdout(&o), elapsed_ms)
    };
    let number_after = |text: &str, key: &str| -> f64 {
        let at = text.find(key).unwrap_or_else(|| panic!("no '{key}' in {text}")) + key.len();
        text[at..].trim_start().split(|c: char| !(c.is_ascii_digit() || c == '.')).next().unwrap().parse().unwrap()
    };
    let scene = scene.to_str().unwrap();
    for accel in ["kdtree", "bvh-sah"] {
        let (out, ms) = timed(&["info", "--accel", accel, scene]);
        let built = number_after(&out, "built in");
        assert!(built > 0.0 && built <= ms, "info --accel {accel}: built in {built} ms, {ms} ms in all");
        let (out, ms) = timed(&["render", "--accel", accel, scene, "--stats-json", "s.json", "-o", "out"]);
        let build = number_after(&out, "build");
        let json = std::fs::read_to_string(tmp.path().join("s.json")).unwrap();
        let build_ms = number_after(&json, "\"build_ms\":");
        assert!(build <= ms && build_ms <= ms, "render --accel {accel}: build {build} ms ({build_ms}), {ms} ms in all");
        let (out, ms) = timed(&["bench", "--accel", accel, scene, "--size", "8x8", "--runs", "1", "--json"]);
        let build_ms = number_after(&out, "\"build_ms\":");
        assert!(build_ms <= ms, "bench --accel {accel}: build {build_ms} ms, {ms} ms in all");
    }
}

#[test]
fn cli_max_isa_caps_the_kernel_keeps_the_image_and_refuses_unknown_values() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |isa: Option<&str>, out: &str| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_arbor"));
        c.args(["render", "-o", out, "--spp", "1", "--stats-json", &format!("{out}.json")]).current_dir(tmp.path());
        match isa {
            Some(v) => c.env("ARBOR_MAX_ISA", v),
            None => c.env_remove("ARBOR_MAX_ISA"),
        };
        let o = c.output().expect("arbor runs");
        assert!(o.status.success() || isa == Some("avx3"), "{isa:?}: {}", stderr(&o));
        o
    };
    let kernel = |out: &str| {
        let stats: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(tmp.path().join(format!("{out}.json"))).unwrap()).unwrap();
        stats["images"][0]["kernel"].as_str().unwrap().to_string()
    };
    run(None, "best");
    let best = kernel("best");
    let image = |out: &str| std::fs::read(tmp.path().join(out).join("cornell_box.png")).unwrap();
    // The kernels compute the same lanes in the same order: a capped render is the same image.
    let order = ["scalar", "sse", "avx2", "avx512"];
    let rank = |k: &str| order.iter().position(|&o| o == k).unwrap_or_else(|| panic!("kernel {k}"));
    for cap in ["sse", "avx2", "avx512"] {
        run(Some(cap), cap);
        let expected = if best == "scalar" { "scalar" } else { order[rank(&best).min(rank(cap))] };
        assert_eq!(kernel(cap), expected, "ARBOR_MAX_ISA={cap} on a processor whose best is {best}");
        assert!(image(cap) == image("best"), "ARBOR_MAX_ISA={cap} changed the image");
    }
    let o = run(Some("avx3"), "typo");
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stderr(&o), "error: ARBOR_MAX_ISA=\"avx3\": expected avx512, avx2 or sse\n");
    assert!(!tmp.path().join("typo").exists() && !tmp.path().join("typo.json").exists());
}
