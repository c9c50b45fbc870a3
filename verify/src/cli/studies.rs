//! `converge` and `recommend`: a refinement study through the library, printed.

use data::load_scene;

use super::CliError;
use super::args::CommonOpts;
use super::progress::Bar;
use crate::output::{Format, TERMINAL_WIDTH};
use crate::study::{self, Refine};

pub fn converge(
    scene: &str,
    quantity: &str,
    refine: Refine,
    opts: &CommonOpts,
) -> Result<(), CliError> {
    let scene = load_scene(scene)?;
    let bar = Bar::new();
    let study = study::converge(
        &scene,
        quantity,
        refine,
        &opts.kinds(),
        &opts.settings(),
        &bar,
    )?;
    bar.clear();
    if let Some(dir) = &opts.out {
        for n in study::write_study(dir, &study)? {
            eprintln!("note: {n}");
        }
        eprintln!("wrote the study and its plots to {}", dir.display());
    }
    match opts.format {
        Format::Json => println!("{}", study::json(&study)),
        Format::Csv => print!("{}", study::csv(&study)),
        Format::Wide => print!("{}", study::wide_table(&study)),
        Format::Table => print!("{}", study::terminal_table(&study, TERMINAL_WIDTH)),
    }
    Ok(())
}

pub fn recommend(scene: &str, quantity: &str, tol: f64, opts: &CommonOpts) -> Result<(), CliError> {
    let scene = load_scene(scene)?;
    let bar = Bar::new();
    let recommendation =
        study::recommend(&scene, quantity, tol, &opts.kinds(), &opts.settings(), &bar);
    bar.clear();
    let r = recommendation?;
    match opts.format {
        Format::Table => print!("{}", r.terminal_text(TERMINAL_WIDTH)),
        Format::Wide | Format::Csv | Format::Json => print!("{}", r.wide_text()),
    }
    Ok(())
}
