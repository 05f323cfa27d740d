//! Hostile images for the bad-input catalogue, written by the test itself into a temporary folder (a
//! few of them are large when decoded, none is large on disk): decompression bombs, headers that claim
//! huge images, NaN and infinite float texels, and the scenes and partial EXRs that use them.
//!
//! - `bomb.png`: 20000 x 20000 pixels of 1-bit grey in 49 KB (deflate packs the zero rows about 1000:1
//!   and each byte holds 8 pixels). Decoded to 8-bit grey it is 400 MB, within the image crate's 512 MiB
//!   allocation limit; the conversion to float RGB then asked for 4.8 GB and aborted the process (under
//!   the catalogue's 1 GiB address-space limit, the image crate panicked).
//! - `big.png`: 8193 x 8192, one row over the budget of 2^26 pixels, small enough to render as a texture
//!   with `--no-limits` under 1 GiB (67 MB of grey, 201 MB of 8-bit RGB).
//! - `huge.exr`: an OpenEXR header and offset table claiming a 65536 x 16384 image (2^30 pixels, 12 GB of
//!   float RGB) in 8 KB; `huge_window.exr`: an 8 x 8 image whose data window claims the same.
//! - `huge.hdr`, `huge.ppm`: Radiance and PPM headers claiming 100000 x 100000.
//! - `nan.exr`, `inf.exr`: 2 x 2 float images with a NaN and an infinite texel (they rendered).
//! - `cube/`: six faces, `px.png` the bomb.
//! - `palette.png`: 4 x 2 pixels of 2-bit palette indices, the palette 13 bytes (four entries and one
//!   byte): the png crate panicked expanding it (found by the `decode_png` fuzz target).
//! - `huge_frame.exr`, `big_frame.exr`: partial EXRs of `arbor render` (one pixel rendered) whose frame is
//!   100000 x 100000, and 16385 x 16385 (just over the film's 2^28 pixels): `merge` allocated the frame
//!   and aborted.

use std::path::Path;

use arbor::accum::SampleSum;
use arbor::farm::{write_partial, Partial};
use arbor::film::Film;
use arbor::math::Color;
use arbor::render::RenderSums;

use super::{cmd, render, Row};

/// Writes every hostile file, and the scenes that name them (made from catalogue scenes, so that their
/// elements keep their lines), into `dir`.
pub fn write_all(dir: &Path, catalogue: &Path) {
    bomb_png(&dir.join("bomb.png"), 20000, 20000);
    bomb_png(&dir.join("big.png"), 8193, 8192);
    std::fs::write(dir.join("huge.exr"), exr_header((65536, 16384), (65536, 16384))).unwrap();
    std::fs::write(dir.join("huge_window.exr"), exr_header((8, 8), (65536, 16384))).unwrap();
    std::fs::write(
        dir.join("huge.hdr"),
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n\x80\x80\x80\x80",
    )
    .unwrap();
    std::fs::write(dir.join("huge.ppm"), b"P6\n100000 100000\n255\n\x80\x80\x80").unwrap();
    let film = |bad: usize, v: f32| {
        let mut pixels = vec![Color::splat(0.5); 4];
        pixels[bad].x = v;
        Film { width: 2, height: 2, pixels }
    };
    arbor::image_io::write_image(&dir.join("nan.exr"), &film(1, f32::NAN)).unwrap();
    arbor::image_io::write_image(&dir.join("inf.exr"), &film(2, f32::INFINITY)).unwrap();
    palette_png(&dir.join("palette.png"));
    let cube = dir.join("cube");
    std::fs::create_dir(&cube).unwrap();
    std::fs::copy(dir.join("bomb.png"), cube.join("px.png")).unwrap();
    for face in ["nx", "py", "ny", "pz", "nz"] {
        arbor::image_io::write_image(&cube.join(format!("{face}.png")), &Film::new(2, 2)).unwrap();
    }
    partial(&dir.join("huge_frame.exr"), (100000, 100000));
    partial(&dir.join("big_frame.exr"), (16385, 16385));
    std::fs::copy(catalogue.join("tex.png"), dir.join("tex.png")).unwrap();
    let scene = |name: &str, from: &str, image: &str, to: &str| {
        let text = std::fs::read_to_string(catalogue.join(from)).unwrap();
        assert!(text.contains(image));
        std::fs::write(dir.join(name), text.replace(image, to)).unwrap();
    };
    for (name, image) in [("bomb", "bomb.png"), ("cube", "cube"), ("huge_exr", "huge.exr"), ("nan", "nan.exr")] {
        scene(&format!("env_{name}.xml"), "env_truncated.xml", "truncated.png", image);
    }
    for (name, image) in [("bomb", "bomb.png"), ("big", "big.png"), ("huge_ppm", "huge.ppm"), ("inf", "inf.exr")] {
        scene(&format!("texture_{name}.xml"), "texture_image_truncated_png.xml", "truncated.png", image);
    }
}

