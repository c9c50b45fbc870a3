//! Euler–Bernoulli beam element (Hermite-cubic v) and the linear axial bar (linear u).
//!
//! Energies per element of length h (x measured from the element start):
//! * kinetic (transverse) T = ½∫ρA v̇² (+ ½∫ρI v̇′² with rotary inertia) → consistent mass;
//! * bending U_b = ½∫EI v″² → stiffness;
//! * geometric (axial force N(x) given) U_g = ½∫N v′² → geometric stiffness;
//! * von Kármán (extensible) U = ½EA h ε̄² + ½∫EI v″², ε̄ = u′ + (1/2h)∫v′² (membrane strain
//!   averaged per element, free of membrane locking), DOFs d = (u₁, u₂, v₁, v₁′, v₂, v₂′):
//!   internal force f = ∂U/∂d and tangent K_t = ∂f/∂d.
//!
//! All integrals use the 4-point Gauss rule: exact for the mass (degree 6) and the linear
//! operators; for the von Kármán energy the force and tangent are the exact derivatives of the
//! *same* quadrature of the energy, which is what energy consistency needs.

use super::contract::{
    Element, ElementDofs, InteriorDof, Local, MAXE, Mat4, MeshElement, NONE, Row, Shapes,
    linear_internal_force, linear_strain_energy, linear_tangent, pad,
};
use super::hermite::hermite;
use super::quadrature::gauss01;
use crate::linalg::dot;

/// Consistent transverse mass ∫ρA NᵢNⱼ (+ ∫ρI Nᵢ′Nⱼ′ when `rho_i` > 0).
pub fn mass(rho_a: f64, rho_i: f64, h: f64) -> Mat4 {
    let (p, w) = gauss01(4);
    let mut m = [[0.0; 4]; 4];
    for (xi, wg) in p.iter().zip(w) {
        let s = hermite(*xi, h);
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] += wg * h * (rho_a * s.n[i] * s.n[j] + rho_i * s.dn[i] * s.dn[j]);
            }
        }
    }
    m
}

/// Bending stiffness ∫EI Nᵢ″Nⱼ″.
pub fn bending_stiffness(ei: f64, h: f64) -> Mat4 {
    let (p, w) = gauss01(4);
    let mut k = [[0.0; 4]; 4];
    for (xi, wg) in p.iter().zip(w) {
        let s = hermite(*xi, h);
        for i in 0..4 {
            for j in 0..4 {
                k[i][j] += wg * h * ei * s.ddn[i] * s.ddn[j];
            }
        }
    }
    k
}

/// Geometric stiffness ∫N(x) Nᵢ′Nⱼ′ for an axial force N given as a function of the local
/// coordinate ξ ∈ [0, 1] (tension positive). Exact for N of degree ≤ 3.
pub fn geometric_stiffness(h: f64, axial_force: impl Fn(f64) -> f64) -> Mat4 {
    let (p, w) = gauss01(4);
    let mut k = [[0.0; 4]; 4];
    for (xi, wg) in p.iter().zip(w) {
        let s = hermite(*xi, h);
        let n = axial_force(*xi);
        for i in 0..4 {
            for j in 0..4 {
                k[i][j] += wg * h * n * s.dn[i] * s.dn[j];
            }
        }
    }
    k
}

/// Von Kármán element DOFs: (u₁, u₂, v₁, v₁′, v₂, v₂′).
pub type VkDofs = [f64; 6];

/// Element-averaged membrane strain ε̄ = u′ + (1/2h)∫v′², its gradient ∂ε̄/∂d and
/// ∫N′N′ᵀ (the Hessian of ½∫v′²).
///
/// With linear u, u′ is constant per element while ½v′² is quartic: a pointwise strain would lock
/// (spurious membrane energy stiffens bending: the spin-up tip deflection came out 17 % low at 8
/// elements). Averaging the membrane strain over the element (an assumed-strain, locking-free
/// choice) keeps a constant strain compatible with u′; the energy below is the exact potential of
/// the force and tangent.
fn membrane(h: f64, d: &VkDofs) -> (f64, VkDofs, [[f64; 4]; 4]) {
    let (p, w) = gauss01(4);
    let dv = [d[2], d[3], d[4], d[5]];
    let mut half_int = 0.0;
    let mut g = [0.0; 6];
    let mut h2 = [[0.0; 4]; 4];
    g[0] = -1.0 / h;
    g[1] = 1.0 / h;
    for (xi, wg) in p.iter().zip(w) {
        let s = hermite(*xi, h);
        let vp = dot(&s.dn, &dv);
        half_int += wg * h * 0.5 * vp * vp;
        for k in 0..4 {
            g[2 + k] += wg * vp * s.dn[k];
            for j in 0..4 {
                h2[k][j] += wg * h * s.dn[k] * s.dn[j];
            }
        }
    }
    ((d[1] - d[0]) / h + half_int / h, g, h2)
}

