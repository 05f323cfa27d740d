//! `arbor bench` and `arbor render --debug` as a user runs them: rows, JSON, exit codes, images.

mod common;

use arbor::accel::AccelKind;
use common::{arbor, stderr, stdout};

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
    assert!(["avx512", "avx2", "sse", "scalar"].contains(&doc["kernel"].as_str().unwrap()), "{}", doc["kernel"]);
}

#[test]
fn bench_bad_arguments_exit_with_clear_messages() {
    let tmp = tempfile::tempdir().unwrap();
    let o = arbor(&["bench", "sphere:100", "--accel", "bvh-sah,quadtree"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown acceleration structure 'quadtree'"), "{}", stderr(&o));
    let o = arbor(&["bench", "sphere:100", "--accel-param", "octree:colour=red"], tmp.path());
    assert_eq!(o.status.code(), Some(2), "a parameter that does not apply is a usage error");
    assert!(stderr(&o).contains("octree has no parameter 'colour'"), "{}", stderr(&o));
    // A misspelt ray set is a usage error listing the valid ones, not taken for a folder.
    let o = arbor(&["bench", "sphere:100", "--rays", "primry"], tmp.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("invalid value 'primry' for '--rays <RAYS>'")
            && stderr(&o).contains("[possible values: primary, diffuse, both]"),
        "{}",
        stderr(&o)
    );
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

/// One ray record of peerbench's `.rays` files and one `.hits` record.
fn ray_record(o: [f32; 3], d: [f32; 3]) -> Vec<u8> {
    [o[0], o[1], o[2], 0.0, d[0], d[1], d[2], f32::INFINITY].iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn hit_record(t: f32, prim: u32) -> Vec<u8> {
    t.to_le_bytes().into_iter().chain(prim.to_le_bytes()).collect()
}

#[test]
fn bench_ray_files_print_peerbench_lines_and_count_mismatches() {
    let tmp = tempfile::tempdir().unwrap();
    let off = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    std::fs::write(tmp.path().join("quad.off"), off).unwrap();
    let dir = tmp.path().join("rays");
    std::fs::create_dir(&dir).unwrap();
    // Two rays straight down onto the square (t = 2), one beside it; the reference is wrong on the third.
    let rays = [
        ([0.25, 0.5, 2.0], [0.0, 0.0, -1.0]),
        ([0.75, 0.5, 2.0], [0.0, 0.0, -1.0]),
        ([3.0, 0.5, 2.0], [0.0, 0.0, -1.0]),
    ];
    let bytes: Vec<u8> = rays.iter().flat_map(|(o, d)| ray_record(*o, *d)).collect();
    let hits: Vec<u8> = [hit_record(2.0, 1), hit_record(2.0, 0), hit_record(5.0, 1)].concat();
    for set in ["primary", "diffuse"] {
        std::fs::write(dir.join(format!("{set}.rays")), &bytes).unwrap();
        std::fs::write(dir.join(format!("{set}.hits")), &hits).unwrap();
    }
    let o = arbor(&["bench", "quad.off", "--ray-dir", "rays", "--threads", "1", "--runs", "1"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("peer=")).collect();
    assert_eq!(lines.len(), 4, "{out}");
    let expected = [("", "primary"), ("-batch", "primary"), ("", "diffuse"), ("-batch", "diffuse")];
    for (line, (mode, set)) in lines.iter().zip(expected) {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let peer = format!("peer=arbor-bvh-sah{mode}");
        assert_eq!(fields[..3], [&peer[..], &format!("set={set}")[..], "threads=1"], "{line}");
        assert!(fields[3].starts_with("build_ms=") && fields[4].starts_with("mrays="), "{line}");
        assert_eq!(fields[5], "hits=2", "{line}");
        assert!(line.contains("mismatch=0.333333"), "{line}");
        let kernel = line.split_whitespace().find_map(|f| f.strip_prefix("kernel=")).unwrap_or("");
        assert!(["avx512", "avx2", "sse", "scalar"].contains(&kernel), "{line}");
    }

    // --query any times the any-hit query: blocked or not, judged against whether the reference hit.
    let o = arbor(&["bench", "quad.off", "--ray-dir", "rays", "--query", "any", "--runs", "1"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("peer=")).collect();
    assert_eq!(lines.len(), 4, "{out}");
    for (line, mode) in lines.iter().zip(["-any", "-any-batch", "-any", "-any-batch"]) {
        assert!(line.starts_with(&format!("peer=arbor-bvh-sah{mode} ")), "{line}");
        assert!(line.contains(" hits=2 ") && line.contains("mismatch=0.333333"), "{line}");
    }
    let o = arbor(&["bench", "quad.off", "--query", "any"], tmp.path());
    assert_eq!(o.status.code(), Some(2), "--query needs --ray-dir: {}", stderr(&o));

    // --rays picks the sets of the folder: the primary files are not even read.
    std::fs::write(dir.join("primary.rays"), b"").unwrap();
    let o = arbor(&["bench", "quad.off", "--ray-dir", "rays", "--rays", "diffuse", "--runs", "1"], tmp.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let sets: Vec<String> = stdout(&o).lines().filter(|l| l.starts_with("peer=")).map(|l| l.to_string()).collect();
    assert_eq!(sets.len(), 2, "{sets:?}");
    assert!(sets.iter().all(|l| l.contains(" set=diffuse ")), "{sets:?}");
    // Read, a file without rays is bad input: it would time nothing.
    std::fs::write(dir.join("primary.hits"), b"").unwrap();
    let o = arbor(&["bench", "quad.off", "--ray-dir", "rays", "--runs", "1"], tmp.path());
    assert_eq!((o.status.code(), stderr(&o).as_str()), (Some(3), "error: rays/primary.rays: the file holds no rays\n"));
    std::fs::write(dir.join("primary.rays"), &bytes).unwrap();
    // A reference hit on a triangle the mesh lacks (it has 2).
    std::fs::write(dir.join("primary.hits"), [hit_record(2.0, 1), hit_record(2.0, 2), hit_record(5.0, 1)].concat())
        .unwrap();
    let o = arbor(&["bench", "quad.off", "--ray-dir", "rays", "--runs", "1"], tmp.path());
    let want = "error: rays/primary.hits: byte 12: hit 1: triangle 2 is not in the mesh (it has 2 triangles)\n";
    assert_eq!((o.status.code(), stderr(&o).as_str()), (Some(3), want));
    std::fs::write(dir.join("primary.hits"), &hits).unwrap();

    // A truncated ray file is bad input (exit 3) named with its byte offset; a missing one an I/O error.
    std::fs::write(dir.join("diffuse.rays"), &bytes[..40]).unwrap();
    let o = arbor(&["bench", "quad.off", "--ray-dir", "rays", "--runs", "1"], tmp.path());
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("diffuse.rays") && stderr(&o).contains("byte 32"), "{}", stderr(&o));
    let o = arbor(&["bench", "quad.off", "--ray-dir", "nowhere", "--runs", "1"], tmp.path());
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(stderr(&o).contains("primary.rays"), "{}", stderr(&o));
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
