//! One function per subcommand.

use data::{BackendError, BackendKind, Model, Scene, Settings, StabilityVerdict, load_scene};

use super::CliError;
use super::args::{Cli, Command, CommonOpts, checked_settings};
use super::stdout::{out, outln, print_json};
use crate::output::{
    Column, Format, SWITCHING_HEADER, TERMINAL_WIDTH, csv_table, fitted_table, ledger_csv,
    observables_csv, switching_rows, text_table, wrap, write_atomic,
};
use crate::registry::backend;

pub fn dispatch(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Scenes { format } => scenes(format),
        Command::Describe { scene, opts } => describe(&scene, &opts),
        Command::Modes { scene, count, opts } => modes(&scene, count as usize, &opts),
        Command::Statics { scene, opts } => statics(&scene, &opts),
        Command::Run { scene, opts } => run(&scene, &opts),
        Command::Compare {
            run,
            reference,
            min_flight,
            channel,
            lowpass,
            format,
        } => {
            let opts = crate::compare::CompareOptions {
                min_flight,
                channels: channel,
                lowpass_hz: lowpass,
            };
            super::compare::compare(&run, &reference, &opts, format)
        }
        Command::Verify {
            suite,
            filter,
            format,
            out,
            shard,
        } => match shard {
            None => super::checks::verify(suite, filter.as_deref(), format, out.as_deref()),
            Some(shard) => {
                super::checks::verify_shard(suite, filter.as_deref(), format, out.as_deref(), shard)
            }
        },
        Command::Merge { dirs, format, out } => super::checks::merge(&dirs, format, &out),
        Command::Converge {
            scene,
            quantity,
            refine,
            shard,
            opts,
        } => match shard {
            None => super::studies::converge(&scene, &quantity, refine, &opts),
            Some(shard) => super::studies::converge_shard(&scene, &quantity, refine, &opts, shard),
        },
        Command::Recommend {
            scene,
            quantity,
            tol,
            refine,
            rung_budget,
            opts,
        } => super::studies::recommend(&scene, &quantity, tol, refine, rung_budget, &opts),
        Command::Coverage { format } => super::checks::coverage(format),
        Command::Stability {
            suite,
            filter,
            format,
            out,
        } => super::checks::stability(suite, filter.as_deref(), format, out.as_deref()),
    }
}

/// Ledger closure above which `run` warns that the answer is not time-converged: an
/// integrator at a sensible step closes the ledger to 1e-4 or better on every catalog scene.
const LEDGER_WARNING: f64 = 1e-3;

fn scenes(format: Format) -> Result<(), CliError> {
    let mut rows = Vec::new();
    for name in data::catalog_names() {
        let scene = load_scene(name)?;
        rows.push(vec![
            name.to_string(),
            scene.family().to_string(),
            scene.description.clone(),
        ]);
    }
    let header = ["scene", "family", "description"];
    match format {
        Format::Table => {
            // Left-aligned listing reads better than the right-aligned numeric table; long
            // descriptions are cut to the terminal width.
            let columns = [
                Column::left(""),
                Column::left(""),
                Column::left("").elastic(),
            ];
            for line in fitted_table(&columns, &rows, TERMINAL_WIDTH).rows {
                outln!("{line}");
            }
        }
        Format::Wide => {
            let w0 = rows.iter().map(|r| r[0].len()).max().unwrap_or(5);
            let w1 = rows.iter().map(|r| r[1].len()).max().unwrap_or(6);
            for r in &rows {
                outln!("{:<w0$}  {:<w1$}  {}", r[0], r[1], r[2]);
            }
        }
        Format::Csv => out!("{}", csv_table(&header, &rows)),
        Format::Json => {
            let v: Vec<_> = rows
                .iter()
                .map(|r| serde_json::json!({"scene": r[0], "family": r[1], "description": r[2]}))
                .collect();
            print_json(&v)?;
        }
    }
    Ok(())
}

#[derive(serde::Serialize)]
struct BackendPlan {
    backend: BackendKind,
    dofs: Option<usize>,
    plan: Option<data::DofPlan>,
    unsupported: Option<String>,
}

