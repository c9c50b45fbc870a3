//! Elastic difference operators of the rocket, derived from the discrete strain energy
//! (report 3.50 with P = EA u'):
//!
//! V = Σ_segments h·EA_s·(½ e_s² + ½ e_s g_s²) + Σ_{interior stations} ½ h·EI_i κ_i²,
//! e_s = (u_{s+1} − u_s)/h, g_s = (w_{s+1} − w_s)/h, κ_i = (w_{i+1} − 2w_i + w_{i−1})/h².
//!
//! Forces are −∂V/∂q. With trapezoid-lumped masses (h/2 at the ends, 5.13–5.14) they reproduce
//! the report's stencils exactly where the OCR is legible: interior axial rows
//! EA(u_{i+1} − 2u_i + u_{i−1})/h² (5.23, in conservative form across the stage junction),
//! interior bending rows −EI δ⁴w/h⁴ (5.25), and at the free ends the rows obtained with the
//! ghost nodes of 5.31 (u_{−1} = u_1) and 5.32 (w_{−1} = 2w_0 − w_1 for zero moment,
//! w_{−2} = w_2 − 2w_1 + 2w_{−1} for zero shear), because κ at the end stations is omitted
//! (zero moment) — see the element tests.

/// Adds axial (N = EA(e + ½g²)) and geometric (P g, P = EA e) forces.
pub fn add_axial_forces(h: f64, ea: &[f64], u: &[f64], w: &[f64], fu: &mut [f64], fw: &mut [f64]) {
    let inv_h = 1.0 / h;
    for s in 0..ea.len() {
        let e = (u[s + 1] - u[s]) * inv_h;
        let g = (w[s + 1] - w[s]) * inv_h;
        let n = ea[s] * (e + 0.5 * g * g);
        let pg = ea[s] * e * g;
        fu[s] += n;
        fu[s + 1] -= n;
        fw[s] += pg;
        fw[s + 1] -= pg;
    }
}

/// Adds bending forces −∂/∂w ½ Σ h EI_i κ_i² (interior stations; κ = 0 at free ends).
pub fn add_bending_forces(h: f64, ei_station: &[f64], w: &[f64], fw: &mut [f64]) {
    let inv_h3 = 1.0 / (h * h * h);
    for i in 1..w.len() - 1 {
        let m = ei_station[i] * (w[i + 1] - 2.0 * w[i] + w[i - 1]) * inv_h3;
        fw[i - 1] -= m;
        fw[i] += 2.0 * m;
        fw[i + 1] -= m;
    }
}

