//! `arbor bench` and `arbor render --debug` as a user runs them: rows, JSON, exit codes, images.

use std::path::Path;
use std::process::{Command, Output};

use arbor::accel::AccelKind;

fn arbor(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_arbor")).args(args).current_dir(cwd).output().expect("arbor runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const QUICK: &[&str] = &["bench", "sphere:3000", "--size", "40x30", "--runs", "1"];

#[test]
fn bench_prints_a_row_per_structure_without_mismatches() {
    let tmp = tempfile::tempdir().unwrap();
    let o = arbor(QUICK, tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("primary: 1200") && out.contains("brute force traces a sample of"), "{out}");
    let header = out.lines().find(|l| l.starts_with("structure")).expect("a header row");
    assert!(header.contains("Mr/s") && header.contains("x brute") && header.ends_with("mismatch"), "{header}");
    for kind in AccelKind::ALL {
        let row = out.lines().find(|l| l.split_whitespace().next() == Some(kind.name()));
        let row = row.unwrap_or_else(|| panic!("no row for {kind}:\n{out}"));
        assert_eq!(row.split_whitespace().last(), Some("0"), "{row}");
    }
}

#[test]
fn bench_json_is_valid_and_complete() {
    let tmp = tempfile::tempdir().unwrap();
    let mut args = QUICK.to_vec();
    args.extend(["--json", "--accel", "brute,bvh-sah", "--accel-param", "bvh-sah:leaf=2"]);
    let o = arbor(&args, tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("valid JSON");
    let rows = doc["structures"].as_array().unwrap();
    let kinds: Vec<&str> = rows.iter().map(|r| r["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["brute", "bvh-sah"]);
    for r in rows {
        assert_eq!(r["mismatches"], 0);
        assert!(r["primary"]["mrays"].as_f64().unwrap() > 0.0 && r["nodes"].as_u64().unwrap() >= 1);
    }
    assert!(rows[1]["primary"]["speedup"].as_f64().unwrap() > 1.0, "{}", rows[1]);
    assert_eq!(doc["rays"]["primary"]["rays"], 1200);
}

#[test]
fn bench_bad_arguments_exit_with_clear_messages() {
    let tmp = tempfile::tempdir().unwrap();
    let o = arbor(&["bench", "sphere:100", "--accel", "bvh-sah,quadtree"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown acceleration structure 'quadtree'"), "{}", stderr(&o));
    let o = arbor(&["bench", "sphere:100", "--accel-param", "octree:colour=red"], tmp.path());
    assert_eq!(o.status.code(), Some(3));
    assert!(stderr(&o).contains("octree has no parameter 'colour'"), "{}", stderr(&o));
    let o = arbor(&["bench", "sphere:lots"], tmp.path());
    assert_eq!(o.status.code(), Some(3));
    let o = arbor(&["bench", "nowhere.ply"], tmp.path());
    assert_eq!(o.status.code(), Some(4));
    assert!(stderr(&o).contains("nowhere.ply"), "{}", stderr(&o));
}

#[test]
fn bench_mesh_file_is_framed_by_default_camera() {
    let tmp = tempfile::tempdir().unwrap();
    let off = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    std::fs::write(tmp.path().join("quad.off"), off).unwrap();
    let o = arbor(&["bench", "quad.off", "--size", "16x16", "--accel", "bvh-sah", "--rays", "primary"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    // The framed square fills a good part of the image.
    let hits: usize = out
        .lines()
        .find(|l| l.contains("primary: 256"))
        .and_then(|l| l.split('(').nth(1)?.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(hits > 40, "{out}");
}

#[test]
fn render_debug_views_write_images_and_report_the_heatmap_maximum() {
    let tmp = tempfile::tempdir().unwrap();
    for view in ["primid", "normal", "heatmap", "boxes", "boxes:1"] {
        let out_dir = format!("out-{}", view.replace(':', "-"));
        let o = arbor(&["render", "--debug", view, "-o", &out_dir], tmp.path());
        assert!(o.status.success(), "{view}: {}", stderr(&o));
        assert!(tmp.path().join(&out_dir).join("cornell_box.png").is_file(), "{view}");
        let out = stdout(&o);
        assert!(out.contains("nodes") && out.contains("leaves"), "{out}");
        assert_eq!(out.contains("heatmap maximum"), view == "heatmap", "{out}");
    }
    let o = arbor(&["render", "--debug", "boxes:deep"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("'deep'"), "{}", stderr(&o));
}
