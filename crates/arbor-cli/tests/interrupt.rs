//! No lost output: `arbor render` stopped by SIGINT or SIGTERM exits 130 or 143 and leaves the output
//! folder as it was (no new image, no temporary file, an older image unchanged), also when it stops at
//! a later camera of a scene with several. Also `--crop`: the
//! cropped image equals the same window of the full render.

#![cfg(unix)]

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const ARBOR: &str = env!("CARGO_BIN_EXE_arbor");

/// `arbor render` of the built-in example at many samples per pixel: minutes of work, so a signal sent
/// after a moment always lands during the run.
fn start_long_render(out: &Path) -> Child {
    Command::new(ARBOR)
        .args(["render", "--quiet", "--spp", "2000", "--threads", "2", "-o"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Sends `signal` (a `kill` name) after `delay`; returns the exit code, failing unless the process
/// stopped within a second.
fn signal_and_wait(mut child: Child, signal: &str, delay: Duration) -> Option<i32> {
    std::thread::sleep(delay);
    let sent = Command::new("kill").arg(format!("-{signal}")).arg(child.id().to_string()).status().unwrap();
    assert!(sent.success(), "kill -{signal} failed");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(start.elapsed() < Duration::from_secs(1), "stopped {:?} after SIG{signal}", start.elapsed());
            let mut err = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
            let said = "interrupted: an image whose render was stopped is not written\n";
            assert_eq!(err, said, "SIG{signal} must be reported once");
            return status.code();
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("arbor render did not stop within 60 s of SIG{signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn interrupt_sigint_exits_130_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let code = signal_and_wait(start_long_render(tmp.path()), "INT", Duration::from_millis(1500));
    assert_eq!(code, Some(130));
    assert!(entries(tmp.path()).is_empty(), "left behind: {:?}", entries(tmp.path()));
}

#[test]
fn interrupt_sigterm_exits_143_and_keeps_the_older_image() {
    let tmp = tempfile::tempdir().unwrap();
    let old = tmp.path().join("cornell_box.png");
    std::fs::write(&old, b"an older image").unwrap();
    let code = signal_and_wait(start_long_render(tmp.path()), "TERM", Duration::from_millis(1500));
    assert_eq!(code, Some(143));
    assert_eq!(entries(tmp.path()), ["cornell_box.png"]);
    assert_eq!(std::fs::read(&old).unwrap(), b"an older image");
}

#[test]
fn interrupt_sigint_keeps_the_older_image() {
    let tmp = tempfile::tempdir().unwrap();
    let old = tmp.path().join("cornell_box.png");
    std::fs::write(&old, b"an older image").unwrap();
    // Early: possibly still while the scene is being built.
    let code = signal_and_wait(start_long_render(tmp.path()), "INT", Duration::from_millis(300));
    assert_eq!(code, Some(130));
    assert_eq!(entries(tmp.path()), ["cornell_box.png"]);
    assert_eq!(std::fs::read(&old).unwrap(), b"an older image");
}

#[test]
fn interrupt_sigterm_during_a_tile_writes_no_partial() {
    // Schedulers preempt tasks with SIGTERM: the slice must not leave a partial EXR to be merged.
    let tmp = tempfile::tempdir().unwrap();
    let child = Command::new(ARBOR)
        .args(["render", "--quiet", "--spp", "2000", "--threads", "2", "--tile", "0/2", "-o"])
        .arg(tmp.path().join("tile-0.exr"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let code = signal_and_wait(child, "TERM", Duration::from_millis(1500));
    assert_eq!(code, Some(143));
    assert!(entries(tmp.path()).is_empty(), "left behind: {:?}", entries(tmp.path()));
}

fn render_png(out: &Path, extra: &[&str]) -> (u32, u32, Vec<u8>) {
    let status =
        Command::new(ARBOR).args(["render", "--quiet", "--spp", "2", "-o"]).arg(out).args(extra).status().unwrap();
    assert!(status.success(), "arbor render {extra:?}: {status}");
    arbor::image_io::read_rgb8(&out.join("cornell_box.png")).unwrap()
}

#[test]
fn crop_equals_the_window_of_the_full_render() {
    let tmp = tempfile::tempdir().unwrap();
    let (w, _, full) = render_png(&tmp.path().join("full"), &[]);
    // Not aligned to the 16-pixel tiles.
    let (x0, y0, x1, y1) = (37u32, 101u32, 130u32, 140u32);
    let (cw, ch, crop) = render_png(&tmp.path().join("crop"), &["--crop", "37,101,130,140", "--threads", "1"]);
    assert_eq!((cw, ch), (x1 - x0, y1 - y0));
    for y in 0..ch {
        let src = (((y0 + y) * w + x0) * 3) as usize;
        let dst = (y * cw * 3) as usize;
        assert_eq!(&crop[dst..dst + (cw * 3) as usize], &full[src..src + (cw * 3) as usize], "row {y}");
    }
    let bad = Command::new(ARBOR).args(["render", "--quiet", "--crop", "0,0,401,10", "-o"]).arg(tmp.path()).output();
    let bad = bad.unwrap();
    assert_eq!(bad.status.code(), Some(3), "{}", String::from_utf8_lossy(&bad.stderr));
    let empty = Command::new(ARBOR).args(["render", "--crop", "5,5,5,9"]).output().unwrap();
    assert_eq!(empty.status.code(), Some(2));
}

#[test]
fn interrupt_during_the_second_camera_keeps_the_first_ones_older_image() {
    // Camera 1 renders in a moment; camera 2 would take minutes. The signal comes once camera 1's
    // summary is out, which the run printed only after writing camera 1's image over the older one.
    let tmp = tempfile::tempdir().unwrap();
    let example = include_str!("../../../examples/cornell_box.xml");
    let (start, end) = (example.find("<Camera ").unwrap(), example.find("</Camera>").unwrap() + "</Camera>".len());
    let camera = &example[start..end];
    let first = camera.replace("cornell_box.png", "first.png");
    let second = camera.replace("cornell_box.png", "second.png").replacen("id=\"", "id=\"2", 1);
    let first = with_spp(&first, 1).replace(">400 400<", ">40 40<");
    let second = with_spp(&second, 10_000);
    let text = format!("{}{first}\n{second}{}", &example[..start], &example[end..]);
    std::fs::write(tmp.path().join("two.xml"), text).unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("first.png"), b"an older image").unwrap();
    let mut child = Command::new(ARBOR)
        .args(["render", "two.xml", "--threads", "2", "-o", "out"])
        .current_dir(tmp.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufRead::lines(std::io::BufReader::new(child.stdout.take().unwrap()));
    let summary = lines.next().expect("camera 1's summary").unwrap();
    assert!(summary.starts_with("out/first.png  "), "{summary}");
    let code = signal_and_wait(child, "INT", Duration::ZERO);
    assert_eq!(code, Some(130));
    assert_eq!(entries(&out), ["first.png"]);
    assert_eq!(std::fs::read(out.join("first.png")).unwrap(), b"an older image");
}

/// `camera` with `NumSamples` `spp` instead of its own.
fn with_spp(camera: &str, spp: u32) -> String {
    let (a, b) = (camera.find("<NumSamples>").unwrap(), camera.find("</NumSamples>").unwrap());
    format!("{}<NumSamples>{spp}{}", &camera[..a], &camera[b..])
}
