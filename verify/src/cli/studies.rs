//! `converge` and `recommend`: a refinement study through the library, printed.

use std::path::{Path, PathBuf};

use data::{BackendKind, Settings, load_scene};

use super::CliError;
use super::args::{CommonOpts, checked_settings};
use super::progress::Bar;
use super::stdout::{out, outln};
use crate::output::{Format, TERMINAL_WIDTH, write_atomic};
use crate::progress::Progress;
use crate::shard::{ConvergeShardFile, MeasuredRung, Shard};
use crate::study::ladder::{Refine, rung_specs};
use crate::study::measure::{RungMeasurement, Timed, measure_rung, parse_study_quantity};
use crate::study::summary::Study;
use crate::study::{run, table};
use crate::suite::run_cache::RunCache;

pub fn converge(
    scene: &str,
    quantity: &str,
    refine: Refine,
    opts: &CommonOpts,
) -> Result<(), CliError> {
    let scene = load_scene(scene)?;
    let bar = Bar::new();
    let study = run::converge(
        &scene,
        quantity,
        refine,
        &opts.kinds(),
        &checked_settings(opts, &opts.kinds())?,
        &bar,
    )?;
    bar.clear();
    write_and_print(&study, opts.out.as_deref(), opts.format)
}

fn write_and_print(study: &Study, out: Option<&Path>, format: Format) -> Result<(), CliError> {
    if let Some(dir) = out {
        for n in table::write_study(dir, study)? {
            eprintln!("note: {n}");
        }
        eprintln!("wrote the study and its plots to {}", dir.display());
    }
    match format {
        Format::Json => outln!("{}", table::json(study)),
        Format::Csv => out!("{}", table::csv(study)),
        Format::Wide => out!("{}", table::wide_table(study)),
        Format::Table => out!("{}", table::terminal_table(study, TERMINAL_WIDTH)),
    }
    Ok(())
}

/// `converge --shard I/N`: measures this shard's rungs and writes them for `flexverify merge`.
pub fn converge_shard(
    scene_arg: &str,
    quantity: &str,
    refine: Refine,
    opts: &CommonOpts,
    shard: Shard,
) -> Result<(), CliError> {
    let Some(dir) = &opts.out else {
        return Err(CliError::Input(
            "error: --shard needs --out DIR (where the shard writes its partial result)".into(),
        ));
    };
    let scene = load_scene(scene_arg)?;
    let kinds = opts.kinds();
    let base = checked_settings(opts, &kinds)?;
    let q = parse_study_quantity(&scene, quantity, &base)?;
    let flat: Vec<(BackendKind, usize, Settings)> = rung_specs(&scene, refine, &kinds, &base)
        .into_iter()
        .flat_map(|(kind, spec)| {
            spec.into_iter()
                .enumerate()
                .map(move |(rung, (settings, _, _))| (kind, rung, settings))
        })
        .collect();
    let cache = RunCache::default();
    let bar = Bar::new();
    let mine: Vec<usize> = (0..flat.len()).filter(|&p| shard.owns(p)).collect();
    bar.begin(mine.len(), "rungs");
    let measurements: Vec<MeasuredRung> = mine
        .into_iter()
        .map(|position| {
            let (kind, rung, settings) = &flat[position];
            bar.start(&format!("{} {quantity}: {kind} rung {rung}", scene.name));
            let measurement = measure_rung(&cache, &scene, *kind, settings, &q, Timed::Repeated);
            bar.advance();
            MeasuredRung {
                position,
                backend: *kind,
                rung: *rung,
                measurement,
            }
        })
        .collect();
    bar.finish();
    bar.clear();
    let file = ConvergeShardFile::new(
        scene_arg,
        quantity,
        refine,
        &kinds,
        &base,
        shard,
        flat.len(),
        measurements,
    );
    write_atomic(dir, &shard.file_name(), file.to_json().as_bytes())?;
    eprintln!(
        "wrote shard {shard} ({} of {} rungs) to {}",
        file.measurements.len(),
        flat.len(),
        dir.join(shard.file_name()).display()
    );
    Ok(())
}

/// `flexverify merge` of `converge` parts: the study of one unsharded run.
pub fn merge_converge(
    files: &[(PathBuf, ConvergeShardFile)],
    dirs: &[PathBuf],
    format: Format,
    out: &Path,
) -> Result<(), CliError> {
    let (head, rungs) =
        crate::shard::merge_converge(files).map_err(|e| CliError::Input(format!("error: {e}")))?;
    let scene = load_scene(&head.scene)?;
    let measured = |kind: BackendKind, rung: usize, _: &Settings| -> RungMeasurement {
        rungs
            .get(&(kind, rung))
            .cloned()
            .unwrap_or_else(|| Err(format!("{kind}: rung {rung} missing from the shards")))
    };
    let study = run::converge_from_rungs(
        &scene,
        &head.quantity,
        head.refine,
        &head.backends,
        &head.base,
        &crate::progress::Silent,
        &measured,
    )?;
    std::fs::create_dir_all(out)?;
    write_and_print(&study, Some(out), format)?;
    eprintln!(
        "merged {} converge shards from {} folder(s)",
        head.shard.count,
        dirs.len()
    );
    Ok(())
}

pub fn recommend(
    scene: &str,
    quantity: &str,
    tol: f64,
    refine: Refine,
    rung_budget_s: f64,
    opts: &CommonOpts,
) -> Result<(), CliError> {
    let scene = load_scene(scene)?;
    let bar = Bar::new();
    let recommendation = crate::study::recommend::recommend(
        &scene,
        quantity,
        tol,
        refine,
        &opts.kinds(),
        &checked_settings(opts, &opts.kinds())?,
        Some(rung_budget_s),
        &bar,
    );
    bar.clear();
    let r = recommendation?;
    match opts.format {
        Format::Table => out!("{}", r.terminal_text(TERMINAL_WIDTH)),
        Format::Wide | Format::Csv => out!("{}", r.wide_text()),
        Format::Json => outln!(
            "{}",
            serde_json::to_string_pretty(&r).expect("serializable recommendation")
        ),
    }
    Ok(())
}