/// Strain energy V(u, w) of the module docs.
pub fn strain_energy(h: f64, ea: &[f64], ei_station: &[f64], u: &[f64], w: &[f64]) -> f64 {
    let mut v = 0.0;
    for s in 0..ea.len() {
        let e = (u[s + 1] - u[s]) / h;
        let g = (w[s + 1] - w[s]) / h;
        v += h * ea[s] * (0.5 * e * e + 0.5 * e * g * g);
    }
    for i in 1..w.len() - 1 {
        let k = (w[i + 1] - 2.0 * w[i] + w[i - 1]) / (h * h);
        v += 0.5 * h * ei_station[i] * k * k;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields(n: usize) -> (Vec<f64>, Vec<f64>) {
        let u = (0..n).map(|i| 1e-3 * ((i as f64) * 0.7).sin()).collect();
        let w = (0..n)
            .map(|i| 2e-3 * ((i as f64) * 0.31).cos() + 1e-4 * i as f64)
            .collect();
        (u, w)
    }

    #[test]
    fn elem_forces_are_minus_energy_gradient() {
        let n = 12;
        let h = 0.5;
        let ea: Vec<f64> = (0..n - 1)
            .map(|s| if s < 6 { 3.0e3 } else { 1.5e3 })
            .collect();
        let ei: Vec<f64> = (0..n).map(|i| 10.0 + i as f64).collect();
        let (u, w) = fields(n);
        let mut fu = vec![0.0; n];
        let mut fw = vec![0.0; n];
        add_axial_forces(h, &ea, &u, &w, &mut fu, &mut fw);
        add_bending_forces(h, &ei, &w, &mut fw);
        let eps = 1e-7;
        for k in 0..n {
            for (field, f) in [(0, &fu), (1, &fw)] {
                let (mut up, mut wp, mut um, mut wm) = (u.clone(), w.clone(), u.clone(), w.clone());
                if field == 0 {
                    up[k] += eps;
                    um[k] -= eps;
                } else {
                    wp[k] += eps;
                    wm[k] -= eps;
                }
                let d = (strain_energy(h, &ea, &ei, &up, &wp)
                    - strain_energy(h, &ea, &ei, &um, &wm))
                    / (2.0 * eps);
                // Central difference of a cubic polynomial energy: truncation O(eps²·V''') ≈ 1e-11,
                // round-off ≈ 1e-16·V/eps ≈ 1e-9 relative to forces of order 1e1.
                assert!(
                    (f[k] + d).abs() <= 1e-6 * (1.0 + d.abs()),
                    "dof {field}/{k}: {} vs {}",
                    f[k],
                    -d
                );
            }
        }
    }

    #[test]
    fn elem_interior_rows_are_exact_derivatives_of_polynomials() {
        // Uniform EI, EA: interior bending row / h equals −EI w'''' exactly for a quartic
        // (δ⁴ x⁴ = 24 h⁴; odd terms cancel), axial row equals EA u'' exactly for a cubic.
        let n = 15;
        let h = 0.3;
        let (ea0, ei0) = (7.0, 5.0);
        let ea = vec![ea0; n - 1];
        let ei = vec![ei0; n];
        let c4 = 0.37;
        let w: Vec<f64> = (0..n)
            .map(|i| {
                let x = i as f64 * h;
                1.0 + 0.2 * x - 0.3 * x * x + 0.11 * x * x * x + c4 * x.powi(4)
            })
            .collect();
        let u: Vec<f64> = (0..n)
            .map(|i| {
                let x = i as f64 * h;
                0.5 * x - 0.25 * x * x + 0.125 * x * x * x
            })
            .collect();
        let mut fw = vec![0.0; n];
        add_bending_forces(h, &ei, &w, &mut fw);
        for (i, f) in fw.iter().enumerate().take(n - 2).skip(2) {
            // per unit length: force / h
            let expected = -ei0 * 24.0 * c4;
            // exact in exact arithmetic; round-off of δ⁴ ~ 16·|w|·1e-16/h⁴ ≈ 1e-12 relative
            assert!(
                (f / h - expected).abs() < 1e-8 * expected.abs(),
                "station {i}"
            );
        }
        let mut fu = vec![0.0; n];
        let zero = vec![0.0; n];
        let mut dummy = vec![0.0; n];
        add_axial_forces(h, &ea, &u, &zero, &mut fu, &mut dummy);
        for (i, f) in fu.iter().enumerate().take(n - 1).skip(1) {
            let x = i as f64 * h;
            let expected = ea0 * (-0.5 + 0.75 * x);
            assert!(
                (f / h - expected).abs() < 1e-9 * (1.0 + expected.abs()),
                "station {i}"
            );
        }
    }

    #[test]
    fn elem_free_end_rows_match_ghost_nodes_5_31_5_32() {
        // Report ghost nodes at the aft end (our station 0 = report station 1):
        // u_{-1} = u_1; w_{-1} = 2w_0 − w_1; w_{-2} = w_2 − 2w_1 + 2w_{-1}.
        // With lumped mass h/2 at the end, h inside, the energy-derived forces must equal
        // the ghost-node stencils times the lumped length.
        let n = 10;
        let h = 0.4;
        let (ea0, ei0) = (3.0, 2.0);
        let (u, w) = fields(n);
        let mut fu = vec![0.0; n];
        let mut fw = vec![0.0; n];
        add_axial_forces(
            h,
            &vec![ea0; n - 1],
            &u,
            &vec![0.0; n],
            &mut fu,
            &mut vec![0.0; n],
        );
        add_bending_forces(h, &vec![ei0; n], &w, &mut fw);
        let gm1 = u[1];
        let axial_row0 = ea0 * (u[1] - 2.0 * u[0] + gm1) / (h * h);
        assert!((fu[0] / (0.5 * h) - axial_row0).abs() < 1e-10 * (1.0 + axial_row0.abs()));
        let wm1 = 2.0 * w[0] - w[1];
        let wm2 = w[2] - 2.0 * w[1] + 2.0 * wm1;
        let d4 = |a: f64, b: f64, c: f64, d: f64, e: f64| {
            (a - 4.0 * b + 6.0 * c - 4.0 * d + e) / h.powi(4)
        };
        let row0 = -ei0 * d4(wm2, wm1, w[0], w[1], w[2]);
        let row1 = -ei0 * d4(wm1, w[0], w[1], w[2], w[3]);
        assert!(
            (fw[0] / (0.5 * h) - row0).abs() < 1e-9 * (1.0 + row0.abs()),
            "{} {}",
            fw[0] / (0.5 * h),
            row0
        );
        assert!((fw[1] / h - row1).abs() < 1e-9 * (1.0 + row1.abs()));
        // Ghost nodes give zero moment and zero shear at the free end:
        let moment = (w[1] - 2.0 * w[0] + wm1) / (h * h);
        let shear = (w[2] - 2.0 * w[1] + 2.0 * wm1 - wm2) / (2.0 * h.powi(3));
        assert!(moment.abs() < 1e-12 && shear.abs() < 1e-9);
    }
}
