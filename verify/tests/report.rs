//! The HTML report of `verify --out` and of `merge --out`: every page exists, and every
//! relative link and image of every page points at a file (and anchor) that exists.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Cheap and varied: the cantilever's frequency, static, history and order cases (26 quick
/// rows, three of them ladders with work–precision and a two-backend Pareto front).
const FILTER: &str = "cantilever";

fn flexverify(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_flexverify"))
        .args(args)
        .output()
        .expect("run flexverify");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flexverify-report-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The values of `attr="…"` in an HTML text.
fn attributes(html: &str, attr: &str) -> Vec<String> {
    let key = format!("{attr}=\"");
    html.match_indices(&key)
        .map(|(i, _)| {
            let rest = &html[i + key.len()..];
            rest[..rest.find('"').expect("closing quote")].replace("&amp;", "&")
        })
        .collect()
}

/// Checks every page of a report: the pages and ids it links exist; returns the pages.
fn check_links(dir: &Path) -> BTreeSet<String> {
    let pages: BTreeMap<String, String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".html"))
        .map(|n| {
            let text = std::fs::read_to_string(dir.join(&n)).unwrap();
            (n, text)
        })
        .collect();
    assert!(pages.contains_key("index.html"), "no index.html in {dir:?}");
    let ids =
        |page: &str| -> BTreeSet<String> { attributes(&pages[page], "id").into_iter().collect() };
    let mut checked = 0;
    for (name, html) in &pages {
        for link in attributes(html, "href")
            .into_iter()
            .chain(attributes(html, "src"))
        {
            assert!(
                !link.contains("://") && !link.starts_with('/'),
                "{name}: link {link} is not relative"
            );
            let (file, anchor) = link.split_once('#').unwrap_or((&link, ""));
            let target = if file.is_empty() { name.as_str() } else { file };
            assert!(
                dir.join(target).is_file(),
                "{name}: {link} points at no file"
            );
            if !anchor.is_empty() {
                assert!(
                    pages.contains_key(target) && ids(target).contains(anchor),
                    "{name}: {link}: no id {anchor} in {target}"
                );
            }
            checked += 1;
        }
        assert!(html.contains("</html>"), "{name} is not a whole page");
    }
    assert!(checked > 0);
    pages.into_keys().collect()
}

