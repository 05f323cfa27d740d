//! The everyday mistakes and odd files of the hardening issue, through the real binary: mesh files
//! truncated between renders, named pipes and devices where files are expected, signals while the scene
//! is still loading, thread counts, images too large for the memory there is, output paths, and what the
//! messages say. Every run has a time limit and fails instead of hanging; every failure is checked for
//! its exit code, its exact message and for leaving the output folder as it was.

#![cfg(unix)]

mod common;

use common::stderr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const ARBOR: &str = env!("CARGO_BIN_EXE_arbor");

/// Runs `cmd` to its end, killing it and failing after `limit`.
fn finish(mut cmd: Command, limit: Duration) -> Output {
    let child = cmd.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("arbor runs");
    let pid = child.id();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(child.wait_with_output()));
    match rx.recv_timeout(limit) {
        Ok(out) => out.unwrap(),
        Err(_) => {
            let _ = Command::new("kill").arg("-KILL").arg(pid.to_string()).status();
            panic!("{cmd:?} still running after {limit:?}: killed");
        }
    }
}

fn arbor(args: &[&str], cwd: &Path) -> Output {
    let mut cmd = Command::new(ARBOR);
    cmd.args(args).current_dir(cwd);
    finish(cmd, Duration::from_secs(20))
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// A one-camera scene whose object is `object` and whose image is `image`.
fn scene(object: &str, image: &str) -> String {
    format!(
        r#"<Scene>
    <Cameras>
        <Camera id="1">
            <Position>0.5 0.5 3</Position>
            <Gaze>0 0 -1</Gaze>
            <Up>0 1 0</Up>
            <NearPlane>-1 1 -1 1</NearPlane>
            <NearDistance>2</NearDistance>
            <ImageResolution>24 16</ImageResolution>
            <ImageName>{image}</ImageName>
        </Camera>
    </Cameras>
    <Lights>
        <AmbientLight>30 30 30</AmbientLight>
        <PointLight id="1"><Position>0 3 5</Position><Intensity>900 900 900</Intensity></PointLight>
    </Lights>
    <Materials>
        <Material id="1"><AmbientReflectance>1 1 1</AmbientReflectance><DiffuseReflectance>1 0.5 0.2</DiffuseReflectance></Material>
    </Materials>
    <VertexData>0.5 0.5 0</VertexData>
    <Objects>
        {object}
    </Objects>
</Scene>
"#
    )
}

const SPHERE: &str = r#"<Sphere id="1"><Material>1</Material><Center>1</Center><Radius>0.5</Radius></Sphere>"#;

fn mesh_object(file: &str) -> String {
    format!(r#"<Mesh id="1"><Material>1</Material><Faces plyFile="{file}"/></Mesh>"#)
}

/// `line:col` of the first `needle` in `text` (1-based), as the scene readers locate elements.
fn position(text: &str, needle: &str) -> String {
    let at = text.find(needle).unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("{line}:{col}")
}

/// A binary little-endian PLY of an `n` x `n` grid of vertices over the unit square (2 (n-1)^2 triangles).
fn grid_ply(path: &Path, n: u32) {
    let faces = 2 * (n - 1) * (n - 1);
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n",
        n * n
    )
    .into_bytes();
    for j in 0..n {
        for i in 0..n {
            for v in [i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32, 0.0] {
                bytes.extend(v.to_le_bytes());
            }
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            for tri in [[a, a + 1, a + n + 1], [a, a + n + 1, a + n]] {
                bytes.push(3);
                tri.iter().for_each(|v| bytes.extend(v.to_le_bytes()));
            }
        }
    }
    std::fs::write(path, bytes).unwrap();
}

fn mkfifo(path: &Path) {
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success(), "mkfifo {}", path.display());
}

#[test]
fn hardening_mesh_truncated_between_renders_exits_3_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    grid_ply(&tmp.path().join("grid.ply"), 30);
    std::fs::write(tmp.path().join("s.xml"), scene(&mesh_object("grid.ply"), "grid.png")).unwrap();
    let first = arbor(&["render", "-q", "s.xml", "-o", "out"], tmp.path());
    assert!(first.status.success(), "{}", stderr(&first));
    let image = std::fs::read(tmp.path().join("out/grid.png")).unwrap();
    let file = std::fs::OpenOptions::new().write(true).open(tmp.path().join("grid.ply")).unwrap();
    let len = file.metadata().unwrap().len();
    file.set_len(len / 2).unwrap();
    drop(file);
    let second = arbor(&["render", "-q", "s.xml", "-o", "out"], tmp.path());
    assert_eq!(second.status.code(), Some(3), "no exit code means a signal (SIGBUS?): {:?}", second.status);
    let err = stderr(&second);
    assert!(err.starts_with("error: grid.ply: byte ") && err.contains(": unexpected end of file in face "), "{err}");
    assert_eq!(std::fs::read(tmp.path().join("out/grid.png")).unwrap(), image, "the older image was touched");
    assert_eq!(entries(&tmp.path().join("out")), ["grid.png"]);
}

