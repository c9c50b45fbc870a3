//! Small dense symmetric positive-definite solves on preallocated storage (no allocation), for
//! the reduced mass matrix (order 3 + 2n + 2·masses ≤ 147) solved at every right-hand side.

/// In-place Cholesky factorization of the row-major n×n SPD matrix `a` (lower triangle used and
/// overwritten by L). Returns the index of the first non-positive pivot on failure.
pub fn cholesky_in_place(a: &mut [f64], n: usize) -> Result<(), usize> {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return Err(j);
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

/// Solves L Lᵀ x = b in place (b becomes x), with L from [`cholesky_in_place`].
pub fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
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

/// y = A x for row-major n×n A.
pub fn mat_vec(a: &[f64], n: usize, x: &[f64], y: &mut [f64]) {
    for i in 0..n {
        y[i] = (0..n).map(|j| a[i * n + j] * x[j]).sum();
    }
}

pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
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
        cholesky_in_place(&mut l, n).unwrap();
        cholesky_solve(&l, n, &mut rhs);
        for i in 0..n {
            // well-conditioned 5×5: round-off ~1e-14
            assert!((rhs[i] - x_true[i]).abs() < 1e-12);
        }
        let mut bad = vec![1.0, 2.0, 2.0, 1.0];
        assert_eq!(cholesky_in_place(&mut bad, 2), Err(1));
    }
}
