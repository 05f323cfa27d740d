//! The `arbor` binary as a user runs it: outputs, summary lines and exit codes.

use std::path::Path;
use std::process::{Command, Output};

fn arbor(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_arbor")).args(args).current_dir(cwd).output().expect("arbor runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const TINY: &str = r#"<Scene>
    <Cameras>
        <Camera id="1">
            <Position>0 0 5</Position>
            <Gaze>0 0 -1</Gaze>
            <Up>0 1 0</Up>
            <NearPlane>-1 1 -1 1</NearPlane>
            <NearDistance>2</NearDistance>
            <ImageResolution>24 16</ImageResolution>
            <ImageName>tiny.IMAGE_EXT</ImageName>
        </Camera>
    </Cameras>
    <Lights>
        <AmbientLight>30 30 30</AmbientLight>
        <PointLight id="1"><Position>0 3 5</Position><Intensity>900 900 900</Intensity></PointLight>
    </Lights>
    <Materials>
        <Material id="1">
            <AmbientReflectance>1 1 1</AmbientReflectance>
            <DiffuseReflectance>1 0.5 0.2</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
    </Materials>
    <VertexData>0 0 0</VertexData>
    <Objects>
        <Sphere id="1"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere>
    </Objects>
</Scene>
"#;

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
fn cli_usage_error_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(arbor(&["render", "--spp", "zero"], tmp.path()).status.code(), Some(2));
    assert_eq!(arbor(&["frobnicate"], tmp.path()).status.code(), Some(2));
    assert_eq!(arbor(&["render", "--accel", "quadtree"], tmp.path()).status.code(), Some(2));
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
    let differ = arbor(&["diff", "a/tiny.png", "b/tiny.png"], tmp.path());
    assert_eq!(differ.status.code(), Some(1), "{}", stdout(&differ));
    assert!(stdout(&differ).contains("PSNR"), "{}", stdout(&differ));
}

#[test]
fn cli_info_describes_the_scene() {
    let tmp = tempfile::tempdir().unwrap();
    let a = write(tmp.path(), "a.xml", &TINY.replace("IMAGE_EXT", "png"));
    let o = arbor(&["info", a.to_str().unwrap()], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("24x16") && out.contains("sphere") && out.contains("bvh-sah"), "{out}");
}