#[test]
fn hardening_pipes_and_devices_are_refused_not_read() {
    let tmp = tempfile::tempdir().unwrap();
    mkfifo(&tmp.path().join("pipe.ply"));
    std::os::unix::fs::symlink("/dev/zero", tmp.path().join("zero.ply")).unwrap();
    for (file, what) in [("pipe.ply", "a named pipe"), ("zero.ply", "a character device")] {
        let text = scene(&mesh_object(file), "m.png");
        std::fs::write(tmp.path().join("s.xml"), &text).unwrap();
        let o = arbor(&["render", "s.xml", "-o", "out"], tmp.path());
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        let want = format!(
            "error: s.xml:{}: Mesh 1: cannot read mesh file '{file}': not a regular file ({what})\n",
            position(&text, "<Mesh")
        );
        assert_eq!(stderr(&o), want);
        assert!(!tmp.path().join("out").exists());
        // Given directly to bench: the file named on the command line cannot be read, exit 4.
        let o = arbor(&["bench", file], tmp.path());
        assert_eq!((o.status.code(), stderr(&o)), (Some(4), format!("error: {file}: not a regular file ({what})\n")));
    }
    // Images: an environment map the scene names, one on the command line, an image to compare.
    mkfifo(&tmp.path().join("sky.exr"));
    let text = scene(SPHERE, "m.png")
        .replace("<Lights>", "<Lights>\n        <SphericalDirectionalLight id=\"1\"><EnvMapName>sky.exr</EnvMapName></SphericalDirectionalLight>");
    std::fs::write(tmp.path().join("env.xml"), &text).unwrap();
    let o = arbor(&["render", "env.xml", "-o", "out"], tmp.path());
    let at = position(&text, "<EnvMapName>");
    let want =
        format!("error: env.xml:{at}: cannot read environment map 'sky.exr': not a regular file (a named pipe)\n");
    assert_eq!((o.status.code(), stderr(&o)), (Some(3), want));
    std::fs::write(tmp.path().join("s.xml"), scene(SPHERE, "m.png")).unwrap();
    let o = arbor(&["render", "s.xml", "--env", "sky.exr", "-o", "out"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o)), (Some(4), "error: sky.exr: not a regular file (a named pipe)\n".into()));
    let o = arbor(&["diff", "sky.exr", "zero.ply"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o)), (Some(4), "error: sky.exr: not a regular file (a named pipe)\n".into()));
    // The scene file and the partials of a merge, named on the command line.
    mkfifo(&tmp.path().join("pipe.xml"));
    let o = arbor(&["render", "pipe.xml", "-o", "out"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o)), (Some(4), "error: pipe.xml: not a regular file (a named pipe)\n".into()));
    let o = arbor(&["merge", "sky.exr", "-o", "out/m.png"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o)), (Some(4), "error: sky.exr: not a regular file (a named pipe)\n".into()));
    assert!(!tmp.path().join("out").exists());
}

/// Starts a render whose scene takes seconds to load and build (a 2-million-triangle mesh under the
/// kd-tree), sends `signal` after `delay` and returns the exit code and how long the process took to
/// stop after the signal.
fn signal_during_load(signal: &str, delay: Duration) -> (Option<i32>, Duration, Vec<String>) {
    let tmp = tempfile::tempdir().unwrap();
    grid_ply(&tmp.path().join("big.ply"), 1001);
    std::fs::write(tmp.path().join("s.xml"), scene(&mesh_object("big.ply"), "big.png")).unwrap();
    let mut child = Command::new(ARBOR)
        .args(["render", "-q", "s.xml", "--accel", "kdtree", "-o", "out"])
        .current_dir(tmp.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(delay);
    assert!(child.try_wait().unwrap().is_none(), "the render ended before the signal: make the scene slower");
    assert!(Command::new("kill").arg(format!("-{signal}")).arg(child.id().to_string()).status().unwrap().success());
    let sent = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status.code(), sent.elapsed(), entries(tmp.path()));
        }
        if sent.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            panic!("arbor did not stop within 30 s of SIG{signal}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn hardening_signal_while_loading_stops_at_once() {
    for (signal, code, delay) in [("TERM", 143, 300), ("INT", 130, 900)] {
        let (got, took, left) = signal_during_load(signal, Duration::from_millis(delay));
        assert_eq!(got, Some(code), "SIG{signal}");
        assert!(took < Duration::from_secs(1), "SIG{signal}: stopped {took:?} after the signal");
        assert_eq!(left, ["big.ply", "s.xml"], "SIG{signal} left output behind");
    }
}

