//! Timoshenko beam element: cubic deflection, quadratic rotation (mixed-order Lagrange, "C3Q2").
//!
//! Fields: transverse deflection v and section rotation θ; shear strain γ = v′ − θ, curvature θ′.
//! Energies U = ½∫EI θ′² + ½∫κGA (v′ − θ)², T = ½∫ρA v̇² + ½∫ρI θ̇².
//!
//! Interpolation on ξ = x/h ∈ [0, 1]: v is the cubic Lagrange interpolant through ξ = 0, ⅓, ⅔, 1,
//! θ the quadratic through ξ = 0, ½, 1. Local DOFs
//! (v₁, θ₁, v₂, θ₂, v(⅓), v(⅔), θ(½)): the first four are the nodal DOFs shared with the
//! neighbours, the last three are element-interior DOFs that the assembly keeps as global DOFs
//! (no static condensation: condensing with K alone would be wrong for the mass, i.e. for modes).
//!
//! Why this pair: v′ and θ are both quadratic, so the Kirchhoff constraint v′ = θ can hold
//! pointwise. The constrained subspace is exactly the C¹ piecewise cubics, so the element does
//! not lock and tends to the Hermite cubic as κGA → ∞. Full Gauss integration (4 points: exact for
//! the degree-6 mass and degree-4 shear integrands) keeps the stiffness the exact energy. The
//! element contains the exact static solution under end loads (v cubic, θ quadratic), hence a
//! tip-loaded cantilever is exact, and eigenvalue errors fall as O(h⁴) (energy error O(h²) in
//! θ′ and γ), unlike the interdependent-interpolation element (IIE), whose constant shear strain
//! cannot follow the linearly varying shear force of a vibrating element and converges at O(h²).

use super::contract::{Element, InteriorDof, InteriorField, Local, Shapes};
use super::quadrature::gauss01;

/// Number of local DOFs of one element.
pub const NDOF: usize = 7;
/// Element-interior DOFs (v(⅓), v(⅔), θ(½)).
pub const INTERIOR: usize = 3;

/// Element matrix (row-major) in the local DOF order above.
pub type Mat7 = [[f64; NDOF]; NDOF];

/// Shape functions of every local DOF at one point: v, v′, θ, θ′ (x-derivatives).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TimoshenkoAt {
    pub v: [f64; NDOF],
    pub dv: [f64; NDOF],
    pub th: [f64; NDOF],
    pub dth: [f64; NDOF],
}

/// Lagrange basis through `nodes` at ξ: values and ξ-derivatives.
fn lagrange<const N: usize>(nodes: &[f64; N], xi: f64) -> ([f64; N], [f64; N]) {
    let mut l = [0.0; N];
    let mut dl = [0.0; N];
    for i in 0..N {
        let mut den = 1.0;
        for j in 0..N {
            if j != i {
                den *= nodes[i] - nodes[j];
            }
        }
        let mut val = 1.0;
        for j in 0..N {
            if j != i {
                val *= xi - nodes[j];
            }
        }
        // d/dξ Π(ξ − ξⱼ) = Σₖ Π_{j≠k}(ξ − ξⱼ).
        let mut der = 0.0;
        for k in 0..N {
            if k == i {
                continue;
            }
            let mut p = 1.0;
            for j in 0..N {
                if j != i && j != k {
                    p *= xi - nodes[j];
                }
            }
            der += p;
        }
        l[i] = val / den;
        dl[i] = der / den;
    }
    (l, dl)
}

/// Evaluates the shape functions on an element of length `h` at local coordinate `xi`.
pub fn shapes(xi: f64, h: f64) -> TimoshenkoAt {
    const V_NODES: [f64; 4] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];
    const T_NODES: [f64; 3] = [0.0, 0.5, 1.0];
    // Local DOF carried by each Lagrange node.
    const V_DOF: [usize; 4] = [0, 4, 5, 2];
    const T_DOF: [usize; 3] = [1, 6, 3];
    let (lv, dlv) = lagrange(&V_NODES, xi);
    let (lt, dlt) = lagrange(&T_NODES, xi);
    let mut s = TimoshenkoAt::default();
    for (k, &d) in V_DOF.iter().enumerate() {
        s.v[d] = lv[k];
        s.dv[d] = dlv[k] / h;
    }
    for (k, &d) in T_DOF.iter().enumerate() {
        s.th[d] = lt[k];
        s.dth[d] = dlt[k] / h;
    }
    s
}

