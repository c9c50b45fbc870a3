//! Modal analysis: K φ = ω² M φ, dense faer self-adjoint eigensolver after a Cholesky reduction.
//!
//! Which matrix is factored matters for accuracy. Reducing with M = LLᵀ (C = L⁻¹KL⁻ᵀ) makes the
//! absolute eigenvalue error ≈ ε‖K‖‖M⁻¹‖ = ε·λ_max: the lowest modes lose accuracy in proportion
//! to λ_max/λ₁, which grows as n⁴ and is large for the quintic's bubble DOFs (measured: mode 1
//! of the cantilever 2e-8 off at 64 cubic elements, 4e-8 at 64 quintic ones). When K is positive
//! definite (every clamped link not spinning past a bending frequency) we reduce with
//! K = LLᵀ instead: C = L⁻¹ M L⁻ᵀ has eigenvalues μ = 1/ω², the lowest modes are the *largest*
//! μ, and their error ≈ ε·μ₁ is relative round-off. An indefinite K (spinning above a bending
//! frequency without stiffening) falls back to the M reduction, whose negative ω² the caller
//! reports as an error.

use faer::{Mat, Side};

use crate::error::FemError;
use crate::linear::LinearLink;

/// fem's `modes` answer: angular frequencies ω [rad/s] reported in Hz with their kinds and
/// shapes, the cost of one factorization of a `dofs`-DOF pencil timed from `start`.
pub fn modal_result(
    scene: &data::Scene,
    settings: &data::FemSettings,
    modes: impl Iterator<Item = (f64, String)>,
    shapes: Vec<data::ModeShape>,
    dofs: usize,
    start: std::time::Instant,
) -> data::ModalResult {
    let (frequencies_hz, kinds) = modes
        .map(|(omega, kind)| (omega / (2.0 * std::f64::consts::PI), kind))
        .unzip();
    data::ModalResult {
        backend: data::BackendKind::Fem,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        frequencies_hz,
        kinds,
        shapes,
        cost: data::Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs,
            factorizations: 1,
            ..Default::default()
        },
    }
}

/// Eigenpairs of the generalized symmetric-definite problem, λ ascending, M-orthonormal vectors
/// in the columns of the returned matrix (fewer than the DOF count when M is singular).
pub fn generalized_eigen(k: &Mat<f64>, m: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), FemError> {
    match k.llt(Side::Lower) {
        Ok(llt) => stiffness_reduction(llt.L(), m),
        Err(_) => mass_reduction(k, m),
    }
}

/// C = L⁻¹ B L⁻ᵀ, symmetrized against round-off before the self-adjoint solver reads the lower
/// triangle.
fn reduce(l: faer::MatRef<'_, f64>, b: &Mat<f64>) -> Mat<f64> {
    let mut t = b.clone();
    l.solve_lower_triangular_in_place(&mut t);
    let mut c = t.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut c);
    let n = c.nrows();
    for i in 0..n {
        for j in 0..i {
            let a = 0.5 * (c[(i, j)] + c[(j, i)]);
            c[(i, j)] = a;
            c[(j, i)] = a;
        }
    }
    c
}

fn self_adjoint(c: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), FemError> {
    let ev = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| FemError::Numerical {
            t: 0.0,
            message: "eigensolver did not converge".into(),
        })?;
    let s = ev.S().column_vector();
    Ok(((0..c.nrows()).map(|i| s[i]).collect(), ev.U().to_owned()))
}