fn describe(name: &str, opts: &CommonOpts) -> Result<(), CliError> {
    let scene = load_scene(name)?;
    let kinds = opts.kinds_for(&scene);
    let settings = checked_settings(opts, &kinds)?;
    let mut plans = Vec::new();
    for kind in kinds {
        match backend(kind).dof_plan(&scene, &settings.for_backend(kind).discretization) {
            Ok(plan) => plans.push(BackendPlan {
                backend: kind,
                dofs: Some(plan.total()),
                plan: Some(plan),
                unsupported: None,
            }),
            Err(e @ (BackendError::Unsupported(_) | BackendError::Numerical { .. })) => {
                plans.push(BackendPlan {
                    backend: kind,
                    dofs: None,
                    plan: None,
                    unsupported: Some(e.to_string()),
                })
            }
            Err(e) => return Err(e.into()),
        }
    }
    let flags = scene.physics_flags();
    match opts.format {
        Format::Json => print_json(&serde_json::json!({
            "scene": scene,
            "family": scene.family(),
            "physics": flags.iter().map(|(k, v)| (k.to_string(), *v)).collect::<std::collections::BTreeMap<_, _>>(),
            "backends": plans,
        })),
        Format::Csv => {
            let mut rows: Vec<Vec<String>> = flags
                .iter()
                .map(|(k, v)| {
                    vec![
                        "physics".into(),
                        k.to_string(),
                        if *v { "on" } else { "off" }.into(),
                    ]
                })
                .collect();
            for p in &plans {
                if let Some(plan) = &p.plan {
                    for g in &plan.groups {
                        rows.push(vec![
                            p.backend.to_string(),
                            g.what.clone(),
                            g.count.to_string(),
                        ]);
                    }
                    rows.push(vec![
                        p.backend.to_string(),
                        "total".into(),
                        plan.total().to_string(),
                    ]);
                } else {
                    rows.push(vec![
                        p.backend.to_string(),
                        "unsupported".into(),
                        p.unsupported.clone().unwrap_or_default(),
                    ]);
                }
            }
            out!("{}", csv_table(&["section", "item", "value"], &rows));
            Ok(())
        }
        Format::Table | Format::Wide => {
            // Each line is built whole, then wrapped to the terminal unless `wide`.
            let mut text = String::new();
            macro_rules! say {
                ($($arg:tt)*) => {{
                    text.push_str(&format!($($arg)*));
                    text.push('\n');
                }};
            }
            say!("scene    {} — {}", scene.name, scene.description);
            say!("family   {}", scene.family());
            say!("units    {}", scene.units);
            say!(
                "run      t_end = {}, output every {}",
                scene.simulation.t_end,
                scene.simulation.output_interval
            );
            say!("physics");
            let width = flags.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
            for (k, v) in &flags {
                say!("  {:<width$} {}", k, if *v { "on" } else { "off" });
            }
            match &scene.model {
                Model::PayloadLink(p) => {
                    say!(
                        "rod: L = {}, R = {}, E = {:e}, G = {:e}, ρ = {}; fields {}; payload m = {}, c = {}",
                        p.length,
                        p.radius,
                        p.youngs_modulus,
                        p.shear_modulus,
                        p.density,
                        p.fields
                            .iter()
                            .map(|f| f.symbol())
                            .collect::<Vec<_>>()
                            .join(", "),
                        p.payload.mass,
                        p.payload.offset
                    );
                }
                Model::PlanarChain(chain) => {
                    for (i, l) in chain.links.iter().enumerate() {
                        say!(
                            "link {} `{}`: L = {}, ρA = {}, EI = {}{}{}",
                            i + 1,
                            l.name,
                            l.length,
                            l.mass_per_length,
                            l.bending_stiffness,
                            l.axial_stiffness
                                .map_or(String::new(), |v| format!(", EA = {v}")),
                            l.tip_mass
                                .map_or(String::new(), |v| format!(", tip mass {v}")),
                        );
                    }
                    for (i, contact) in chain.contacts.iter().enumerate() {
                        say!(
                            "contact {}: tip of `{}` against {:?} ({:?}, μ = {})",
                            i + 1,
                            contact.link,
                            contact.surface,
                            contact.mode,
                            contact.friction
                        );
                    }
                }
                Model::Rocket(_) | Model::MobileManipulator(_) => {}
            }
            say!("degrees of freedom");
            for p in &plans {
                match &p.plan {
                    Some(plan) => {
                        say!("  {}: {} DOFs", p.backend, plan.total());
                        for g in &plan.groups {
                            say!("      {:>6}  {}", g.count, g.what);
                        }
                        for b in &plan.builds {
                            say!("      builds: {b}");
                        }
                    }
                    None => say!(
                        "  {}: {}",
                        p.backend,
                        p.unsupported.as_deref().unwrap_or("unsupported")
                    ),
                }
            }
            if opts.format == Format::Wide {
                out!("{text}");
            } else {
                for line in text.lines() {
                    let indent = line.len() - line.trim_start().len();
                    outln!("{}", wrap(line, TERMINAL_WIDTH, indent + 4));
                }
            }
            Ok(())
        }
    }
}

