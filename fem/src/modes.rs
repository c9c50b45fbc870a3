//! Modal analysis: K φ = ω² M φ by Cholesky reduction (M = L Lᵀ, C = L⁻¹ K L⁻ᵀ symmetric),
//! dense faer self-adjoint eigensolver.

use data::scene::Link;
use faer::{Mat, Side};

use crate::error::FemError;
use crate::linear::LinearLink;

/// Eigenpairs of the generalized symmetric-definite problem, λ ascending, M-orthonormal vectors
/// in the columns of the returned matrix.
pub fn generalized_eigen(k: &Mat<f64>, m: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), FemError> {
    let llt = m.llt(Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "mass matrix is not positive definite".into(),
    })?;
    let lm = llt.L();
    let mut t = k.clone();
    lm.solve_lower_triangular_in_place(&mut t);
    let mut c = t.transpose().to_owned();
    lm.solve_lower_triangular_in_place(&mut c);
    // Symmetrize against round-off before the self-adjoint solver reads the lower triangle.
    let n = c.nrows();
    for i in 0..n {
        for j in 0..i {
            let a = 0.5 * (c[(i, j)] + c[(j, i)]);
            c[(i, j)] = a;
            c[(j, i)] = a;
        }
    }
    let ev = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| FemError::Numerical {
            t: 0.0,
            message: "eigensolver did not converge".into(),
        })?;
    let s = ev.S().column_vector();
    let lam: Vec<f64> = (0..n).map(|i| s[i]).collect();
    let mut x = ev.U().to_owned();
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
            if sys.layout.axial && a % sys.layout.dofs_per_node == 2 {
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
pub fn sample_shape(
    sys: &LinearLink,
    link: &Link,
    v: &[f64],
    stations: usize,
) -> (Vec<f64>, Vec<f64>) {
    let st = stations.max(2);
    let xs: Vec<f64> = (0..st)
        .map(|k| sys.length * k as f64 / (st - 1) as f64)
        .collect();
    let mut w: Vec<f64> = xs.iter().map(|&x| sys.deflection_at(v, x, link)).collect();
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