/// Stiffness ∫EI θ′ᵢθ′ⱼ + κGA γᵢγⱼ, γ = v′ − θ (exact: integrands of degree ≤ 4).
pub fn stiffness(ei: f64, kga: f64, h: f64) -> Mat7 {
    let (p, w) = gauss01(4);
    let mut k = [[0.0; NDOF]; NDOF];
    for (xi, wg) in p.iter().zip(w) {
        let s = shapes(*xi, h);
        for i in 0..NDOF {
            let gi = s.dv[i] - s.th[i];
            for j in 0..NDOF {
                let gj = s.dv[j] - s.th[j];
                k[i][j] += wg * h * (ei * s.dth[i] * s.dth[j] + kga * gi * gj);
            }
        }
    }
    k
}

/// Consistent mass ∫ρA vᵢvⱼ + ρI θᵢθⱼ (exact: integrands of degree ≤ 6).
pub fn mass(rho_a: f64, rho_i: f64, h: f64) -> Mat7 {
    let (p, w) = gauss01(4);
    let mut m = [[0.0; NDOF]; NDOF];
    for (xi, wg) in p.iter().zip(w) {
        let s = shapes(*xi, h);
        for i in 0..NDOF {
            for j in 0..NDOF {
                m[i][j] += wg * h * (rho_a * s.v[i] * s.v[j] + rho_i * s.th[i] * s.th[j]);
            }
        }
    }
    m
}

/// The Timoshenko element (cubic v, quadratic θ), DOFs (v₁, θ₁, v₂, θ₂, v(⅓), v(⅔), θ(½)).
#[derive(Debug, Clone, Copy)]
pub struct Timoshenko;

