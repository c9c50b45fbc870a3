//! End-to-end tests of the `flexverify` binary: listing, describing, bad input, exit codes.

use std::process::Command;

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

/// Runs flexverify with `args` (ending in `--format json`), requires exit 0 and parses stdout.
fn flexverify_json(args: &[&str]) -> serde_json::Value {
    let (code, out, err) = flexverify(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    serde_json::from_str(&out).unwrap()
}

fn temp_file(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("flexverify-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn cli_scenes_lists_the_whole_catalog() {
    let (code, out, _) = flexverify(&["scenes"]);
    assert_eq!(code, 0);
    for name in data::catalog_names() {
        assert!(
            out.lines().any(|l| l.starts_with(name)),
            "{name} missing:\n{out}"
        );
    }
}

#[test]
fn cli_describe_barhorst_case1_shows_its_physics() {
    let (code, out, err) = flexverify(&["describe", "barhorst-case1"]);
    assert_eq!(code, 0, "{err}");
    let state = |flag: &str| {
        out.lines()
            .find(|l| l.split_whitespace().next() == Some(flag))
            .and_then(|l| l.split_whitespace().nth(1))
            .unwrap_or_else(|| panic!("no `{flag}` line:\n{out}"))
            .to_string()
    };
    assert_eq!(state("gravity"), "on");
    assert_eq!(state("contact"), "on");
    assert_eq!(state("kelvin_voigt"), "on");
    assert_eq!(state("axial"), "off");
    assert_eq!(state("shear"), "off");
}

#[test]
fn cli_bad_scene_files_exit_2_with_location() {
    let good = include_str!("../../data/scenes/single-link.toml");
    let cases = [
        (
            "unknown-key",
            good.replace("tip_mass = 0.5", "tip_mass = 0.5\ntip_mas = 1.0"),
            "tip_mas",
        ),
        (
            "negative",
            good.replace("length = 1.0", "length = -2.0"),
            "link[0].length",
        ),
        (
            "nan",
            good.replace("bending_stiffness = 10.0", "bending_stiffness = nan"),
            "link[0].bending_stiffness",
        ),
        (
            "syntax",
            good.replace("[simulation]", "[simulation"),
            "malformed TOML",
        ),
        (
            "contradiction",
            good.replace(
                "tip_mass = 0.5",
                "tip_mass = 0.5\naxial = true\nforeshortening = true\naxial_stiffness = 1.0",
            ),
            "contradictory",
        ),
    ];
    for (name, text, needle) in cases {
        let p = temp_file(&format!("{name}.toml"), &text);
        let (code, _, err) = flexverify(&["describe", p.to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.toml:")),
            "{name}: no file:line in {err}"
        );
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}

#[test]
fn cli_missing_scene_and_bad_numbers_exit_2() {
    let (code, _, err) = flexverify(&["run", "no-such-scene"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("flexverify scenes"));
    for bad in ["-1", "0", "nan", "inf", "abc"] {
        let (code, _, err) = flexverify(&["run", "spin-up", "--dt", bad]);
        assert_eq!(code, 2, "--dt {bad}: {err}");
        assert!(err.contains("--dt"), "{err}");
    }
    let (code, _, _) = flexverify(&["run", "spin-up", "--elements", "0"]);
    assert_eq!(code, 2);
}

#[test]
fn cli_unsupported_requests_exit_3_without_results() {
    // The modal backend has no statics of the free-free rocket.
    let (code, out, err) = flexverify(&[
        "statics",
        "rocket",
        "--backend",
        "modal",
        "--format",
        "json",
    ]);
    assert_eq!(code, 3, "{out}{err}");
    assert!(err.contains("unsupported"), "{err}");
    assert!(out.trim().is_empty(), "a fake result was printed: {out}");
}

#[test]
fn cli_converge_cantilever_reports_the_orders_of_each_method() {
    let study = flexverify_json(&[
        "converge",
        "cantilever",
        "--quantity",
        "freq1",
        "--format",
        "json",
    ]);
    assert!(
        study["reference_label"]
            .as_str()
            .unwrap()
            .contains("analytic:clamped-free")
    );
    let ladder = |b: &str| {
        study["ladders"]
            .as_array()
            .unwrap()
            .iter()
            .find(|l| l["backend"] == b)
            .unwrap_or_else(|| panic!("no {b} ladder"))
            .clone()
    };
    let order = |b: &str| ladder(b)["observed_order"].as_f64().unwrap();
    assert!(
        (order("fem") - 4.0).abs() < 0.3,
        "fem order {}",
        order("fem")
    );
    assert!(
        (order("fdm") - 2.0).abs() < 0.2,
        "fdm order {}",
        order("fdm")
    );
    assert_eq!(ladder("modal")["monotone_from_above"], true);
    // Every rung carries a measured (positive) wall time for the work-precision diagram.
    for b in ["fem", "fdm", "modal"] {
        for r in ladder(b)["rungs"].as_array().unwrap() {
            assert!(r["wall_time_s"].as_f64().unwrap() > 0.0);
        }
    }
}

#[test]
fn cli_converge_space_time_refines_elements_and_step_together() {
    let study = flexverify_json(&[
        "converge",
        "cantilever",
        "--quantity",
        "tip_deflection@0.01",
        "--backend",
        "fem",
        "--refine",
        "space-time",
        "--format",
        "json",
    ]);
    assert_eq!(study["refine"], "space-time");
    let rungs = study["ladders"][0]["rungs"].as_array().unwrap();
    assert!(rungs.len() >= 4);
    // Each rung doubles the elements and halves the step (labels `elements=N dt=…`).
    let parse = |r: &serde_json::Value| -> (f64, f64, f64) {
        let label = r["discretization"].as_str().unwrap();
        let field = |key: &str| -> f64 {
            let rest = &label[label.find(key).unwrap() + key.len()..];
            rest.split_whitespace().next().unwrap().parse().unwrap()
        };
        (
            field("elements="),
            field("dt="),
            r["value"].as_f64().unwrap(),
        )
    };
    let rows: Vec<(f64, f64, f64)> = rungs.iter().map(parse).collect();
    for w in rows.windows(2) {
        assert_eq!(w[1].0, 2.0 * w[0].0);
        assert!((w[1].1 - 0.5 * w[0].1).abs() <= 1e-3 * w[1].1, "{w:?}");
    }
    // Both errors fall: the last difference is a small fraction of the first.
    let first = (rows[1].2 - rows[0].2).abs();
    let last = (rows[rows.len() - 1].2 - rows[rows.len() - 2].2).abs();
    assert!(last < 1e-2 * first, "differences {first:.3e} … {last:.3e}");
}

#[test]
fn cli_recommend_names_a_discretization_that_a_rerun_confirms() {
    // In space (the backends' ladders) and in time (fem's step at the mesh given, which the
    // re-run must keep): the re-run reproduces the recommended value.
    let time_refined = ["--refine", "time", "--backend", "fem", "--elements", "4"];
    for extra in [&[][..], &time_refined[..]] {
        let mut args = vec![
            "recommend",
            "spin-up",
            "--quantity",
            "tip_deflection@15",
            "--tol",
            "1e-3",
        ];
        args.extend(extra);
        let (code, out, err) = flexverify(&args);
        assert_eq!(code, 0, "{err}");
        let line = out
            .lines()
            .find(|l| l.starts_with("re-run: flexverify "))
            .expect(&out);
        if !extra.is_empty() {
            assert!(
                line.contains(" --elements 4 ") && line.contains(" --dt "),
                "{line}"
            );
        }
        let value: f64 = out
            .split("value ")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .and_then(|s| s.trim().parse().ok())
            .expect(&out);
        let mut args: Vec<&str> = line
            .trim_start_matches("re-run: flexverify ")
            .split_whitespace()
            .collect();
        args.extend(["--format", "json"]);
        let (code, rerun, err) = flexverify(&args);
        assert_eq!(code, 0, "{err}");
        let runs: serde_json::Value = serde_json::from_str(&rerun).unwrap();
        let channel = runs[0]["observables"]["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == "link1.tip_deflection")
            .unwrap()
            .clone();
        let last = channel["values"]
            .as_array()
            .unwrap()
            .last()
            .unwrap()
            .as_f64()
            .unwrap();
        // The recommendation prints 11 significant digits; the re-run is bit-identical.
        assert!(
            (last - value).abs() <= 1e-10 * value.abs(),
            "{line}: {last} vs {value}"
        );
    }
    // And an impossible tolerance is refused with the best error found; a rung budget every
    // run exceeds stops the ladder after its first rung, and says so.
    for budget in [None, Some("1e-9")] {
        let mut args = vec![
            "recommend",
            "cantilever",
            "--quantity",
            "freq1",
            "--tol",
            "1e-30",
            "--backend",
            "fdm",
        ];
        args.extend(budget.iter().flat_map(|b| ["--rung-budget", *b]));
        let (code, _, err) = flexverify(&args);
        assert_eq!(code, 1);
        assert!(err.contains("no measured discretization meets"), "{err}");
        let capped = "finer rungs were not measured (fdm ladder capped after stations=11";
        assert_eq!(err.contains(capped), budget.is_some(), "{err}");
    }
}

#[test]
fn cross_recommend_refuses_when_the_backends_converge_apart() {
    // At the output interval as time step (the scene's coarsest fixed step), fem's space
    // ladder converges to its O(h²) time-discretization answer while modal's adaptive
    // integration does not share that error: the two limits differ by far more than either
    // ladder's own error estimate, so neither may be scored against the other.
    let scene = data::load_scene("spin-up").unwrap();
    let dt = scene.simulation.output_interval.to_string();
    let (code, out, err) = flexverify(&[
        "recommend",
        "spin-up",
        "--quantity",
        "tip_deflection@15",
        "--tol",
        "1e-6",
        "--backend",
        "fem,modal",
        "--dt",
        &dt,
    ]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the models disagree"), "{err}");
    assert!(
        err.contains("fem converges to") && err.contains("modal to"),
        "{err}"
    );
    assert!(!out.contains("recommended:"), "{out}");
    // `converge` reports the same two limits and scores each ladder against its own.
    let (code, out, err) = flexverify(&[
        "converge",
        "spin-up",
        "--quantity",
        "tip_deflection@15",
        "--backend",
        "fem,modal",
        "--dt",
        &dt,
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let study: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(study["reference"].is_null(), "{out}");
    let d = &study["disagreement"];
    assert_eq!(d["first"]["backend"], "fem");
    assert_eq!(d["second"]["backend"], "modal");
    assert!(d["relative_difference"].as_f64().unwrap() > 1e-6);
}

#[test]
fn cli_run_contact_scene_writes_the_switching_history() {
    let dir = std::env::temp_dir().join(format!("flexverify-cli-switch-{}", std::process::id()));
    let (code, out, err) = flexverify(&[
        "run",
        "barhorst-case1-tipmass",
        "--backend",
        "modal",
        "--modes",
        "2",
        "--t-end",
        "0.6",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("switching events"), "{out}");
    let csv = std::fs::read_to_string(dir.join("barhorst-case1-tipmass-modal-switching.csv"))
        .expect("switching history written");
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(
        rows.iter().any(|r| r.split(',').nth(1) == Some("impact")),
        "no impact row:\n{csv}"
    );
    // Rows are in time order.
    let times: Vec<f64> = rows
        .iter()
        .map(|r| r.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{csv}");
    let obs =
        std::fs::read_to_string(dir.join("barhorst-case1-tipmass-modal-observables.csv")).unwrap();
    assert!(obs.lines().next().unwrap().contains("contact1.phase"));
}

#[test]
fn cli_default_outputs_fit_120_columns() {
    let commands: [&[&str]; 10] = [
        &["verify", "--filter", "cantilever"],
        &["scenes"],
        &["describe", "constrained-arm"],
        &["modes", "cantilever"],
        &["run", "spin-up"],
        &[
            "run",
            "barhorst-case1-tipmass",
            "--backend",
            "modal",
            "--modes",
            "2",
            "--t-end",
            "0.6",
        ],
        &["converge", "cantilever", "--quantity", "freq1"],
        &[
            "recommend",
            "cantilever",
            "--quantity",
            "freq1",
            "--tol",
            "1e-6",
        ],
        &["stability"],
        &["coverage"],
    ];
    for args in commands {
        let (code, out, err) = flexverify(args);
        assert_eq!(code, 0, "{args:?}: {err}");
        assert!(!out.trim().is_empty(), "{args:?}: no output");
        for line in out.lines() {
            assert!(
                line.chars().count() <= 120,
                "{args:?}: {} characters:\n{line}",
                line.chars().count()
            );
        }
    }
    // `--format wide` keeps every column at full width (the check kind, scene, reference …).
    let (code, wide, _) = flexverify(&["verify", "--filter", "cantilever", "--format", "wide"]);
    assert_eq!(code, 0);
    assert!(wide.lines().any(|l| l.contains("analytic:clamped-free")));
    assert!(wide.lines().any(|l| l.chars().count() > 120), "{wide}");
}

#[test]
fn cli_closed_output_pipe_ends_quietly_with_the_sigpipe_status() {
    use std::process::Stdio;
    // The reader is gone before anything is written, as in `flexverify scenes | head -0`:
    // closed before the child starts, so the outcome does not depend on scheduling.
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let child = Command::new(env!("CARGO_BIN_EXE_flexverify"))
        .arg("scenes")
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .spawn()
        .expect("run flexverify");
    let out = child.wait_with_output().expect("wait for flexverify");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{err}");
    assert!(err.is_empty(), "nothing on stderr, got:\n{err}");
}

#[test]
fn cli_flag_no_requested_backend_reads_exits_2_naming_flag_and_readers() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["run", "cantilever", "--backend", "fem", "--basis", "poly"],
            "`--basis` applies to modal; the requested backend fem does not read it",
        ),
        (
            &[
                "modes",
                "cantilever",
                "--backend",
                "modal",
                "--elements",
                "8",
            ],
            "`--elements` applies to fem; the requested backend modal does not read it",
        ),
        (
            &[
                "statics",
                "cantilever",
                "--backend",
                "fem,fdm",
                "--modes",
                "4",
            ],
            "`--modes` applies to modal; the requested backends fem, fdm do not read it",
        ),
        (
            &["run", "cantilever", "--backend", "fdm", "--rtol", "1e-6"],
            "`--rtol` applies to fem, modal and reference; the requested backend fdm does not \
             read it",
        ),
        (
            &[
                "describe",
                "cantilever",
                "--backend",
                "modal",
                "--safety-factor",
                "0.5",
            ],
            "`--safety-factor` applies to fem and fdm; the requested backend modal does not \
             read it",
        ),
        (
            &[
                "converge",
                "cantilever",
                "--quantity",
                "freq1",
                "--backend",
                "fem",
                "--stations",
                "11",
            ],
            "`--stations` applies to fdm; the requested backend fem does not read it",
        ),
    ];
    let method_cases: [(&[&str], &str); 2] = [
        (
            &[
                "run",
                "cantilever",
                "--backend",
                "fem",
                "--method",
                "dopri5",
            ],
            "`--method dopri5` applies to modal; the requested backend fem does not implement \
             it; fem offers energy-midpoint, generalized-alpha, central-difference, \
             implicit-midpoint, bathe",
        ),
        (
            &[
                "run",
                "spin-up",
                "--backend",
                "fem,modal",
                "--method",
                "velocity-form",
            ],
            "`--method velocity-form` applies to fdm; the requested backends fem, modal do not \
             implement it; fem offers",
        ),
    ];
    for (args, message) in cases.into_iter().chain(method_cases) {
        let (code, out, err) = flexverify(args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert!(err.contains(message), "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: {out}");
    }
}

#[test]
fn cli_flags_for_several_backends_reach_only_the_backends_that_read_them() {
    let freqs = |args: &[&str]| -> Vec<serde_json::Value> {
        let mut all = vec!["modes", "cantilever", "--count", "2", "--format", "json"];
        all.extend_from_slice(args);
        let v = flexverify_json(&all);
        v.as_array().unwrap().clone()
    };
    let both = freqs(&["--backend", "fem,modal", "--modes", "3", "--elements", "4"]);
    let fem = freqs(&["--backend", "fem", "--elements", "4"]);
    let modal = freqs(&["--backend", "modal", "--modes", "3"]);
    assert_eq!(both.len(), 2);
    assert_eq!(both[0]["frequencies_hz"].as_array().map(Vec::len), Some(2));
    assert_eq!(
        both[0]["frequencies_hz"], fem[0]["frequencies_hz"],
        "fem with --modes set for modal"
    );
    assert_eq!(
        both[1]["frequencies_hz"], modal[0]["frequencies_hz"],
        "modal with --elements set for fem"
    );
}

#[test]
fn cli_a_study_refuses_a_time_after_the_runs_end_before_running() {
    // `rocket` ends at 0.1 s: every rung would fail alike, so the quantity is refused as bad
    // input (exit 2) naming the end and the flag that moves it, for converge and recommend,
    // and with --t-end the refusal names that end instead.
    for (args, names) in [
        (
            &[
                "converge",
                "rocket",
                "--quantity",
                "rocket.vY@0.2",
                "--backend",
                "fdm",
            ][..],
            "0.1 s (the scene's t_end)",
        ),
        (
            &[
                "recommend",
                "rocket",
                "--quantity",
                "rocket.vY@0.2",
                "--tol",
                "1e-3",
                "--backend",
                "fdm",
                "--t-end",
                "0.15",
            ][..],
            "0.15 s (--t-end)",
        ),
    ] {
        let (code, out, err) = flexverify(args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert!(err.contains(names) && err.contains("--t-end 0.2"), "{err}");
    }
}

/// A fresh folder for one test's run outputs.
fn out_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("flexverify-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// `flexverify run SCENE ARGS… --out DIR`, which must succeed.
fn run_into(dir: &std::path::Path, scene: &str, args: &[&str]) {
    let mut all = vec!["run", scene];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--format", "json", "--out", dir.to_str().unwrap()]);
    let (code, _, err) = flexverify(&all);
    assert_eq!(code, 0, "{all:?}: {err}");
}

#[test]
fn cli_compare_histories_of_two_steps_and_of_a_run_with_itself() {
    let (coarse, fine) = (out_dir("compare-coarse"), out_dir("compare-fine"));
    run_into(
        &coarse,
        "single-link",
        &["--backend", "fem", "--t-end", "0.05", "--dt", "1e-3"],
    );
    run_into(
        &fine,
        "single-link",
        &["--backend", "fem", "--t-end", "0.05", "--dt", "5e-4"],
    );
    let result: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(coarse.join("single-link-fem.json")).unwrap(),
    )
    .unwrap();
    let channels: Vec<&str> = result["observables"]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();

    let c = flexverify_json(&[
        "compare",
        coarse.to_str().unwrap(),
        fine.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let rows = c["histories"].as_array().unwrap();
    let names: Vec<&str> = rows
        .iter()
        .map(|h| h["channel"].as_str().unwrap())
        .collect();
    assert_eq!(names, channels, "one history per channel");
    for h in rows {
        let d = h["max_abs_diff"].as_f64().unwrap();
        assert!(d.is_finite() && d >= 0.0, "{h}");
    }
    assert!(
        rows.iter()
            .any(|h| h["max_abs_diff"].as_f64().unwrap() > 0.0),
        "halving the step changed nothing: {c}"
    );
    assert!(c["episodes"].is_null(), "single-link has no contact: {c}");
    assert_eq!(c["run"]["settings"]["time"]["dt"].as_f64(), Some(1e-3));

    // The result file named directly, against its own folder.
    let same = flexverify_json(&[
        "compare",
        coarse.join("single-link-fem.json").to_str().unwrap(),
        coarse.to_str().unwrap(),
        "--format",
        "json",
    ]);
    for h in same["histories"].as_array().unwrap() {
        assert_eq!(h["max_abs_diff"].as_f64(), Some(0.0), "{h}");
    }
    let (code, csv, err) = flexverify(&[
        "compare",
        coarse.to_str().unwrap(),
        fine.to_str().unwrap(),
        "--format",
        "csv",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        csv.lines().next(),
        Some("kind,name,run,reference,abs_diff,relative")
    );
    assert_eq!(
        csv.lines().filter(|l| l.starts_with("history,")).count(),
        channels.len()
    );
    for dir in [coarse, fine] {
        std::fs::remove_dir_all(dir).unwrap();
    }
}

#[test]
fn cli_compare_contact_episodes_of_two_backends_and_of_a_run_with_itself() {
    let (fem, modal) = (out_dir("compare-fem"), out_dir("compare-modal"));
    run_into(
        &fem,
        "barhorst-case1",
        &["--backend", "fem", "--elements", "4", "--t-end", "0.35"],
    );
    run_into(
        &modal,
        "barhorst-case1",
        &["--backend", "modal", "--t-end", "0.35"],
    );
    let (fem, modal) = (fem.to_str().unwrap(), modal.to_str().unwrap());
    let cross = flexverify_json(&["compare", fem, modal, "--format", "json"]);
    let episodes = &cross["episodes"];
    assert!(
        episodes.is_object(),
        "a contact scene has episodes: {cross}"
    );
    assert!(!episodes["run"].as_array().unwrap().is_empty(), "{cross}");
    assert_eq!(
        (
            cross["run"]["backend"].as_str(),
            cross["reference"]["backend"].as_str()
        ),
        (Some("fem"), Some("modal"))
    );

    let same = flexverify_json(&["compare", fem, fem, "--format", "json"]);
    let episodes = &same["episodes"];
    assert!(!episodes["pairs"].as_array().unwrap().is_empty(), "{same}");
    assert_eq!(
        episodes["largest"]["abs_diff"].as_f64(),
        Some(0.0),
        "{same}"
    );

    // The default table: the episodes section, the largest difference, 120 columns.
    let (code, out, err) = flexverify(&["compare", fem, modal]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("contact episodes"), "{out}");
    assert!(
        out.contains("largest boundary difference") || out.contains("not paired"),
        "{out}"
    );
    for line in out
        .lines()
        .filter(|l| !l.contains(fem) && !l.contains(modal))
    {
        assert!(line.chars().count() <= 120, "{line}");
    }
    for dir in [fem, modal] {
        std::fs::remove_dir_all(dir).unwrap();
    }
}

#[test]
fn cli_compare_bad_input_exits_2_with_one_clear_message() {
    let (pair, other) = (out_dir("compare-pair"), out_dir("compare-other"));
    run_into(
        &pair,
        "single-link",
        &["--backend", "fem,modal", "--t-end", "0.02"],
    );
    run_into(&other, "spin-up", &["--backend", "fem", "--t-end", "0.02"]);
    let fem = pair.join("single-link-fem.json");
    let missing = pair.join("no-such-run.json");
    let (pair_s, other_s) = (pair.to_str().unwrap(), other.to_str().unwrap());
    let (fem_s, missing_s) = (fem.to_str().unwrap(), missing.to_str().unwrap());
    let cases: [(&[&str], &[&str]); 5] = [
        (&["compare", missing_s, fem_s], &[missing_s]),
        (
            &["compare", pair_s, fem_s],
            &["single-link-fem.json", "single-link-modal.json", "name one"],
        ),
        (
            &["compare", fem_s, other_s],
            &["`single-link`", "`spin-up`"],
        ),
        (
            &["compare", fem_s, fem_s, "--min-flight", "0"],
            &["--min-flight"],
        ),
        (
            &["compare", fem_s, fem_s, "--channel", "nope"],
            &["`nope`", "joint1.angle"],
        ),
    ];
    for (args, needles) in cases {
        let (code, out, err) = flexverify(args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        for needle in needles {
            assert!(err.contains(needle), "{args:?}: no `{needle}` in {err}");
        }
    }
    for dir in [pair, other] {
        std::fs::remove_dir_all(dir).unwrap();
    }
}

#[test]
fn cli_output_interval_sets_every_backends_samples_and_refuses_a_bad_value() {
    let dir = out_dir("output-interval");
    run_into(
        &dir,
        "single-link",
        &["--t-end", "0.02", "--output-interval", "0.005"],
    );
    for backend in ["fem", "fdm", "modal"] {
        let file = dir.join(format!("single-link-{backend}.json"));
        let result: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let times: Vec<f64> = result["observables"]["time"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t.as_f64().unwrap())
            .collect();
        let expected = [0.0, 0.005, 0.01, 0.015, 0.02];
        assert_eq!(times.len(), expected.len(), "{backend}: {times:?}");
        for (t, e) in times.iter().zip(expected) {
            assert!((t - e).abs() < 1e-12, "{backend}: {times:?}");
        }
        assert_eq!(
            result["settings"]["time"]["output_interval"], 0.005,
            "{backend}"
        );
    }
    let (code, _, err) = flexverify(&["run", "single-link", "--output-interval", "0"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--output-interval"), "{err}");
    let (code, _, err) = flexverify(&[
        "run",
        "single-link",
        "--backend",
        "fem",
        "--output-interval",
        "1e-9",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("time.output_interval") && err.contains("above the limit"),
        "{err}"
    );
    // An end time whose samples the scene's spacing cannot store is refused before running.
    let (code, _, err) = flexverify(&["run", "single-link", "--backend", "fem", "--t-end", "1e9"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("time.t_end") && err.contains("above the limit"),
        "{err}"
    );
}