/// Strain energy ½EA h ε̄² + ½∫EI v″² of one element.
pub fn von_karman_energy(ea: f64, ei: f64, h: f64, d: &VkDofs) -> f64 {
    let (eps, _, _) = membrane(h, d);
    let kb = bending_stiffness(ei, h);
    let dv = [d[2], d[3], d[4], d[5]];
    let mut bend = 0.0;
    for a in 0..4 {
        bend += 0.5 * dv[a] * dot(&kb[a], &dv);
    }
    0.5 * ea * h * eps * eps + bend
}

/// Internal force f = ∂U/∂d of the von Kármán element.
pub fn von_karman_force(ea: f64, ei: f64, h: f64, d: &VkDofs) -> VkDofs {
    let (eps, g, _) = membrane(h, d);
    let kb = bending_stiffness(ei, h);
    let dv = [d[2], d[3], d[4], d[5]];
    let n = ea * eps;
    let mut f = [0.0; 6];
    for k in 0..6 {
        f[k] = n * h * g[k];
    }
    for a in 0..4 {
        f[2 + a] += dot(&kb[a], &dv);
    }
    f
}

/// Tangent K_t = ∂f/∂d of the von Kármán element.
pub fn von_karman_tangent(ea: f64, ei: f64, h: f64, d: &VkDofs) -> [[f64; 6]; 6] {
    let (eps, g, h2) = membrane(h, d);
    let kb = bending_stiffness(ei, h);
    let n = ea * eps;
    let mut k = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            k[i][j] = ea * h * g[i] * g[j];
        }
    }
    for i in 0..4 {
        for j in 0..4 {
            k[2 + i][2 + j] += n * h2[i][j] + kb[i][j];
        }
    }
    k
}

/// The Euler–Bernoulli Hermite-cubic element: DOFs (v₁, v₁′, v₂, v₂′). An extensible link uses
/// the von Kármán operators above (element-averaged membrane strain, linear u).
#[derive(Debug, Clone, Copy)]
pub struct HermiteCubic;