#[test]
fn hardening_thread_counts() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("s.xml"), scene(SPHERE, "s.png")).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let too_many = (4 * cores + 1).to_string();
    for command in [&["render", "s.xml", "-o", "out"][..], &["bench", "sphere:100", "--runs", "1"][..]] {
        for n in [too_many.as_str(), "10000"] {
            let mut args = command.to_vec();
            args.extend(["--threads", n]);
            let start = Instant::now();
            let o = arbor(&args, tmp.path());
            assert!(start.elapsed() < Duration::from_secs(10), "{args:?} took {:?}", start.elapsed());
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            let want = format!(
                "error: invalid value '{n}' for '--threads <N>': at most {} threads (4 per core on this machine of \
                 {cores}); 0 uses all cores",
                4 * cores
            );
            assert!(stderr(&o).starts_with(&want), "{}", stderr(&o));
        }
    }
    assert!(!tmp.path().join("out").exists());
    let o = arbor(&["render", "-q", "s.xml", "--threads", "0", "-o", "out"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let help = String::from_utf8_lossy(&arbor(&["render", "--help"], tmp.path()).stdout).into_owned();
    assert!(help.contains("--threads <N>") && help.contains("0 uses all cores"), "{help}");
}

#[test]
fn hardening_image_too_large_for_the_memory_exits_4() {
    let tmp = tempfile::tempdir().unwrap();
    let text = scene(SPHERE, "huge.png").replace("<ImageResolution>24 16<", "<ImageResolution>30000 30000<");
    std::fs::write(tmp.path().join("s.xml"), text).unwrap();
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" \"$@\"")
        .arg(ARBOR)
        .args(["render", "s.xml", "--no-limits", "-o", "out"])
        .current_dir(tmp.path());
    let o = finish(cmd, Duration::from_secs(20));
    // 9e8 pixels of sums, film, encoding, and the full-frame film: 100 bytes each.
    assert_eq!(
        (o.status.code(), stderr(&o)),
        (Some(4), "error: not enough memory for a 30000x30000 image (83.8 GiB)\n".to_string())
    );
    assert!(!tmp.path().join("out").exists() || entries(&tmp.path().join("out")).is_empty());
}

