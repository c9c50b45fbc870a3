//! `verify --shard I/N` as separate processes and `flexverify merge`: the merged report is the
//! one an unsharded run writes (identical apart from wall times); mismatched parts are refused.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A cheap filter: 23 quick cases (frequencies, statics, orders of the cantilever), < 1 s.
const FILTER: &str = "cantilever";

fn flexverify(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_flexverify"))
        .args(args)
        .output()
        .expect("run flexverify");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flexverify-shard-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The JSON value without its timing fields (`wall_time_s` and the repeated `timing`), at any
/// depth.
fn json_without_wall(text: &str) -> serde_json::Value {
    fn strip(v: serde_json::Value) -> serde_json::Value {
        match v {
            serde_json::Value::Object(m) => m
                .into_iter()
                .filter(|(k, _)| k != "wall_time_s" && k != "timing")
                .map(|(k, v)| (k, strip(v)))
                .collect(),
            serde_json::Value::Array(a) => a.into_iter().map(strip).collect(),
            other => other,
        }
    }
    strip(serde_json::from_str(text).expect("JSON"))
}

/// Columns of the study CSV that hold timings.
const STUDY_TIMING_COLUMNS: [&str; 5] =
    ["wall_s", "wall_median_s", "wall_max_s", "repeats", "spread"];

/// The CSV records without the named columns.
fn csv_without(text: &str, drop: &[&str]) -> Vec<Vec<String>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(text.as_bytes());
    let records: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    let keep: Vec<bool> = records[0].iter().map(|h| !drop.contains(&h)).collect();
    assert!(keep.iter().any(|k| !k), "none of {drop:?} in the header");
    records
        .iter()
        .map(|r| {
            r.iter()
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(c, _)| c.to_string())
                .collect()
        })
        .collect()
}

/// The CSV records with the `wall [s]` column removed.
fn csv_without_wall(text: &str) -> Vec<Vec<String>> {
    csv_without(text, &["wall [s]"])
}

fn shard_run(dir: &Path, filter: &str, shard: &str) -> (i32, String, String) {
    flexverify(&[
        "verify",
        "--suite",
        "quick",
        "--filter",
        filter,
        "--shard",
        shard,
        "--out",
        s(dir),
    ])
}

fn plot_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".svg") || n.ends_with(".png"))
        .collect();
    names.sort();
    names
}

