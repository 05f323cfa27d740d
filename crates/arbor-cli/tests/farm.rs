//! Farm slices through the real binary: tiles, sample ranges and cameras rendered by separate
//! `arbor render` runs and put together by `arbor merge` give the single-process image byte for byte
//! (PNG and EXR); wrong slices are usage errors (exit 2) and parts that do not fit exit 3, each with
//! its exact message.

mod common;

use std::path::Path;
use std::process::Command;
use std::sync::LazyLock;

use common::arbor;

fn ok(args: &[&str], cwd: &Path) -> String {
    let o = arbor(args, cwd);
    assert!(o.status.success(), "arbor {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn fails(args: &[&str], cwd: &Path) -> (i32, String) {
    let o = arbor(args, cwd);
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn same_file(a: &Path, b: &Path) {
    let (x, y) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert!(x == y, "{} and {} differ", a.display(), b.display());
}

/// Two cameras looking at the shared sphere; 4 samples per pixel (jittered strata).
static TWO_CAMERAS: LazyLock<String> = LazyLock::new(|| {
    common::sphere_scene(
        r#"        <Camera id="front">
            <Position>0 0 5</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up>
            <NearPlane>-1 1 -1 1</NearPlane><NearDistance>2</NearDistance>
            <ImageResolution>37 23</ImageResolution><NumSamples>4</NumSamples>
            <ImageName>front.png</ImageName>
        </Camera>
        <Camera id="side">
            <Position>5 0 0</Position><Gaze>-1 0 0</Gaze><Up>0 1 0</Up>
            <NearPlane>-1 1 -1 1</NearPlane><NearDistance>2</NearDistance>
            <ImageResolution>29 31</ImageResolution><NumSamples>4</NumSamples>
            <ImageName>side.png</ImageName>
        </Camera>"#,
    )
});

#[test]
fn farm_cli_tiles_of_the_example_merge_to_the_whole_png() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    ok(&["render", "--quiet", "--spp", "2", "-o", "whole"], d);
    let mut parts = vec!["merge".to_string()];
    for i in 0..4 {
        let out = format!("parts/tile-{i}.exr");
        let said = ok(&["render", "--quiet", "--spp", "2", "--tile", &format!("{i}/4"), "-o", &out], d);
        assert_eq!(said, format!("Saved: {out}\n"));
        parts.push(out);
    }
    parts.extend(["-o".into(), "merged.png".into()]);
    let args: Vec<&str> = parts.iter().map(String::as_str).collect();
    assert!(ok(&args, d).ends_with("Saved: merged.png\n"));
    same_file(&d.join("merged.png"), &d.join("whole/cornell_box.png"));
}

#[test]
fn farm_cli_cameras_tiles_and_sample_ranges_merge_to_the_whole_exr() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // The side camera names a tone mapping; the front camera's PNG gets the default one.
    let tonemap = "<ImageName>side.exr</ImageName><Tonemap><TMO>Photographic</TMO><TMOOptions>0.3 5</TMOOptions>\
                   <Saturation>0.8</Saturation><Gamma>1.8</Gamma></Tonemap>";
    let scene = TWO_CAMERAS.replace(".png", ".exr").replace("<ImageName>side.exr</ImageName>", tonemap);
    std::fs::write(d.join("two.xml"), scene).unwrap();
    ok(&["render", "--quiet", "two.xml", "-o", "whole"], d);
    for cam in ["front", "side"] {
        let mut args = vec!["merge".to_string()];
        for i in 0..9 {
            for (k, n) in [(0, 1), (1, 3)] {
                let out = format!("{cam}-{i}-{k}.exr");
                let tile = format!("{i}/9");
                let (k, n) = (k.to_string(), n.to_string());
                let slice = ["--tile", &tile, "--sample-offset", &k, "--sample-count", &n, "-o", &out];
                ok(&[&["render", "--quiet", "two.xml", "--camera", cam][..], &slice[..]].concat(), d);
                args.push(out);
            }
        }
        args.extend(["-o".into(), format!("{cam}.exr")]);
        let said = ok(&args.iter().map(String::as_str).collect::<Vec<_>>(), d);
        assert!(said.ends_with(&format!("Saved: {cam}.exr\nSaved: {cam}.png\n")), "{said}");
        same_file(&d.join(format!("{cam}.exr")), &d.join(format!("whole/{cam}.exr")));
        // The tone-mapped PNG beside it, as the single-process render wrote it.
        same_file(&d.join(format!("{cam}.png")), &d.join(format!("whole/{cam}.png")));
    }
}