/// Runs `f` for each requested backend with the settings it reads; unsupported backends are reported, and the command
/// fails with status 3 only when none could answer.
fn for_backends<T>(
    scene: &Scene,
    opts: &CommonOpts,
    mut f: impl FnMut(&dyn data::Backend, &Settings) -> Result<T, BackendError>,
) -> Result<Vec<(BackendKind, T)>, CliError> {
    let kinds = opts.kinds_for(scene);
    let settings = checked_settings(opts, &kinds)?;
    let mut done = Vec::new();
    let mut unsupported = Vec::new();
    for kind in kinds {
        match f(backend(kind).as_ref(), &settings.for_backend(kind)) {
            Ok(v) => done.push((kind, v)),
            Err(BackendError::Unsupported(why)) => {
                unsupported.push(format!("{kind}: unsupported: {why}"))
            }
            Err(e) => return Err(e.into()),
        }
    }
    for u in &unsupported {
        eprintln!("{u}");
    }
    if done.is_empty() {
        return Err(CliError::Unsupported(format!(
            "unsupported: no requested backend can do this for scene `{}`",
            scene.name
        )));
    }
    Ok(done)
}

fn modes(name: &str, count: usize, opts: &CommonOpts) -> Result<(), CliError> {
    let scene = load_scene(name)?;
    let results = for_backends(&scene, opts, |b, settings| b.modes(&scene, settings, count))?;
    if let Some(dir) = &opts.out {
        for (kind, r) in &results {
            let json = serde_json::to_vec_pretty(r).expect("serializable");
            write_atomic(dir, &format!("{}-{kind}-modes.json", scene.name), &json)?;
        }
    }
    let n = results
        .iter()
        .map(|(_, r)| r.frequencies_hz.len())
        .max()
        .unwrap_or(0);
    let mut header = vec!["mode".to_string()];
    header.extend(results.iter().map(|(k, _)| format!("{k} [Hz]")));
    let rows: Vec<Vec<String>> = (0..n)
        .map(|i| {
            let mut row = vec![(i + 1).to_string()];
            row.extend(results.iter().map(|(_, r)| {
                r.frequencies_hz
                    .get(i)
                    .map_or("-".into(), |f| format!("{f:.9e}"))
            }));
            row
        })
        .collect();
    let header: Vec<&str> = header.iter().map(|s| s.as_str()).collect();
    match opts.format {
        // At most four columns of numbers: the full table fits a terminal.
        Format::Table | Format::Wide => out!("{}", text_table(&header, &rows)),
        Format::Csv => out!("{}", csv_table(&header, &rows)),
        Format::Json => print_json(&results.iter().map(|(_, r)| r).collect::<Vec<_>>())?,
    }
    Ok(())
}

fn statics(name: &str, opts: &CommonOpts) -> Result<(), CliError> {
    let scene = load_scene(name)?;
    let results = for_backends(&scene, opts, |b, settings| b.statics(&scene, settings))?;
    let rows: Vec<Vec<String>> = results
        .iter()
        .map(|(k, r)| {
            vec![
                k.to_string(),
                format!("{:.12e}", r.tip_deflection),
                format!("{:.12e}", r.tip_rotation),
                r.cost.dofs.to_string(),
            ]
        })
        .collect();
    let header = ["backend", "tip deflection", "tip rotation", "dofs"];
    match opts.format {
        // At most four columns of numbers: the full table fits a terminal.
        Format::Table | Format::Wide => out!("{}", text_table(&header, &rows)),
        Format::Csv => out!("{}", csv_table(&header, &rows)),
        Format::Json => print_json(&results.iter().map(|(_, r)| r).collect::<Vec<_>>())?,
    }
    Ok(())
}