/// The runs over the files of [`write_all`] (in their folder): exit 3 and a located message naming the
/// file for every image above the budget or not finite; with `--no-limits`, a run that fits in the
/// catalogue's 1 GiB, or a clean out-of-memory error (exit 3 at the scene's element, 4 for a file on the
/// command line), never an abort.
#[rustfmt::skip]
pub fn rows() -> Vec<Row> {
    let over = |what: &str, size: &str, pixels: u64, limit: u64| {
        format!("{what} {size} has {pixels} pixels, more than the limit of {limit}; --no-limits lifts the limits\n")
    };
    let error = |text: String| format!("error: {text}");
    let bomb_scene = over("image", "20000x20000", 400_000_000, 1 << 26);
    let bomb_file = over("image", "20000x20000", 400_000_000, 1 << 28);
    vec![
    // Textures, environment maps and cube faces: the scene's budget, 2^26 pixels.
    render("env_bomb.xml", 3, error(format!("env_bomb.xml:14:43: cannot read environment map 'bomb.png': {bomb_scene}"))),
    render("texture_bomb.xml", 3, error(format!("texture_bomb.xml:24:17: cannot read texture image 'bomb.png': {bomb_scene}"))),
    cmd(&["info", "texture_bomb.xml"], 3, error(format!("texture_bomb.xml:24:17: cannot read texture image 'bomb.png': {bomb_scene}"))),
    cmd(&["bench", "texture_bomb.xml", "--runs", "1"], 3, error(format!("texture_bomb.xml:24:17: cannot read texture image 'bomb.png': {bomb_scene}"))),
    render("env_cube.xml", 3, error(format!("env_cube.xml:14:43: cannot read environment map 'cube': cube/px.png: {bomb_scene}"))),
    render("env_huge_exr.xml", 3, error(format!("env_huge_exr.xml:14:43: cannot read environment map 'huge.exr': {}", over("image", "65536x16384", 1 << 30, 1 << 26)))),
    render("texture_huge_ppm.xml", 3, error(format!("texture_huge_ppm.xml:24:17: cannot read texture image 'huge.ppm': {}", over("image", "100000x100000", 10_000_000_000, 1 << 26)))),
    render("texture_big.xml", 3, error(format!("texture_big.xml:24:17: cannot read texture image 'big.png': {}", over("image", "8193x8192", 67_117_056, 1 << 26)))),
    cmd(&["render", "env_nan.xml", "--env", "bomb.png", "-o", "OUT"], 3, error(format!("bomb.png: {bomb_scene}"))),
    // --no-limits: an image one row over the budget renders; the bomb fails cleanly for want of memory.
    cmd(&["render", "texture_big.xml", "--no-limits", "-o", "OUT"], 0, ""),
    cmd(&["render", "env_bomb.xml", "--no-limits", "-o", "OUT"], 3, "error: env_bomb.xml:14:43: cannot read environment map 'bomb.png': not enough memory to convert it: 20000x20000 pixels (4.5 GiB)\n"),
    // NaN and infinite texels: refused, naming the first.
    render("env_nan.xml", 3, "error: env_nan.xml:14:43: cannot read environment map 'nan.exr': pixel (1, 0) is not finite: (NaN, 0.5, 0.5)\n"),
    render("texture_inf.xml", 3, "error: texture_inf.xml:24:17: cannot read texture image 'inf.exr': pixel (0, 1) is not finite: (inf, 0.5, 0.5)\n"),
    // diff and merge: the film's limit, 2^28 pixels (what render may write).
    cmd(&["diff", "bomb.png", "tex.png"], 3, error(format!("bomb.png: {bomb_file}"))),
    cmd(&["diff", "tex.png", "bomb.png", "--no-limits"], 4, "error: bomb.png: not enough memory to convert it: 20000x20000 pixels (1.1 GiB)\n"),
    cmd(&["diff", "tex.png", "huge.exr"], 3, error(format!("huge.exr: {}", over("image", "65536x16384", 1 << 30, 1 << 28)))),
    cmd(&["diff", "tex.png", "huge_window.exr"], 3, error(format!("huge_window.exr: {}", over("the data window", "65536x16384", 1 << 30, 1 << 28)))),
    cmd(&["diff", "tex.png", "huge.hdr"], 3, error(format!("huge.hdr: {}", over("image", "100000x100000", 10_000_000_000, 1 << 28)))),
    cmd(&["diff", "tex.png", "palette.png"], 3, "error: palette.png: cannot decode image: its palette (PLTE) holds 13 bytes, not whole RGB entries\n"),
    cmd(&["diff", "huge.ppm", "tex.png"], 3, error(format!("huge.ppm: {}", over("image", "100000x100000", 10_000_000_000, 1 << 28)))),
    cmd(&["merge", "huge_frame.exr", "-o", "OUT/merged.png"], 3, error(format!("huge_frame.exr: {}", over("the frame", "100000x100000", 10_000_000_000, 1 << 28)))),
    cmd(&["merge", "big_frame.exr", "-o", "OUT/merged.png"], 3, error(format!("big_frame.exr: {}", over("the frame", "16385x16385", 268_468_225, 1 << 28)))),
    cmd(&["merge", "big_frame.exr", "--no-limits", "-o", "OUT/merged.png"], 4, "error: not enough memory for a 16385x16385 image (1.0 GiB)\n"),
    ]
}