#[test]
fn farm_cli_refuses_wrong_slices_and_parts() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(d.join("two.xml"), &*TWO_CAMERAS).unwrap();
    let usage = [
        (&["--tile", "4/4", "--camera", "front", "-o", "a.exr"][..], "error: --tile 4/4: the index is 0-based, so it must be below 4\n"),
        (&["--tile", "0/0", "--camera", "front", "-o", "a.exr"][..], "error: --tile I/N needs N >= 1\n"),
        (&["--tile", "0/2000", "--camera", "front", "-o", "a.exr"][..], "error: --tile 0/2000: 2000 tiles do not fit a 37x23 frame\n"),
        (&["--tile", "0/4", "--camera", "front", "-o", "a.png"][..], "error: --tile, --sample-offset and --sample-count write a partial EXR: -o must name a .exr file, got 'a.png'\n"),
        (&["--tile", "0/4", "-o", "a.exr"][..], "error: a slice renders one camera, but two.xml has 2: pick one with --camera ID\n"),
        (&["--sample-offset", "3", "--sample-count", "2", "--camera", "side", "-o", "a.exr"][..], "error: --sample-offset 3 --sample-count 2: samples 3..5 are not inside the image's 4 samples per pixel (--spp or the scene's NumSamples)\n"),
        (&["--tile", "0/4", "--camera", "side", "--debug", "primid", "-o", "a.exr"][..], "error: --debug views cannot be rendered in slices\n"),
    ];
    for (flags, message) in usage {
        let (code, err) = fails(&[&["render", "two.xml"][..], flags].concat(), d);
        assert_eq!((code, err.as_str()), (2, message), "{flags:?}");
        assert!(!d.join("a.exr").exists() && !d.join("a.png").exists());
    }

    for (cam, i) in [("front", 0), ("front", 1), ("side", 2)] {
        let tile = format!("{i}/4");
        ok(&["render", "-q", "two.xml", "--camera", cam, "--tile", &tile, "-o", &format!("{cam}{i}.exr")], d);
    }
    let (code, err) = fails(&["merge", "front0.exr", "front1.exr", "-o", "m.png"], d);
    assert_eq!(
        (code, err.as_str()),
        (3, "error: the parts do not cover pixel (0, 11): no part has its samples 0..4\n")
    );
    let (code, err) = fails(&["merge", "front0.exr", "side2.exr", "-o", "m.png"], d);
    let msg = "error: side2.exr: not from the same render as front0.exr (the scene, camera or options differ)\n";
    assert_eq!((code, err.as_str()), (3, msg));
    let (code, err) = fails(&["merge", "front0.exr", "front0.exr", "-o", "m.png"], d);
    let msg = "error: front0.exr: samples 0..4 of pixel (0, 0) are also in front0.exr\n";
    assert_eq!((code, err.as_str()), (3, msg));
    assert!(!d.join("m.png").exists());
    // The output may not replace a part, nor may the PNG beside an HDR output.
    let before = std::fs::read(d.join("front0.exr")).unwrap();
    let (code, err) = fails(&["merge", "front0.exr", "front1.exr", "-o", "./front0.exr"], d);
    let msg = "error: -o ./front0.exr: merge would write ./front0.exr, which is the part front0.exr\n";
    assert_eq!((code, err.as_str()), (2, msg));
    std::fs::write(d.join("front0.png"), b"kept").unwrap();
    let (code, err) = fails(&["merge", "front0.exr", "front0.png", "-o", "front0.exr"], d);
    let msg = "error: -o front0.exr: merge would write front0.exr, which is the part front0.exr\n";
    assert_eq!((code, err.as_str()), (2, msg));
    let (code, err) = fails(&["merge", "front1.exr", "front0.png", "-o", "front0.hdr"], d);
    let msg = "error: -o front0.hdr: merge would write front0.png, which is the part front0.png\n";
    assert_eq!((code, err.as_str()), (2, msg));
    assert_eq!(std::fs::read(d.join("front0.exr")).unwrap(), before);
    assert_eq!(std::fs::read(d.join("front0.png")).unwrap(), b"kept");
}