#[test]
fn hardening_o_names_an_image_or_a_folder() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("one.xml"), scene(SPHERE, "s.png")).unwrap();
    let o = arbor(&["render", "-q", "one.xml", "-o", "out.jpg"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(tmp.path().join("out.jpg")).unwrap().starts_with(&[0xff, 0xd8, 0xff]), "not a JPEG");
    assert!(String::from_utf8_lossy(&o.stdout).contains("Saved: out.jpg"));

    let two = scene(SPHERE, "a.png").replace(
        "    </Cameras>",
        "        <Camera id=\"2\"><Position>0 0 5</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up><NearPlane>-1 1 -1 1</NearPlane>\
         <NearDistance>2</NearDistance><ImageResolution>8 8</ImageResolution><ImageName>b.png</ImageName></Camera>\n    </Cameras>",
    );
    std::fs::write(tmp.path().join("two.xml"), two).unwrap();
    let o = arbor(&["render", "two.xml", "-o", "two.png"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o),
        "error: -o two.png names one image, but the scene has 2 cameras: -o names a folder for them (or pick one \
         with --camera ID)\n"
    );
    let o = arbor(&["render", "-q", "two.xml", "-o", "b.png", "--camera", "2"], tmp.path());
    assert!(o.status.success() && tmp.path().join("b.png").is_file(), "{}", stderr(&o));
    let o = arbor(&["render", "one.xml", "-o", "out.bmp"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stderr(&o), "error: cannot write .bmp images; supported: png, ppm, exr, hdr, jpg, jpeg\n");
    assert_eq!(entries(tmp.path()), ["b.png", "one.xml", "out.jpg", "two.xml"]);
}

#[test]
fn hardening_output_paths_are_checked_before_rendering() {
    let tmp = tempfile::tempdir().unwrap();
    let text = scene(SPHERE, "s.tga");
    std::fs::write(tmp.path().join("tga.xml"), &text).unwrap();
    let o = arbor(&["render", "tga.xml", "-o", "out"], tmp.path());
    let want = format!(
        "error: tga.xml:{}: Camera 1: ImageName 's.tga': cannot write .tga images; supported: png, ppm, exr, hdr, jpg, jpeg\n",
        position(&text, "<ImageName>")
    );
    assert_eq!((o.status.code(), stderr(&o)), (Some(3), want));
    assert!(o.stdout.is_empty(), "rendered before failing");

    let text = scene(SPHERE, "s.png");
    std::fs::write(tmp.path().join("s.xml"), &text).unwrap();
    let o = arbor(&["render", "s.xml", "-o", "out", "--stats-json", "nowhere/stats.json"], tmp.path());
    let want = "error: nowhere/stats.json: cannot write it: the folder nowhere does not exist\n";
    assert_eq!((o.status.code(), stderr(&o).as_str()), (Some(4), want));
    assert!(!tmp.path().join("out").exists(), "the image was written before the stats path was checked");

    // A folder that takes no new file; as root, permission bits do not stop writes, and /sys stands in.
    let locked = tmp.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    let mut perms = std::fs::metadata(&locked).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&locked, perms).unwrap();
    let folder = if std::fs::write(locked.join("probe"), b"").is_ok() { PathBuf::from("/sys") } else { locked };
    let o = arbor(&["render", "s.xml", "-o", folder.to_str().unwrap()], tmp.path());
    let want = format!(
        "error: s.xml:{}: Camera 1: ImageName 's.png': {}: cannot write it: Permission denied (os error 13)\n",
        position(&text, "<ImageName>"),
        folder.join("s.png").display()
    );
    assert_eq!((o.status.code(), stderr(&o)), (Some(4), want));
    assert_eq!(entries(tmp.path()), ["locked", "s.xml", "tga.xml"]);
}

#[test]
fn hardening_scene_images_stay_in_the_output_folder_and_apart() {
    let tmp = tempfile::tempdir().unwrap();
    let outside = tmp.path().join("abs.png");
    for name in ["../escape.png", "a/../../escape.png", outside.to_str().unwrap()] {
        let text = scene(SPHERE, name);
        std::fs::write(tmp.path().join("up.xml"), &text).unwrap();
        let o = arbor(&["render", "up.xml", "-o", "out"], tmp.path());
        let want = format!(
            "error: up.xml:{}: Camera 1: ImageName '{name}': must be a name inside the output folder (no absolute \
             path, no '..')\n",
            position(&text, "<ImageName>")
        );
        assert_eq!((o.status.code(), stderr(&o)), (Some(3), want));
        assert_eq!(entries(tmp.path()), ["up.xml"], "{name}: wrote something");
    }

    // Two cameras whose files collide: the second's HDR image brings a PNG of the first's name.
    let one = scene(SPHERE, "s.png");
    let second = one.find("</Camera>").map(|i| i + "</Camera>".len()).unwrap();
    let camera = &one[one.find("<Camera ").unwrap()..second];
    let camera2 = camera.replace(r#"id="1""#, r#"id="2""#).replace("s.png", "s.exr");
    let text = format!("{}\n{camera2}{}", &one[..second], &one[second..]);
    std::fs::write(tmp.path().join("two.xml"), &text).unwrap();
    let o = arbor(&["render", "two.xml", "-o", "out"], tmp.path());
    let want = format!(
        "error: two.xml:{}: Camera 2: ImageName 's.exr': out/s.png would also be written by camera 1\n",
        position(&text, "<ImageName>s.exr")
    );
    assert_eq!((o.status.code(), stderr(&o)), (Some(3), want));

    // A statistics file that is a folder is refused before rendering.
    std::fs::write(tmp.path().join("s.xml"), scene(SPHERE, "s.png")).unwrap();
    std::fs::create_dir(tmp.path().join("stats")).unwrap();
    let o = arbor(&["render", "s.xml", "-o", "out", "--stats-json", "stats"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o).as_str()), (Some(4), "error: stats: cannot write it: it is a folder\n"));
    assert_eq!(entries(tmp.path()), ["s.xml", "stats", "two.xml", "up.xml"]);
}