/// A `w` x `h` PNG of 1-bit black, compressed as far as deflate goes.
fn bomb_png(path: &Path, w: u32, h: u32) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, w, h);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::One);
    encoder.set_compression(png::Compression::High);
    encoder.set_filter(png::Filter::NoFilter);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&vec![0; w.div_ceil(8) as usize * h as usize]).unwrap();
    writer.finish().unwrap();
}

/// A 4 x 2 PNG of 2-bit palette indices whose palette holds 13 bytes, not whole RGB entries.
fn palette_png(path: &Path) {
    let mut encoder = png::Encoder::new(std::fs::File::create(path).unwrap(), 4, 2);
    encoder.set_color(png::ColorType::Indexed);
    encoder.set_depth(png::BitDepth::Two);
    encoder.set_palette(vec![0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255, 155]);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&[0b0001_1011, 0b1110_0100]).unwrap();
    writer.finish().unwrap();
}

/// An OpenEXR header of float R, G, B with ZIP blocks of 16 rows, `display` and `data` windows from
/// (0, 0), and an offset table of zeros (no block).
fn exr_header(display: (i32, i32), data: (i32, i32)) -> Vec<u8> {
    let mut b = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut attribute = |name: &str, kind: &str, value: &[u8]| {
        for text in [name, kind] {
            b.extend_from_slice(text.as_bytes());
            b.push(0);
        }
        b.extend_from_slice(&(value.len() as i32).to_le_bytes());
        b.extend_from_slice(value);
    };
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        for v in [2i32, 0, 1, 1] {
            channels.extend_from_slice(&v.to_le_bytes()); // float, pLinear and reserved, x and y sampling
        }
    }
    channels.push(0);
    let window =
        |(w, h): (i32, i32)| [0, 0, w - 1, h - 1].iter().flat_map(|v: &i32| v.to_le_bytes()).collect::<Vec<_>>();
    attribute("channels", "chlist", &channels);
    attribute("compression", "compression", &[3]);
    attribute("dataWindow", "box2i", &window(data));
    attribute("displayWindow", "box2i", &window(display));
    attribute("lineOrder", "lineOrder", &[0]);
    attribute("pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute("screenWindowCenter", "v2f", &[0; 8]);
    attribute("screenWindowWidth", "float", &1f32.to_le_bytes());
    b.push(0);
    b.resize(b.len() + 8 * (data.1 as usize).div_ceil(16), 0);
    b
}

/// A partial EXR of one rendered pixel of a `frame`-sized render.
fn partial(path: &Path, frame: (u32, u32)) {
    let sums = RenderSums {
        frame,
        window: (0, 0, 1, 1),
        spp: 1,
        samples: (0, 1),
        scale: 1.0,
        sums: vec![SampleSum::default()],
    };
    write_partial(path, &Partial { identity: "hostile".into(), camera: "1".into(), tonemap: None, sums }).unwrap();
}