#[test]
fn sys_shard_three_processes_merge_into_the_single_run() {
    let root = scratch("merge");
    let single = root.join("single");
    let (code_single, stdout_single, err) = flexverify(&[
        "verify",
        "--suite",
        "quick",
        "--filter",
        FILTER,
        "--format",
        "csv",
        "--out",
        s(&single),
    ]);
    assert!(code_single == 0 || code_single == 1, "{err}");
    let shards: Vec<PathBuf> = (1..=3).map(|i| root.join(format!("s{i}"))).collect();
    let mut rows = 0;
    for (i, dir) in shards.iter().enumerate() {
        let (code, _, err) = shard_run(dir, FILTER, &format!("{}/3", i + 1));
        assert!(code == 0 || code == 1, "{err}");
        let file = std::fs::read_to_string(dir.join(format!("shard-{}-of-3.json", i + 1))).unwrap();
        let v: serde_json::Value = serde_json::from_str(&file).unwrap();
        let share = v["outcomes"].as_array().unwrap().len();
        assert!(share > 0, "shard {} ran nothing", i + 1);
        rows += share;
    }
    let merged = root.join("merged");
    let mut args = vec!["merge"];
    args.extend(shards.iter().map(|d| s(d)));
    args.extend(["--format", "csv", "--out", s(&merged)]);
    let (code_merged, stdout_merged, err) = flexverify(&args);
    assert_eq!(code_merged, code_single, "{err}");

    let json_single = std::fs::read_to_string(single.join("verification.json")).unwrap();
    let json_merged = std::fs::read_to_string(merged.join("verification.json")).unwrap();
    let cases = serde_json::from_str::<serde_json::Value>(&json_single).unwrap();
    assert_eq!(
        cases.as_array().unwrap().len(),
        rows,
        "shards must partition the selection"
    );
    assert_eq!(
        json_without_wall(&json_single),
        json_without_wall(&json_merged)
    );

    let csv_single = std::fs::read_to_string(single.join("verification.csv")).unwrap();
    let csv_merged = std::fs::read_to_string(merged.join("verification.csv")).unwrap();
    assert_eq!(csv_without_wall(&csv_single), csv_without_wall(&csv_merged));
    assert_eq!(
        csv_without_wall(&stdout_single),
        csv_without_wall(&stdout_merged)
    );

    assert!(merged.join("index.html").is_file());
    assert_eq!(plot_names(&single), plot_names(&merged));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn sys_shard_merge_refuses_missing_duplicated_and_foreign_shards() {
    let root = scratch("refuse");
    let all = root.join("all");
    for i in 1..=3 {
        let (code, _, err) = shard_run(&all, "freq-cantilever", &format!("{i}/3"));
        assert!(code == 0 || code == 1, "{err}");
    }
    let part = root.join("part");
    let (code, _, err) = shard_run(&part, "freq-cantilever", "2/3");
    assert!(code == 0 || code == 1, "{err}");
    let foreign = root.join("foreign");
    let (code, _, err) = shard_run(&foreign, "freq-cantilever-fem", "2/3");
    assert!(code == 0 || code == 1, "{err}");
    let out = root.join("out");

    let (code, _, err) = flexverify(&["merge", s(&part), "--out", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("shard(s) 1, 3 of 3 missing"), "{err}");

    let (code, _, err) = flexverify(&["merge", s(&all), s(&part), "--out", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("shard 2/3 appears twice"), "{err}");

    // Shard 2 of another filter in place of the real shard 2.
    std::fs::remove_file(all.join("shard-2-of-3.json")).unwrap();
    let (code, _, err) = flexverify(&["merge", s(&all), s(&foreign), "--out", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("filters differ"), "{err}");

    // A shard file whose rows were edited is not taken as a part of the selection.
    let edited = root.join("edited");
    std::fs::create_dir_all(&edited).unwrap();
    let text = std::fs::read_to_string(part.join("shard-2-of-3.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["outcomes"].as_array_mut().unwrap().pop();
    std::fs::write(edited.join("shard-2-of-3.json"), v.to_string()).unwrap();
    let (code, _, err) = flexverify(&["merge", s(&all), s(&edited), "--out", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not shard 2/3's share"), "{err}");

    let (code, _, err) = flexverify(&["merge", s(&root.join("none")), "--out", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cannot read"), "{err}");
    assert!(!out.join("verification.json").exists());
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn sys_shard_bad_shard_argument_exits_2_with_one_message() {
    let root = scratch("bad");
    for bad in ["0/3", "4/3", "1/0", "0/0", "x/3", "2", "1/2/3", "-1/3"] {
        let (code, out, err) = shard_run(&root, "freq-cantilever", bad);
        assert_eq!(code, 2, "--shard {bad}: {err}");
        assert!(
            err.contains("--shard") && err.contains("expected I/N"),
            "{bad}: {err}"
        );
        assert!(out.is_empty(), "{bad}: {out}");
    }
    let (code, _, err) = flexverify(&["verify", "--filter", "freq-cantilever", "--shard", "1/2"]);
    assert_eq!(code, 2);
    assert!(err.contains("--shard needs --out"), "{err}");
    let _ = std::fs::remove_dir_all(&root);
}

/// `--filter ladder-cantilever-t`: no case, the refinement ladders of `cantilever-tip-mass`
/// and `cantilever-timoshenko` (first frequency, every backend's space ladder; about 4 s each
/// with the timing repeats).
const LADDER_FILTER: &str = "ladder-cantilever-t";

#[test]
fn sys_shard_full_suite_ladders_merge_into_the_single_run() {
    let root = scratch("ladders");
    let single = root.join("single");
    let full = ["verify", "--suite", "full", "--filter", LADDER_FILTER];
    let mut args = full.to_vec();
    args.extend(["--out", s(&single)]);
    let (code, stdout_single, err) = flexverify(&args);
    assert_eq!(code, 0, "{err}");
    let shards: Vec<PathBuf> = (1..=2).map(|i| root.join(format!("s{i}"))).collect();
    for (i, dir) in shards.iter().enumerate() {
        let shard = format!("{}/2", i + 1);
        let mut args = full.to_vec();
        args.extend(["--shard", &shard, "--out", s(dir)]);
        let (code, _, err) = flexverify(&args);
        assert_eq!(code, 0, "{err}");
        let file = std::fs::read_to_string(dir.join(format!("shard-{}-of-2.json", i + 1))).unwrap();
        let v: serde_json::Value = serde_json::from_str(&file).unwrap();
        assert_eq!(v["ladder_selection"].as_array().unwrap().len(), 2);
        assert_eq!(v["ladders"].as_array().unwrap().len(), 1, "shard {shard}");
    }
    let merged = root.join("merged");
    let (code, stdout_merged, err) =
        flexverify(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    assert_eq!(code, 0, "{err}");
    // The survey table (scene, backend, rungs, finest value, order) is printed the same.
    assert!(
        stdout_single.contains("cantilever-timoshenko"),
        "{stdout_single}"
    );
    assert_eq!(stdout_single, stdout_merged);
    for scene in ["cantilever-tip-mass", "cantilever-timoshenko"] {
        let stem = format!("ladders/converge-{scene}-freq1");
        let read = |dir: &Path, ext: &str| {
            std::fs::read_to_string(dir.join(format!("{stem}.{ext}")))
                .unwrap_or_else(|e| panic!("{stem}.{ext} in {}: {e}", dir.display()))
        };
        let json_single = read(&single, "json");
        assert!(json_single.contains("\"counters\""));
        assert_eq!(
            json_without_wall(&json_single),
            json_without_wall(&read(&merged, "json"))
        );
        assert_eq!(
            csv_without(&read(&single, "csv"), &STUDY_TIMING_COLUMNS),
            csv_without(&read(&merged, "csv"), &STUDY_TIMING_COLUMNS)
        );
    }
    assert_eq!(
        plot_names(&single.join("ladders")),
        plot_names(&merged.join("ladders"))
    );
    assert!(merged.join("index.html").is_file());
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn sys_shard_converge_rungs_merge_into_the_single_study() {
    let root = scratch("converge");
    let study = [
        "converge",
        "cantilever",
        "--quantity",
        "freq1",
        "--backend",
        "fem,modal",
    ];
    let single = root.join("single");
    let mut args = study.to_vec();
    args.extend(["--format", "csv", "--out", s(&single)]);
    let (code, stdout_single, err) = flexverify(&args);
    assert_eq!(code, 0, "{err}");
    let parts = root.join("parts");
    for i in 1..=3 {
        let shard = format!("{i}/3");
        let mut args = study.to_vec();
        args.extend(["--shard", &shard, "--out", s(&parts)]);
        let (code, _, err) = flexverify(&args);
        assert_eq!(code, 0, "{err}");
    }
    let merged = root.join("merged");
    let (code, stdout_merged, err) =
        flexverify(&["merge", s(&parts), "--format", "csv", "--out", s(&merged)]);
    assert_eq!(code, 0, "{err}");
    let name = "converge-cantilever-freq1";
    let json_single = std::fs::read_to_string(single.join(format!("{name}.json"))).unwrap();
    let json_merged = std::fs::read_to_string(merged.join(format!("{name}.json"))).unwrap();
    assert!(json_single.contains("\"rungs\""));
    assert_eq!(
        json_without_wall(&json_single),
        json_without_wall(&json_merged)
    );
    assert_eq!(
        csv_without(&stdout_single, &STUDY_TIMING_COLUMNS),
        csv_without(&stdout_merged, &STUDY_TIMING_COLUMNS)
    );

    // A part of another study is refused.
    let other = root.join("other");
    let mut args = vec![
        "converge",
        "cantilever",
        "--quantity",
        "freq2",
        "--backend",
        "fem,modal",
    ];
    args.extend(["--shard", "2/3", "--out", s(&other)]);
    assert_eq!(flexverify(&args).0, 0);
    std::fs::remove_file(parts.join("shard-2-of-3.json")).unwrap();
    let (code, _, err) = flexverify(&["merge", s(&parts), s(&other), "--out", s(&merged)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("quantities differ"), "{err}");
    let _ = std::fs::remove_dir_all(&root);
}
