//! The continuous extension of a step: the state between two levels.
//!
//! Over a step of length τ from level a to level b the state is interpolated linearly in time,
//! y(θ) = y_a + θ(y_b − y_a), θ ∈ [0, 1], for the positions and the velocities alike. Linear,
//! not the cubic Hermite interpolant of positions and velocities, for two reasons:
//! * the ledger's works are integrated by the trapezoidal rule, so they are linear in time
//!   inside a step; stored energies at a linearly interpolated state keep the ledger's residual
//!   at a sample inside a step between those of the two levels, while a cubic state moves the
//!   energies by O(τ²) against the linear works (measured with the cubic: the relative ledger
//!   closure of `single-link` over its run went from 8.2e-6 to 3.9e-5, `barhorst-case2` from
//!   1.9e-6 to 3.1e-6);
//! * a Hermite interpolant needs q̇ = v, and the rocket's rigid coordinates carry body-frame
//!   quasi-velocities (its sampled rigid velocity moved by half its peak with the cubic).
//!
//! The linear extension's error, ⅛τ²|ÿ|, is below the methods' own second-order error at the
//! stability steps fdm takes.

use super::levels::Levels;

/// The state at t_a + θτ on the linear interpolant of the step from level `a` to level `b`:
/// positions into `q`, velocities into `v`.
pub fn linear(a: &Levels, b: &Levels, theta: f64, q: &mut [f64], v: &mut [f64]) {
    for i in 0..q.len() {
        q[i] = a.q[i] + theta * (b.q[i] - a.q[i]);
        v[i] = a.v[i] + theta * (b.v[i] - a.v[i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_linear_extension_meets_the_levels_and_reproduces_a_line() {
        let (q0, v0, slope) = (0.25, -1.5, 3.0);
        let level = |theta: f64| Levels {
            q: vec![q0 + slope * theta, -q0],
            v: vec![v0 - slope * theta, v0],
        };
        let (a, b) = (level(0.0), level(1.0));
        let (mut q, mut v) = ([0.0; 2], [0.0; 2]);
        for k in 0..=4 {
            let theta = k as f64 / 4.0;
            linear(&a, &b, theta, &mut q, &mut v);
            let exact = level(theta);
            for i in 0..2 {
                assert!(
                    (q[i] - exact.q[i]).abs() <= 1e-15,
                    "θ = {theta}: q {}",
                    q[i]
                );
                assert!(
                    (v[i] - exact.v[i]).abs() <= 1e-15,
                    "θ = {theta}: v {}",
                    v[i]
                );
            }
        }
        linear(&a, &b, 0.0, &mut q, &mut v);
        assert_eq!((q.to_vec(), v.to_vec()), (a.q.clone(), a.v.clone()));
    }
}