impl Element for Timoshenko {
    fn name(&self) -> &'static str {
        "Timoshenko"
    }
    fn description(&self) -> &'static str {
        "Timoshenko beam (cubic v, quadratic θ, interior DOFs global"
    }
    fn plan_fields(&self) -> &'static [(&'static str, usize)] {
        // Nodal v plus v(⅓), v(⅔) per element; nodal θ plus θ(½).
        &[("transverse v", 3), ("section rotation θ", 2)]
    }
    fn slope_label(&self) -> &'static str {
        "ψ"
    }
    fn interior(&self) -> &'static [InteriorDof] {
        &[
            InteriorDof {
                field: InteriorField::Deflection,
                label: "v",
                at: 1.0 / 3.0,
            },
            InteriorDof {
                field: InteriorField::Deflection,
                label: "v",
                at: 2.0 / 3.0,
            },
            InteriorDof {
                field: InteriorField::Rotation,
                label: "ψ",
                at: 0.5,
            },
        ]
    }
    fn independent_rotation(&self) -> bool {
        true
    }
    fn gauss_points(&self) -> usize {
        4
    }
    fn sub_gauss_points(&self) -> usize {
        3
    }
    fn shapes(&self, xi: f64, h: f64) -> Shapes {
        let s = shapes(xi, h);
        Shapes {
            n: s.v,
            dn: s.dv,
            b: s.th,
            db: s.dth,
        }
    }
    fn translates(&self, a: usize) -> bool {
        // θ₁, θ₂, θ(½) turn sections only.
        !(a == 1 || a == 3 || a == 6)
    }
    fn mass(&self, rho_a: f64, rho_i: f64, h: f64) -> Local {
        mass(rho_a, rho_i, h)
    }
    fn stiffness(&self, ei: f64, kga: f64, h: f64) -> Local {
        stiffness(ei, kga, h)
    }
    fn geometric_stiffness(&self, _h: f64, _axial_force: &dyn Fn(f64) -> f64) -> Option<Local> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::euler_bernoulli;

    fn quad(a: &Mat7, x: &[f64; NDOF], y: &[f64; NDOF]) -> f64 {
        (0..NDOF)
            .map(|i| (0..NDOF).map(|j| x[i] * a[i][j] * y[j]).sum::<f64>())
            .sum()
    }

    /// Eigenvalues of a symmetric 7×7 matrix, ascending (faer's self-adjoint solver).
    fn sym_eigenvalues(a: Mat7) -> [f64; NDOF] {
        let m = faer::Mat::from_fn(NDOF, NDOF, |i, j| a[i][j]);
        let ev = m
            .self_adjoint_eigenvalues(faer::Side::Lower)
            .expect("symmetric eigenvalues");
        std::array::from_fn(|i| ev[i])
    }

    #[test]
    fn elem_timoshenko_shapes_interpolate_and_reproduce_polynomials() {
        let h = 0.4;
        // v = cubic, θ = quadratic: nodal values reproduce them and their derivatives exactly.
        let v = |x: f64| 0.3 - 1.1 * x + 2.0 * x * x - 0.7 * x.powi(3);
        let dv = |x: f64| -1.1 + 4.0 * x - 2.1 * x * x;
        let t = |x: f64| 0.9 + 0.5 * x - 1.3 * x * x;
        let dt = |x: f64| 0.5 - 2.6 * x;
        let d = [
            v(0.0),
            t(0.0),
            v(h),
            t(h),
            v(h / 3.0),
            v(2.0 * h / 3.0),
            t(0.5 * h),
        ];
        for k in 0..=10 {
            let xi = k as f64 / 10.0;
            let s = shapes(xi, h);
            let dot = |a: &[f64; NDOF]| (0..NDOF).map(|i| a[i] * d[i]).sum::<f64>();
            let x = xi * h;
            // Exact reproduction: round-off only.
            assert!((dot(&s.v) - v(x)).abs() < 1e-14);
            assert!((dot(&s.dv) - dv(x)).abs() < 1e-13);
            assert!((dot(&s.th) - t(x)).abs() < 1e-14);
            assert!((dot(&s.dth) - dt(x)).abs() < 1e-13);
        }
    }

    #[test]
    fn elem_timoshenko_matrices_symmetric_total_mass_and_two_rigid_modes() {
        let (ei, kga, rho_a, rho_i, h) = (175.0, 6.73e6, 0.785, 2.0e-4, 0.02);
        let k = stiffness(ei, kga, h);
        let m = mass(rho_a, rho_i, h);
        let kmax = k.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
        let mmax = m.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
        for i in 0..NDOF {
            for j in 0..NDOF {
                assert!((k[i][j] - k[j][i]).abs() <= 1e-15 * kmax);
                assert!((m[i][j] - m[j][i]).abs() <= 1e-15 * mmax);
            }
        }
        // Rigid translation v = 1, θ = 0 and rotation v = x, θ = 1.
        let t = [1.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0];
        let r = [0.0, 1.0, h, 1.0, h / 3.0, 2.0 * h / 3.0, 1.0];
        // tᵀMt = ρA h: total mass of the element.
        assert!((quad(&m, &t, &t) - rho_a * h).abs() < 1e-14 * rho_a * h);
        for mode in [t, r] {
            for row in &k {
                let f: f64 = (0..NDOF).map(|j| row[j] * mode[j]).sum();
                // Cancellation among entries of size ≤ kmax: round-off relative to it.
                assert!(f.abs() < 1e-12 * kmax);
            }
        }
        // Positive semidefinite with exactly two zero eigenvalues: the rigid modes. The
        // scale-free test uses the eigenvalues of the (dimensionless) matrix normalized by its
        // largest one: the third must be clearly positive.
        let mut kn = k;
        kn.iter_mut().flatten().for_each(|x| *x /= kmax);
        let ev = sym_eigenvalues(kn);
        assert!(ev[0].abs() < 1e-12 && ev[1].abs() < 1e-12, "{ev:?}");
        assert!(ev[2] > 1e-8, "third eigenvalue {ev:?}");
        // The mass is positive definite (ρA > 0, ρI > 0).
        let mut mn = m;
        mn.iter_mut().flatten().for_each(|x| *x /= mmax);
        assert!(sym_eigenvalues(mn)[0] > 1e-6);
    }

    #[test]
    fn elem_timoshenko_thin_limit_energies_approach_hermite_cubic() {
        // κGA → ∞: minimizing the shear energy over the interior DOFs for given nodal (v, v′)
        // must give the Hermite-cubic bending energy: no locking. Check on the static
        // condensation of K (a statics-only operation; the assembly never condenses).
        let (ei, h) = (175.0, 0.05);
        let kb = euler_bernoulli::bending_stiffness(ei, h);
        for (kga_scale, tol) in [(1e4, 2e-3), (1e6, 2e-5), (1e8, 2e-7)] {
            let kga = kga_scale * ei / (h * h);
            let k = stiffness(ei, kga, h);
            let c = condense(&k);
            for i in 0..4 {
                for j in 0..4 {
                    // Relative deviation O(EI/(κGA h²)) = 1/scale.
                    assert!(
                        (c[i][j] - kb[i][j]).abs() < tol * kb[0][0],
                        "scale {kga_scale}: K{i}{j} {} vs {}",
                        c[i][j],
                        kb[i][j]
                    );
                }
            }
        }
    }

    /// Schur complement of the interior block: K_nn − K_ni K_ii⁻¹ K_in (3×3 Gauss elimination).
    fn condense(k: &Mat7) -> [[f64; 4]; 4] {
        let mut a = *k;
        for p in 4..NDOF {
            for r in 0..NDOF {
                if r == p {
                    continue;
                }
                let f = a[r][p] / a[p][p];
                for c in 0..NDOF {
                    a[r][c] -= f * a[p][c];
                }
            }
        }
        let mut out = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                out[i][j] = a[i][j];
            }
        }
        out
    }
}