fn run(name: &str, opts: &CommonOpts) -> Result<(), CliError> {
    let scene = load_scene(name)?;
    // Contacts (and so switching events) exist only in planar chains.
    let has_contacts = match &scene.model {
        Model::PlanarChain(chain) => !chain.contacts.is_empty(),
        Model::Rocket(_) | Model::PayloadLink(_) | Model::MobileManipulator(_) => false,
    };
    let results = for_backends(&scene, opts, |b, settings| b.simulate(&scene, settings))?;
    if let Some(dir) = &opts.out {
        for (kind, r) in &results {
            let stem = format!("{}-{kind}", scene.name);
            write_atomic(
                dir,
                &format!("{stem}.json"),
                &serde_json::to_vec_pretty(r).expect("serializable"),
            )?;
            write_atomic(
                dir,
                &format!("{stem}-observables.csv"),
                observables_csv(&r.observables).as_bytes(),
            )?;
            write_atomic(
                dir,
                &format!("{stem}-ledger.csv"),
                ledger_csv(&r.ledger).as_bytes(),
            )?;
            write_atomic(
                dir,
                &format!("{stem}-events.json"),
                &serde_json::to_vec_pretty(&r.events).expect("serializable"),
            )?;
            if has_contacts {
                write_atomic(
                    dir,
                    &format!("{stem}-switching.csv"),
                    csv_table(&SWITCHING_HEADER, &switching_rows(&r.events)).as_bytes(),
                )?;
            }
        }
        eprintln!("wrote results to {}", dir.display());
    }
    match opts.format {
        Format::Json => print_json(&results.iter().map(|(_, r)| r).collect::<Vec<_>>())?,
        Format::Csv => {
            for (_, r) in &results {
                out!("{}", observables_csv(&r.observables));
            }
        }
        Format::Table | Format::Wide => {
            let wide = opts.format == Format::Wide;
            let header = [
                "backend",
                "verdict",
                "t reached",
                "dofs",
                "steps",
                "rejected",
                "wall [s]",
                "ledger closure",
                "events",
            ];
            let rows: Vec<Vec<String>> = results
                .iter()
                .map(|(k, r)| {
                    vec![
                        k.to_string(),
                        match &r.verdict {
                            StabilityVerdict::Completed => "completed".into(),
                            StabilityVerdict::Stopped { .. } => "STOPPED".into(),
                        },
                        r.observables
                            .time
                            .last()
                            .map_or("-".into(), |t| format!("{t:.4}")),
                        r.cost.dofs.to_string(),
                        r.cost.steps.to_string(),
                        r.cost.rejected_steps.to_string(),
                        format!("{:.3e}", r.cost.wall_time_s),
                        format!("{:.2e}", r.ledger.relative_closure()),
                        r.events.len().to_string(),
                    ]
                })
                .collect();
            if wide {
                out!("{}", text_table(&header, &rows));
            } else {
                let columns = header.map(Column::right);
                out!("{}", fitted_table(&columns, &rows, TERMINAL_WIDTH));
            }
            // Final values of every channel, one column per backend.
            let mut names: Vec<String> = Vec::new();
            for (_, r) in &results {
                for c in &r.observables.channels {
                    if !names.contains(&c.name) && !c.name.contains('@') {
                        names.push(c.name.clone());
                    }
                }
            }
            let mut header = vec!["final value".to_string()];
            header.extend(results.iter().map(|(k, _)| k.to_string()));
            let rows: Vec<Vec<String>> = names
                .iter()
                .map(|n| {
                    let mut row = vec![n.clone()];
                    row.extend(results.iter().map(|(_, r)| {
                        r.observables
                            .get(n)
                            .and_then(|c| c.values.last())
                            .map_or("-".into(), |v| format!("{v:.6e}"))
                    }));
                    row
                })
                .collect();
            let header: Vec<&str> = header.iter().map(|s| s.as_str()).collect();
            outln!();
            if wide {
                out!("{}", text_table(&header, &rows));
            } else {
                let mut columns: Vec<Column> = header.iter().map(|h| Column::right(h)).collect();
                columns[0] = Column::left(header[0]).elastic();
                out!("{}", fitted_table(&columns, &rows, TERMINAL_WIDTH));
            }
            if has_contacts {
                // The terminal table names the columns briefly; `--format wide` and the
                // switching CSV spell them out.
                let short = [
                    "t",
                    "event",
                    "contact",
                    "impulse",
                    "KE lost",
                    "momentum res.",
                    "normal force",
                    "t tol.",
                ]
                .map(Column::right);
                for (k, r) in &results {
                    let rows = switching_rows(&r.events);
                    outln!("\n{k}: {} switching events", rows.len());
                    if wide {
                        out!("{}", text_table(&SWITCHING_HEADER, &rows));
                    } else {
                        out!("{}", fitted_table(&short, &rows, TERMINAL_WIDTH));
                    }
                }
            }
        }
    }
    for (k, r) in &results {
        let closure = r.ledger.relative_closure();
        if closure > LEDGER_WARNING {
            eprintln!(
                "{}",
                wrap(
                    &format!(
                        "warning: {k}: the energy ledger closes only to {closure:.2e} \
                         (relative); the time step is too coarse for this scene — refine --dt \
                         (or --rtol) and compare"
                    ),
                    TERMINAL_WIDTH,
                    4
                )
            );
        }
    }
    let stopped: Vec<String> = results
        .iter()
        .filter_map(|(k, r)| match &r.verdict {
            StabilityVerdict::Stopped { diagnostic } => {
                Some(format!("{k}: run stopped {diagnostic}"))
            }
            StabilityVerdict::Completed => None,
        })
        .collect();
    if stopped.is_empty() {
        Ok(())
    } else {
        Err(CliError::Stopped(stopped.join("\n")))
    }
}