impl Element for HermiteCubic {
    fn name(&self) -> &'static str {
        "Hermite-cubic"
    }
    fn description(&self) -> &'static str {
        "Euler–Bernoulli beam (Hermite cubic v"
    }
    fn plan_fields(&self) -> &'static [(&'static str, usize)] {
        &[("transverse v", 1), ("slope v′", 1)]
    }
    fn slope_label(&self) -> &'static str {
        "v′"
    }
    fn interior(&self) -> &'static [InteriorDof] {
        &[]
    }
    fn independent_rotation(&self) -> bool {
        false
    }
    fn gauss_points(&self) -> usize {
        4
    }
    fn sub_gauss_points(&self) -> usize {
        3
    }
    fn shapes(&self, xi: f64, h: f64) -> Shapes {
        let s = hermite(xi, h);
        Shapes::euler_bernoulli(&s.n, &s.dn, &s.ddn)
    }
    fn translates(&self, _a: usize) -> bool {
        true
    }
    fn mass(&self, rho_a: f64, rho_i: f64, h: f64) -> Local {
        pad(&mass(rho_a, rho_i, h))
    }
    fn stiffness(&self, ei: f64, _kga: f64, h: f64) -> Local {
        pad(&bending_stiffness(ei, h))
    }
    fn geometric_stiffness(&self, h: f64, axial_force: &dyn Fn(f64) -> f64) -> Option<Local> {
        Some(pad(&geometric_stiffness(h, axial_force)))
    }
    fn internal_force(
        &self,
        el: &MeshElement,
        u: [f64; 2],
        d: &Row,
        fu: &mut [f64; 2],
        fe: &mut Row,
    ) {
        if el.axial {
            let fv = von_karman_force(el.ea, el.ei, el.h, &[u[0], u[1], d[0], d[1], d[2], d[3]]);
            fu[0] += fv[0];
            fu[1] += fv[1];
            for a in 0..4 {
                fe[a] += fv[2 + a];
            }
        } else {
            linear_internal_force(el, u, d, fu, fe);
        }
    }
    fn tangent(
        &self,
        el: &MeshElement,
        dofs: &ElementDofs,
        u: [f64; 2],
        d: &Row,
        c_q: f64,
        add: &mut dyn FnMut(usize, usize, f64),
    ) {
        if el.axial {
            let kt = von_karman_tangent(el.ea, el.ei, el.h, &[u[0], u[1], d[0], d[1], d[2], d[3]]);
            let dd = &dofs.d;
            let all = [dofs.u[0], dofs.u[1], dd[0], dd[1], dd[2], dd[3]];
            for a in 0..6 {
                for b in 0..6 {
                    if all[a] != NONE && all[b] != NONE {
                        add(all[a], all[b], c_q * kt[a][b]);
                    }
                }
            }
        } else {
            linear_tangent(el, dofs, u, d, c_q, add);
        }
    }
    fn add_strain_energy(&self, el: &MeshElement, u: [f64; 2], d: &Row, strain: &mut f64) {
        if el.axial {
            *strain += von_karman_energy(el.ea, el.ei, el.h, &[u[0], u[1], d[0], d[1], d[2], d[3]]);
        } else {
            linear_strain_energy(el, u, d, strain);
        }
    }
    fn consistent_load(&self, el: &MeshElement, q0: f64) -> Row {
        // ∫q₀N of the Hermite cubics in closed form.
        let h = el.h;
        let mut fq = [0.0; MAXE];
        fq[..4].copy_from_slice(&[
            0.5 * q0 * h,
            q0 * h * h / 12.0,
            0.5 * q0 * h,
            -q0 * h * h / 12.0,
        ]);
        fq
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed_form_mass(rho_a: f64, h: f64) -> Mat4 {
        let c = rho_a * h / 420.0;
        [
            [156.0 * c, 22.0 * h * c, 54.0 * c, -13.0 * h * c],
            [
                22.0 * h * c,
                4.0 * h * h * c,
                13.0 * h * c,
                -3.0 * h * h * c,
            ],
            [54.0 * c, 13.0 * h * c, 156.0 * c, -22.0 * h * c],
            [
                -13.0 * h * c,
                -3.0 * h * h * c,
                -22.0 * h * c,
                4.0 * h * h * c,
            ],
        ]
    }

    fn closed_form_stiffness(ei: f64, h: f64) -> Mat4 {
        let c = ei / (h * h * h);
        [
            [12.0 * c, 6.0 * h * c, -12.0 * c, 6.0 * h * c],
            [6.0 * h * c, 4.0 * h * h * c, -6.0 * h * c, 2.0 * h * h * c],
            [-12.0 * c, -6.0 * h * c, 12.0 * c, -6.0 * h * c],
            [6.0 * h * c, 2.0 * h * h * c, -6.0 * h * c, 4.0 * h * h * c],
        ]
    }

    #[test]
    fn elem_eb_matrices_match_closed_forms_and_are_symmetric() {
        let (rho_a, ei, h) = (0.785, 175.0, 0.0625);
        let m = mass(rho_a, 0.0, h);
        let k = bending_stiffness(ei, h);
        let (mc, kc) = (closed_form_mass(rho_a, h), closed_form_stiffness(ei, h));
        for i in 0..4 {
            for j in 0..4 {
                // Gauss-4 integrates the degree-6 (mass) and degree-2 (stiffness) integrands
                // exactly: only round-off relative to the largest entry.
                assert!((m[i][j] - mc[i][j]).abs() < 1e-14 * mc[0][0]);
                assert!((k[i][j] - kc[i][j]).abs() < 1e-12 * kc[0][0]);
                // Symmetric up to summation-order round-off.
                assert!((m[i][j] - m[j][i]).abs() <= 1e-15 * mc[0][0]);
                assert!((k[i][j] - k[j][i]).abs() <= 1e-15 * kc[0][0]);
            }
        }
    }

    #[test]
    fn elem_eb_total_mass_and_rigid_modes() {
        let (rho_a, ei, h) = (1.2, 1.4e4, 0.37);
        let m = mass(rho_a, 0.0, h);
        // Rigid translation t = (1, 0, 1, 0): tᵀMt = ρA h (total mass).
        let t = [1.0, 0.0, 1.0, 0.0];
        let mt: f64 = (0..4)
            .map(|i| (0..4).map(|j| t[i] * m[i][j] * t[j]).sum::<f64>())
            .sum();
        assert!((mt - rho_a * h).abs() < 1e-14 * rho_a * h);
        // Rigid translation and rotation r = (0, 1, h, 1) lie in the null space of K.
        let k = bending_stiffness(ei, h);
        let r = [0.0, 1.0, h, 1.0];
        for i in 0..4 {
            let kt: f64 = (0..4).map(|j| k[i][j] * t[j]).sum();
            let kr: f64 = (0..4).map(|j| k[i][j] * r[j]).sum();
            // Cancellation of entries of size EI/h³: round-off relative to that.
            assert!(kt.abs() < 1e-12 * ei / h.powi(3));
            assert!(kr.abs() < 1e-12 * ei / h.powi(3));
        }
    }

    #[test]
    fn elem_eb_mass_positive_definite() {
        let m = mass(1.0, 0.0, 0.5);
        // Cholesky succeeds ⇔ SPD.
        let mut l = [[0.0f64; 4]; 4];
        for i in 0..4 {
            for j in 0..=i {
                let s: f64 = m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
                if i == j {
                    assert!(s > 0.0, "mass not positive definite");
                    l[i][j] = s.sqrt();
                } else {
                    l[i][j] = s / l[j][j];
                }
            }
        }
    }

    #[test]
    fn elem_geometric_stiffness_constant_force_closed_form() {
        let (n0, h) = (3.0, 0.25);
        let kg = geometric_stiffness(h, |_| n0);
        // Classic N/(30h)[36, 3h, −36, 3h; 3h, 4h², −3h, −h²; …].
        let c = n0 / (30.0 * h);
        let exact = [
            [36.0 * c, 3.0 * h * c, -36.0 * c, 3.0 * h * c],
            [3.0 * h * c, 4.0 * h * h * c, -3.0 * h * c, -h * h * c],
            [-36.0 * c, -3.0 * h * c, 36.0 * c, -3.0 * h * c],
            [3.0 * h * c, -h * h * c, -3.0 * h * c, 4.0 * h * h * c],
        ];
        for i in 0..4 {
            for j in 0..4 {
                assert!((kg[i][j] - exact[i][j]).abs() < 1e-13 * exact[0][0]);
            }
        }
    }

    #[test]
    fn elem_von_karman_force_is_energy_gradient_and_tangent_is_force_jacobian() {
        let (ea, ei, h) = (2.8e3, 1.4e1, 0.8);
        let d: VkDofs = [0.01, -0.02, 0.05, 0.2, -0.1, -0.3];
        let f = von_karman_force(ea, ei, h, &d);
        let kt = von_karman_tangent(ea, ei, h, &d);
        let eps = 1e-6;
        for k in 0..6 {
            let (mut dp, mut dm) = (d, d);
            dp[k] += eps;
            dm[k] -= eps;
            let g = (von_karman_energy(ea, ei, h, &dp) - von_karman_energy(ea, ei, h, &dm))
                / (2.0 * eps);
            // Central difference: truncation O(ε²·U‴) ≈ 1e-12·EA and round-off
            // U·1e-16/ε ≈ 1e-10·U; 1e-7 relative to the force scale covers both.
            let scale = f.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            assert!((g - f[k]).abs() < 1e-7 * scale, "dof {k}: {g} vs {}", f[k]);
            let fp = von_karman_force(ea, ei, h, &dp);
            let fm = von_karman_force(ea, ei, h, &dm);
            let kscale = kt.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
            for i in 0..6 {
                let fd = (fp[i] - fm[i]) / (2.0 * eps);
                assert!((fd - kt[i][k]).abs() < 1e-7 * kscale, "K[{i}][{k}]");
            }
        }
        for i in 0..6 {
            for j in 0..6 {
                // The tangent of a potential is symmetric.
                assert!((kt[i][j] - kt[j][i]).abs() < 1e-12 * kt[0][0].abs());
            }
        }
    }
}