#[test]
fn sys_report_every_page_link_and_image_exists() {
    let dir = scratch("single");
    let (code, err) = flexverify(&["verify", "--filter", FILTER, "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let pages = check_links(&dir);
    // One page per scene of the rows, and the index links each of them.
    let json = std::fs::read_to_string(dir.join("verification.json")).unwrap();
    let rows: Vec<serde_json::Value> = serde_json::from_str(&json).unwrap();
    let scenes: BTreeSet<String> = rows
        .iter()
        .map(|r| r["scene"].as_str().unwrap().to_string())
        .collect();
    let index = std::fs::read_to_string(dir.join("index.html")).unwrap();
    for s in &scenes {
        let page = format!("scene-{s}.html");
        assert!(pages.contains(&page), "no page for scene {s}");
        assert!(
            index.contains(&format!("href=\"{page}\"")),
            "index does not link {page}"
        );
    }
    assert_eq!(pages.len(), scenes.len() + 1, "{pages:?}");
    // The summary tables and the coverage matrix are on the index.
    for heading in ["By check kind", "By scene", "Coverage", "Work–precision"] {
        assert!(index.contains(heading), "index lacks {heading}");
    }
    // The order cases' ladders give a Pareto front of the cantilever's first frequency across
    // fem and fdm, drawn and shown on the scene page.
    let scene = std::fs::read_to_string(dir.join("scene-cantilever.html")).unwrap();
    assert!(scene.contains("src=\"pareto-cantilever-freq1.svg\""));
    let svg = std::fs::read_to_string(dir.join("pareto-cantilever-freq1.svg")).unwrap();
    for legend in ["fem", "fdm", "Pareto front"] {
        assert!(
            svg.lines().any(|l| l.trim() == legend),
            "front lacks legend {legend}"
        );
    }
}

#[test]
fn sys_report_merged_from_shards_has_the_same_pages_and_links() {
    let filter = "order-cantilever";
    let single = scratch("merge-single");
    let (code, err) = flexverify(&[
        "verify",
        "--filter",
        filter,
        "--out",
        single.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let parts: Vec<PathBuf> = (1..=2).map(|i| scratch(&format!("part{i}"))).collect();
    for (i, part) in parts.iter().enumerate() {
        let shard = format!("{}/2", i + 1);
        let (code, err) = flexverify(&[
            "verify",
            "--filter",
            filter,
            "--shard",
            &shard,
            "--out",
            part.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
    }
    let merged = scratch("merged");
    let (code, err) = flexverify(&[
        "merge",
        parts[0].to_str().unwrap(),
        parts[1].to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(check_links(&merged), check_links(&single));
    let files = |d: &Path| -> BTreeSet<String> {
        std::fs::read_dir(d)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".svg") || n.ends_with(".html"))
            .collect()
    };
    assert_eq!(files(&merged), files(&single));
}

/// A report with failures, one of them a row without plots: the index lists them first and
/// links each to its line on the scene page, which lists them under its summary. The failing
/// rows are made by editing a one-shard result (the catalog has no failing row to run) and
/// merged, which is how the report of a real failing run is written too.
#[test]
fn sys_report_failures_link_to_their_rows_and_plots() {
    let root = scratch("failures");
    let part = root.join("part");
    let (code, err) = flexverify(&[
        "verify",
        "--filter",
        "cantilever-modal",
        "--shard",
        "1/1",
        "--out",
        part.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let file = part.join("shard-1-of-1.json");
    let mut shard: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let mut failed = Vec::new();
    for row in shard["outcomes"].as_array_mut().unwrap() {
        let id = row["id"].as_str().unwrap().to_string();
        // A frequency row (no plots) and a history row (plots).
        if id == "freq-cantilever-modal-cf6-mode2" || id == "hist-cantilever-modal-fem-tip-y" {
            row["status"] = "fail".into();
            row["tolerance"] = (row["error"].as_f64().unwrap() / 2.0).into();
            row["message"] = "error exceeds tolerance (edited for the test)".into();
            failed.push(id);
        }
    }
    assert_eq!(failed.len(), 2, "rows not found: {failed:?}");
    std::fs::write(&file, shard.to_string()).unwrap();
    let report = root.join("report");
    let (code, err) = flexverify(&[
        "merge",
        part.to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    check_links(&report);
    let index = std::fs::read_to_string(report.join("index.html")).unwrap();
    let scene = std::fs::read_to_string(report.join("scene-cantilever.html")).unwrap();
    let failures =
        &index[index.find("id=\"failures\"").unwrap()..index.find("id=\"kinds\"").unwrap()];
    for id in &failed {
        let line = format!("scene-cantilever.html#line-{id}");
        assert!(failures.contains(&line), "the index does not link {line}");
        let summary = &scene[..scene.find("id=\"rows\"").unwrap()];
        assert!(
            summary.contains(&format!("href=\"#line-{id}\"")),
            "the scene page's summary does not list {id}"
        );
    }
    // The history row's plot is linked from the failures table by what it shows.
    assert!(
        failures.contains("href=\"case-hist-cantilever-modal-fem-tip-y.svg\""),
        "{failures}"
    );
    assert!(failures.contains(">histories</a>"), "{failures}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn sys_report_work_of_a_zero_limit_reads_back_with_absolute_errors() {
    // The impulse excess tends to 0 (the tip-mass momentum limit): its work–precision errors
    // are absolute and finite, so the work file reads back (merge and the scene fronts use it).
    let dir = scratch("zero-limit");
    let (code, err) = flexverify(&[
        "verify",
        "--filter",
        "limit-impulse-tipmass-fem",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("note:"), "{err}");
    let (works, notes) = verify::work::read_all(&dir);
    assert!(notes.is_empty(), "{notes:?}");
    let work = works
        .iter()
        .find(|w| w.case == "limit-impulse-tipmass-fem")
        .expect("the case's work file");
    assert!(
        work.reference_label.contains("absolute error"),
        "{}",
        work.reference_label
    );
    for p in &work.points {
        assert!(p.error.is_finite(), "{p:?}");
        assert_eq!(p.error, p.value.abs(), "{p:?}");
    }
}