#[test]
fn hardening_hdr_image_and_its_png_are_checked_together() {
    let tmp = tempfile::tempdir().unwrap();
    let text = scene(SPHERE, "s.exr");
    std::fs::write(tmp.path().join("s.xml"), &text).unwrap();
    // The PNG beside the EXR cannot be written (a folder has its name): refused before rendering, and
    // the EXR is not written alone.
    std::fs::create_dir(tmp.path().join("x.png")).unwrap();
    let o = arbor(&["render", "s.xml", "-o", "x.exr"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o).as_str()), (Some(4), "error: x.png: cannot write it: it is a folder\n"));
    assert!(o.stdout.is_empty(), "rendered before failing");
    std::fs::create_dir_all(tmp.path().join("out/s.png")).unwrap();
    let o = arbor(&["render", "s.xml", "-o", "out"], tmp.path());
    let at = position(&text, "<ImageName>");
    let want = format!("error: s.xml:{at}: Camera 1: ImageName 's.exr': out/s.png: cannot write it: it is a folder\n");
    assert_eq!((o.status.code(), stderr(&o)), (Some(4), want));
    assert_eq!(entries(tmp.path()), ["out", "s.xml", "x.png"]);
    assert_eq!(entries(&tmp.path().join("out")), ["s.png"]);
    // A debug view is written without a PNG beside it, so the folder is in nobody's way.
    let o = arbor(&["render", "-q", "s.xml", "-o", "x.exr", "--debug", "normal"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(entries(tmp.path()), ["out", "s.xml", "x.exr", "x.png"]);
    assert!(tmp.path().join("x.png").is_dir());
    std::fs::remove_file(tmp.path().join("x.exr")).unwrap();
    // An older PNG of that name is replaced, as --help says.
    std::fs::remove_dir(tmp.path().join("x.png")).unwrap();
    std::fs::write(tmp.path().join("x.png"), b"older").unwrap();
    let o = arbor(&["render", "-q", "s.xml", "-o", "x.exr"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(tmp.path().join("x.png")).unwrap().starts_with(b"\x89PNG"));
    assert_eq!(entries(tmp.path()), ["out", "s.xml", "x.exr", "x.png"]);
}

#[test]
fn hardening_short_render_prints_no_progress_to_a_log() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("s.xml"), scene(SPHERE, "s.png")).unwrap();
    // Standard error is a pipe here, as in a batch job's log.
    let o = arbor(&["render", "s.xml", "-o", "out"], tmp.path());
    assert!(o.status.success());
    assert_eq!(stderr(&o), "", "a render shorter than the progress interval logs nothing");
}

#[test]
fn hardening_help_lists_every_command() {
    let tmp = tempfile::tempdir().unwrap();
    let help = String::from_utf8_lossy(&arbor(&["--help"], tmp.path()).stdout).into_owned();
    assert!(help.contains("render, info, bench, diff and merge"), "{help}");
    for command in ["render", "info", "bench", "merge", "diff"] {
        assert!(help.lines().any(|l| l.trim_start().starts_with(command)), "no {command} in:\n{help}");
    }
}

#[test]
fn hardening_signal_stops_bench_and_info_too() {
    let tmp = tempfile::tempdir().unwrap();
    grid_ply(&tmp.path().join("big.ply"), 1001);
    std::fs::write(tmp.path().join("s.xml"), scene(&mesh_object("big.ply"), "big.png")).unwrap();
    for args in [&["bench", "sphere:3000000", "--runs", "1"][..], &["info", "s.xml", "--accel", "kdtree"][..]] {
        let mut child = Command::new(ARBOR)
            .args(args)
            .current_dir(tmp.path())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(500));
        assert!(child.try_wait().unwrap().is_none(), "{args:?} ended before the signal");
        assert!(Command::new("kill").arg("-TERM").arg(child.id().to_string()).status().unwrap().success());
        let sent = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status;
            }
            if sent.elapsed() > Duration::from_secs(30) {
                let _ = child.kill();
                panic!("{args:?} did not stop within 30 s of SIGTERM");
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        assert_eq!(status.code(), Some(143), "{args:?}");
        assert!(sent.elapsed() < Duration::from_secs(1), "{args:?} stopped {:?} after SIGTERM", sent.elapsed());
        // Neither writes an image, so the message mentions none.
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(err, "interrupted\n", "{args:?}");
    }
}

