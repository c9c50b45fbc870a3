//! The kinetic-energy gradient and mass product of a system at a given velocity: what the
//! discrete gradient is built from, and its finite-difference oracle for the checks.

use crate::linalg::max_abs;
use crate::system::{Parts, System};

/// Relative size of the finite-difference perturbation of q for Ṁ(x)x in the oracle
/// [`kinetic_gradient_fd`].
pub const FD_STEP: f64 = 1e-5;
/// ∂T/∂q at (q, x) with T = ½xᵀM(q)x, analytic ([`System::add_kinetic_gradient`], the one
/// the scheme uses). Allocates: for checks, not for step loops.
pub fn kinetic_gradient<S: System + ?Sized>(
    system: &mut S,
    t: f64,
    q: &[f64],
    x: &[f64],
) -> Vec<f64> {
    let mut out = vec![0.0; q.len()];
    system.add_kinetic_gradient(t, q, x, 1.0, &mut out);
    out
}

/// ∂T/∂q at (q, x) by the identity ∂T/∂q = Ṁ(x)x − R_in(q, x, 0) with the central difference
/// Ṁ(x)x = [M(q + εx)x − M(q − εx)x]/(2ε), ε‖x‖∞ = `delta` (truncation ~10⁻¹⁰, round-off
/// ~10⁻¹¹ relative at `delta` = [`FD_STEP`]): 3 inertial passes of the residual, independent of
/// the analytic sweep — its test oracle. Allocates: for checks, not for step loops.
pub fn kinetic_gradient_fd<S: System + ?Sized>(
    system: &mut S,
    t: f64,
    q: &[f64],
    x: &[f64],
    delta: f64,
) -> Vec<f64> {
    let n = q.len();
    let zero = vec![0.0; n];
    let mut out = zero.clone();
    let xmax = max_abs(x);
    if xmax == 0.0 {
        return out;
    }
    let eps = delta / xmax;
    let (mut tmp, mut tmp2) = (zero.clone(), zero.clone());
    let qp: Vec<f64> = q.iter().zip(x).map(|(a, b)| a + eps * b).collect();
    system.residual_parts(t, &qp, &zero, x, Parts::INERTIA, &mut tmp);
    let qm: Vec<f64> = q.iter().zip(x).map(|(a, b)| a - eps * b).collect();
    system.residual_parts(t, &qm, &zero, x, Parts::INERTIA, &mut tmp2);
    for i in 0..n {
        out[i] = (tmp[i] - tmp2[i]) / (2.0 * eps);
    }
    system.residual_parts(t, q, x, &zero, Parts::INERTIA, &mut tmp);
    for i in 0..n {
        out[i] -= tmp[i];
    }
    out
}

/// The mass product M(q)x = R_in(q, 0, x). Allocates: for checks, not for step loops.
pub fn mass_product<S: System + ?Sized>(system: &mut S, t: f64, q: &[f64], x: &[f64]) -> Vec<f64> {
    let n = q.len();
    let zero = vec![0.0; n];
    let mut out = zero.clone();
    system.residual_parts(t, q, &zero, x, Parts::INERTIA, &mut out);
    out
}
