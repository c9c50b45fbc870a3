//! The crate's small dense kernels on preallocated row-major storage (no allocation): dot
//! product, matrix–vector product, the 2 × 2 solve by Cramer's rule, and the Cholesky factorization A = L Lᵀ with its two
//! triangular solves, used for the reduced mass matrices solved at every right-hand side
//! (order ≤ ~150), the Newton matrix M + cD + c²K of the chain and the condensation of the
//! Timoshenko section rotation.

/// Σ aᵢ bᵢ over the shorter of the two slices.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// out = M x for the row-major n × n matrix M.
pub fn mat_vec(m: &[f64], n: usize, x: &[f64], out: &mut [f64]) {
    for i in 0..n {
        let row = &m[i * n..(i + 1) * n];
        out[i] = row.iter().zip(x).map(|(a, b)| a * b).sum();
    }
}

/// Solves the 2 × 2 system [[s₀, s₁], [s₂, s₃]] x = r (row-major, Cramer's rule): the
/// contact's two multipliers (symmetric, s₁ = s₂) and the Newton solve's Schur complement of
/// two constraint rows.
pub fn solve2(s: &[f64; 4], r: [f64; 2]) -> [f64; 2] {
    let det = s[0] * s[3] - s[1] * s[2];
    [
        (s[3] * r[0] - s[1] * r[1]) / det,
        (s[0] * r[1] - s[2] * r[0]) / det,
    ]
}

/// A pivot of a Cholesky factorization that is not positive and finite: the matrix is not
/// (numerically) positive definite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotPositiveDefinite {
    /// Index of the failing pivot.
    pub pivot: usize,
}

/// In-place Cholesky factorization A = L Lᵀ of the SPD matrix A (row-major n × n; L is left in
/// the lower triangle).
pub fn cholesky_factor(a: &mut [f64], n: usize) -> Result<(), NotPositiveDefinite> {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return Err(NotPositiveDefinite { pivot: j });
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    Ok(())
}

/// Forward/back substitution b ← (L Lᵀ)⁻¹ b with the lower Cholesky factor stored in `l`
/// (row-major n × n, from [`cholesky_factor`]).
pub fn cholesky_substitute(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
}

/// In-place Cholesky solve of the SPD system A x = b (A overwritten by its factor, b by x).
pub fn cholesky_solve(a: &mut [f64], n: usize, b: &mut [f64]) -> Result<(), NotPositiveDefinite> {
    cholesky_factor(a, n)?;
    cholesky_substitute(a, n, b);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_cholesky_solves_spd_system() {
        let n = 5;
        // A = Bᵀ B + n I is SPD
        let b: Vec<f64> = (0..n * n)
            .map(|i| ((i * 7 + 3) % 11) as f64 - 5.0)
            .collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| b[k * n + i] * b[k * n + j]).sum::<f64>()
                    + if i == j { n as f64 } else { 0.0 };
            }
        }
        let x_true: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let mut rhs = vec![0.0; n];
        mat_vec(&a, n, &x_true, &mut rhs);
        let mut l = a.clone();
        cholesky_factor(&mut l, n).unwrap();
        cholesky_substitute(&l, n, &mut rhs);
        for i in 0..n {
            // well-conditioned 5×5: round-off ~1e-14
            assert!((rhs[i] - x_true[i]).abs() < 1e-12);
        }
        let mut bad = vec![1.0, 2.0, 2.0, 1.0];
        assert_eq!(
            cholesky_factor(&mut bad, 2),
            Err(NotPositiveDefinite { pivot: 1 })
        );
    }
}