/// `scene(SPHERE, first)` with a second camera (id 2) writing `second` at `resolution`.
fn two_cameras(first: &str, second: &str, resolution: &str) -> String {
    let one = scene(SPHERE, first);
    let end = one.find("</Camera>").map(|i| i + "</Camera>".len()).unwrap();
    let camera = &one[one.find("<Camera ").unwrap()..end];
    let camera2 = camera
        .replace(r#"id="1""#, r#"id="2""#)
        .replace(&format!(">{first}<"), &format!(">{second}<"))
        .replace(">24 16<", &format!(">{resolution}<"));
    format!("{}\n        {camera2}{}", &one[..end], &one[end..])
}

#[test]
fn hardening_a_run_of_several_cameras_writes_all_its_images_or_none() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("first.png"), b"an older image").unwrap();
    let unchanged = || {
        assert_eq!(entries(&out), ["first.png"], "left behind");
        assert_eq!(std::fs::read(out.join("first.png")).unwrap(), b"an older image", "clobbered");
    };

    // A second ImageName of 150,000 characters, which no file system holds: the first image was
    // written (over the older one), then the write of the second failed naming neither scene nor line.
    let long = format!("{}.png", "b".repeat(150_000));
    let text = two_cameras("first.png", &long, "24 16");
    std::fs::write(tmp.path().join("long.xml"), &text).unwrap();
    let o = arbor(&["render", "long.xml", "-o", "out"], tmp.path());
    let want = format!(
        "error: long.xml:{}: Camera 2: ImageName '{}…{}.png': a file or folder name in it is 150004 bytes long, more \
         than the 255 this file system takes (NAME_MAX)\n",
        position(&text, &format!("<ImageName>{long}")),
        "b".repeat(40),
        "b".repeat(12)
    );
    assert_eq!((o.status.code(), stderr(&o)), (Some(3), want));
    assert!(o.stdout.is_empty(), "rendered before failing");
    unchanged();

    // A NUL character (JSON can write one).
    let json = r#"{"Scene": {"Cameras": {"Camera": {"_id": "1", "Position": "0 0 5", "Gaze": "0 0 -1", "Up": "0 1 0",
            "NearPlane": "-1 1 -1 1", "NearDistance": "2", "ImageResolution": "8 8", "ImageName": "a\u0000b.png"}}}}"#;
    std::fs::write(tmp.path().join("nul.json"), json).unwrap();
    let o = arbor(&["render", "nul.json", "--no-warnings", "-o", "out"], tmp.path());
    let want = format!(
        "error: nul.json:{}: Camera 1: ImageName 'a\\u{{0}}b.png': contains a NUL character, which no file name may hold\n",
        position(json, "\"ImageName\"")
    );
    assert_eq!((o.status.code(), stderr(&o)), (Some(3), want));
    unchanged();

    // A second image too large for the memory there is: refused before the first render.
    let text = two_cameras("first.png", "second.png", "16000 16000");
    std::fs::write(tmp.path().join("big.xml"), &text).unwrap();
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" \"$@\"")
        .arg(ARBOR)
        .args(["render", "big.xml", "-o", "out"])
        .current_dir(tmp.path());
    let o = finish(cmd, Duration::from_secs(20));
    let want = "error: not enough memory for a 16000x16000 image (23.8 GiB)\n";
    assert_eq!((o.status.code(), stderr(&o).as_str()), (Some(4), want));
    unchanged();

    // A run that succeeds says what it wrote once everything is written.
    let text = two_cameras("first.png", "second.exr", "20 10");
    std::fs::write(tmp.path().join("two.xml"), &text).unwrap();
    let o = arbor(&["render", "two.xml", "-o", "out"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout);
    let saved: Vec<&str> = said.lines().filter(|l| l.starts_with("Saved: ")).collect();
    assert_eq!(saved, ["Saved: out/first.png", "Saved: out/second.exr", "Saved: out/second.png"]);
    assert!(said.lines().rev().take(3).all(|l| l.starts_with("Saved: ")), "the Saved lines come last:\n{said}");
    assert_eq!(entries(&out), ["first.png", "second.exr", "second.png"]);
    assert_ne!(std::fs::read(out.join("first.png")).unwrap(), b"an older image");
}