/// K = LLᵀ: eigenvalues μ = 1/λ of L⁻¹ M L⁻ᵀ, φ = L⁻ᵀ y / √μ (then φᵀMφ = 1).
///
/// M may be singular here (a Timoshenko link without rotary inertia leaves θ massless): those
/// directions have μ = 0, i.e. infinite frequency, and are not returned. Neither is any μ within
/// round-off of zero (below 1e3·ε·μ_max), whose 1/μ would carry no correct digit.
fn stiffness_reduction(
    l: faer::MatRef<'_, f64>,
    m: &Mat<f64>,
) -> Result<(Vec<f64>, Mat<f64>), FemError> {
    let c = reduce(l, m);
    let (mu, y) = self_adjoint(&c)?;
    let n = mu.len();
    let mu_max = mu.iter().fold(0.0f64, |a, &b| a.max(b));
    if mu_max <= 0.0 {
        return Err(FemError::Numerical {
            t: 0.0,
            message: "mass matrix is zero".into(),
        });
    }
    let floor = 1e3 * f64::EPSILON * mu_max;
    let finite = mu.iter().filter(|&&x| x > floor).count();
    let mut x = y;
    l.transpose().solve_upper_triangular_in_place(&mut x);
    // μ ascending ⇒ λ = 1/μ descending: take the largest μ first.
    let mut out = Mat::<f64>::zeros(n, finite);
    let mut lam = Vec::with_capacity(finite);
    for j in 0..finite {
        let src = n - 1 - j;
        let s = 1.0 / mu[src].sqrt();
        for i in 0..n {
            out[(i, j)] = x[(i, src)] * s;
        }
        lam.push(1.0 / mu[src]);
    }
    Ok((lam, out))
}

/// M = LLᵀ: eigenvalues λ of L⁻¹ K L⁻ᵀ, φ = L⁻ᵀ y. Used when K is not positive definite.
fn mass_reduction(k: &Mat<f64>, m: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), FemError> {
    let llt = m.llt(Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "mass matrix is not positive definite".into(),
    })?;
    let lm = llt.L();
    let c = reduce(lm, k);
    let (lam, mut x) = self_adjoint(&c)?;
    lm.transpose().solve_upper_triangular_in_place(&mut x);
    Ok((lam, x))
}

/// One computed mode of a single link.
#[derive(Debug, Clone)]
pub struct Mode {
    pub omega: f64,
    pub kind: &'static str,
    pub vector: Vec<f64>,
}

/// Lowest `count` modes of a linear link model. Negative ω² (the linear model spinning above
/// its first bending frequency) is an error, never a NaN frequency.
pub fn link_modes(sys: &LinearLink, count: usize) -> Result<Vec<Mode>, FemError> {
    let (lam, x) = generalized_eigen(&sys.k, &sys.m)?;
    let n = sys.ndof();
    let mut out = Vec::with_capacity(count.min(n));
    for (j, &l) in lam.iter().enumerate().take(count.min(n)) {
        if l < 0.0 {
            return Err(FemError::Numerical {
                t: 0.0,
                message: format!(
                    "mode {} has ω² = {l:.3e} < 0: the linearized link is unstable (spinning \
                     above a bending frequency without geometric stiffening)",
                    j + 1
                ),
            });
        }
        let v: Vec<f64> = (0..n).map(|i| x[(i, j)]).collect();
        // Kinetic-energy share of the axial DOFs decides the kind.
        let mut axial_share = 0.0;
        let mut total = 0.0;
        for a in 0..n {
            let mv: f64 = (0..n).map(|b| sys.m[(a, b)] * v[b]).sum();
            total += v[a] * mv;
            if sys.layout.is_axial(a) {
                axial_share += v[a] * mv;
            }
        }
        let kind = if total > 0.0 && axial_share > 0.5 * total {
            "axial"
        } else {
            "bending"
        };
        out.push(Mode {
            omega: l.sqrt(),
            kind,
            vector: v,
        });
    }
    Ok(out)
}

/// Samples a mode's transverse component at `stations` equally spaced points, normalized to unit
/// maximum magnitude (largest entry positive); an axial mode with no transverse part stays zero.
pub fn sample_shape(sys: &LinearLink, v: &[f64], stations: usize) -> (Vec<f64>, Vec<f64>) {
    let st = stations.max(2);
    let xs: Vec<f64> = (0..st)
        .map(|k| sys.length * k as f64 / (st - 1) as f64)
        .collect();
    let mut w: Vec<f64> = xs.iter().map(|&x| sys.deflection_at(v, x)).collect();
    let (mut big, mut arg) = (0.0f64, 0.0f64);
    for &y in &w {
        if y.abs() > big {
            big = y.abs();
            arg = y;
        }
    }
    let vmax = v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    if big > 1e-9 * vmax.max(f64::MIN_POSITIVE) {
        let s = big.copysign(arg);
        w.iter_mut().for_each(|y| *y /= s);
    } else {
        w.iter_mut().for_each(|y| *y = 0.0);
    }
    (xs, w)
}