#[test]
fn farm_cli_stats_json_and_plain_progress_lines() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(d.join("two.xml"), &*TWO_CAMERAS).unwrap();
    let o = arbor(&["render", "two.xml", "--camera", "side", "--stats-json", "stats.json", "-o", "out"], d);
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    // Standard error is a pipe here: plain progress lines, but none for a render shorter than their
    // interval (tests/hardening.rs and the progress unit test cover the lines themselves).
    assert!(!err.contains("side.png: "), "{err}");
    assert!(String::from_utf8_lossy(&o.stdout).ends_with("Saved: out/side.png\n"));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("stats.json")).unwrap()).unwrap();
    let image = &stats["images"][0];
    assert_eq!(image["camera"], "side");
    assert_eq!(image["scene"], "two.xml");
    assert_eq!((image["width"].as_u64(), image["height"].as_u64()), (Some(29), Some(31)));
    assert_eq!(image["window"], serde_json::json!([0, 0, 29, 31]));
    assert_eq!(image["samples"], serde_json::json!([0, 4]));
    for key in ["spp", "accel", "build_ms", "render_ms", "rays", "mrays_per_s", "threads", "kernel"] {
        assert!(!image[key].is_null(), "{key} missing");
    }
}

/// The first executable `name` on this process's PATH.
fn on_path(name: &str) -> std::path::PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path).map(|d| d.join(name)).find(|p| p.is_file()).unwrap_or_else(|| panic!("no {name}"))
}

#[test]
fn farm_slurm_submit_without_sbatch_creates_nothing() {
    // A PATH of only the tools submit.sh uses besides Slurm's: it ran `mkdir` and then failed on
    // `sbatch: command not found`, leaving OUTPUT's folder and the parts folder behind.
    let tmp = tempfile::tempdir().unwrap();
    let bin = tmp.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    for tool in ["bash", "realpath", "dirname", "mkdir"] {
        std::os::unix::fs::symlink(on_path(tool), bin.join(tool)).unwrap();
    }
    std::fs::write(tmp.path().join("scene.xml"), &*TWO_CAMERAS).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../deploy/slurm/submit.sh");
    let submit = || {
        Command::new(bin.join("bash"))
            .arg(&script)
            .args(["scene.xml", "4", "renders/frame.png"])
            .env_clear()
            .env("PATH", &bin)
            .current_dir(tmp.path())
            .output()
            .unwrap()
    };
    let o = submit();
    let want = format!(
        "{}: sbatch not found on PATH (Slurm's job submission; run this on a Slurm login node, or see docs/farm.md \
         for tiles without Slurm); nothing was created\n",
        script.display()
    );
    assert_eq!((o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned()), (Some(127), want));
    let mut left: Vec<String> =
        std::fs::read_dir(tmp.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, ["bin", "scene.xml"]);

    // With an sbatch (a stand-in that prints a job id), the folders are made and both jobs submitted.
    std::fs::write(bin.join("sbatch"), "#!/bin/sh\necho 42\n").unwrap();
    std::fs::set_permissions(bin.join("sbatch"), std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let o = submit();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(String::from_utf8_lossy(&o.stdout), "ARRAY_JOB=42\nMERGE_JOB=42\n");
    assert!(tmp.path().join("renders/parts").is_dir());
}
