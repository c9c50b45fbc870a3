//! Helpers shared by the fdm test files.
#![allow(dead_code)]

use data::RunResult;

/// The samples of an observable channel (panics with the name if the run has no such channel).
pub fn channel<'a>(r: &'a RunResult, name: &str) -> &'a [f64] {
    &r.observables
        .channels
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no channel {name}"))
        .values
}

/// A deflected, moving two-link chain state of n DOFs (joint angles first; foreshortening sums
/// nonzero, every coupling active).
pub fn moving_chain_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n)
        .map(|i| match i {
            0 => 0.7,
            1 => 1.9,
            _ => 0.02 * (0.9 * i as f64).sin() + 0.004 * i as f64,
        })
        .collect();
    let v = (0..n)
        .map(|i| match i {
            0 => 1.3,
            1 => -0.8,
            _ => 0.3 * (1.7 * i as f64).cos(),
        })
        .collect();
    (q, v)
}
