//! The free-free eigenfunctions of the constant-(ignition-)mass stepped case.
//!
//! Computed on the fine mesh of [`super::fine_mesh`] as the generalized symmetric-definite
//! problem K φ = ω² M φ, reduced by the Cholesky factor of M (faer has no symmetric-definite
//! generalized solver). The rigid modes (bending: translation and rotation; axial: translation)
//! are the zero eigenvalues and are dropped; the elastic modes kept are M-orthogonal to them,
//! i.e. ∫ m₀ W_k dx = ∫ m₀ x W_k dx = ∫ m₀ U_k dx = 0 (checked in the tests).
//!
//! Normalization: each eigenfunction has unit value at the nose, φ_k(L) = 1 (a free end, never a
//! node), so the modal coordinates are nose displacements in length units. That keeps the
//! integrator's absolute tolerance meaningful.

use super::body::Body;
use super::eig::lowest_eigenpairs_refined;
use super::error::RocketError;
use super::fine_mesh::{FineMesh, axial_matrices, bending_matrices, hermite, lagrange2};

/// Which field a set of eigenfunctions describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    Axial,
    Bending,
}

impl Field {
    fn name(self) -> &'static str {
        match self {
            Field::Axial => "axial",
            Field::Bending => "bending",
        }
    }
    /// Number of rigid-body (zero-frequency) modes of the free-free field.
    pub fn rigid_modes(self) -> usize {
        match self {
            Field::Axial => 1,
            Field::Bending => 2,
        }
    }
}

/// Elastic eigenfunctions of one field on the fine mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeSet {
    pub field: Field,
    /// Circular frequencies ω_k [rad/s] of the constant-mass beam, ascending.
    pub omega: Vec<f64>,
    /// Nodal vectors, `coeffs[k]` of length `mesh.bending_dofs()` or `mesh.axial_dofs()`.
    pub coeffs: Vec<Vec<f64>>,
    /// Smallest rigid-mode eigenvalue magnitude relative to the first elastic one (diagnostic).
    pub rigid_gap: f64,
}

impl ModeSet {
    pub fn count(&self) -> usize {
        self.omega.len()
    }

    /// (φ_k, φ_k', φ_k'') at station x.
    pub fn eval(&self, mesh: &FineMesh, k: usize, x: f64) -> (f64, f64, f64) {
        let (e, s) = mesh.locate(x);
        let el = &mesh.elements[e];
        let c = &self.coeffs[k];
        match self.field {
            Field::Bending => {
                let (n, d, dd) = hermite(s, el.h);
                let map = FineMesh::bending_map(e);
                let mut out = (0.0, 0.0, 0.0);
                for a in 0..4 {
                    out.0 += n[a] * c[map[a]];
                    out.1 += d[a] * c[map[a]];
                    out.2 += dd[a] * c[map[a]];
                }
                out
            }
            Field::Axial => {
                let (n, d) = lagrange2(s, el.h);
                let map = FineMesh::axial_map(e);
                let mut out = (0.0, 0.0, 0.0);
                for a in 0..3 {
                    out.0 += n[a] * c[map[a]];
                    out.1 += d[a] * c[map[a]];
                }
                out
            }
        }
    }

    /// Values and first derivatives of every mode on element e at local s (used to tabulate).
    pub fn eval_element(&self, mesh: &FineMesh, e: usize, s: f64, val: &mut [f64], d1: &mut [f64]) {
        let el = &mesh.elements[e];
        match self.field {
            Field::Bending => {
                let (n, d, _) = hermite(s, el.h);
                let map = FineMesh::bending_map(e);
                for (k, c) in self.coeffs.iter().enumerate() {
                    val[k] = (0..4).map(|a| n[a] * c[map[a]]).sum();
                    d1[k] = (0..4).map(|a| d[a] * c[map[a]]).sum();
                }
            }
            Field::Axial => {
                let (n, d) = lagrange2(s, el.h);
                let map = FineMesh::axial_map(e);
                for (k, c) in self.coeffs.iter().enumerate() {
                    val[k] = (0..3).map(|a| n[a] * c[map[a]]).sum();
                    d1[k] = (0..3).map(|a| d[a] * c[map[a]]).sum();
                }
            }
        }
    }
}

/// Number of fine-mesh elements used for `modes` eigenfunctions per field: about 16 elements per
/// half-wave of the highest mode kept (Hermite cubic eigenvalue error ≈ (βh)⁴/720 ≲ 1e-5), at
/// least 96, at most 480 (the dense eigen-solution costs ~(2·elements)³).
pub fn fine_elements(modes: usize) -> usize {
    (16 * (modes + 2)).clamp(96, 480)
}

/// First elastic eigenvalue of a uniform free-free beam with the length-averaged properties:
/// the shift of the shift-invert eigen-solution (only its order of magnitude matters).
fn shift_estimate(mesh: &FineMesh, field: Field) -> f64 {
    let l = mesh.length;
    let avg = |f: fn(&super::fine_mesh::Element) -> f64| {
        mesh.elements.iter().map(|e| f(e) * e.h).sum::<f64>() / l
    };
    let m = avg(|e| e.mass0);
    match field {
        Field::Bending => (4.73 / l).powi(4) * avg(|e| e.ei) / m,
        Field::Axial => (std::f64::consts::PI / l).powi(2) * avg(|e| e.ea) / m,
    }
}

/// Computes the first `count` elastic modes of `field` for the constant-mass case on `mesh`.
pub fn elastic_modes(mesh: &FineMesh, field: Field, count: usize) -> Result<ModeSet, RocketError> {
    let (k, m, n) = match field {
        Field::Bending => bending_matrices(mesh),
        Field::Axial => axial_matrices(mesh),
    };
    let rigid = field.rigid_modes();
    if count + rigid > n {
        return Err(RocketError::Basis {
            field: field.name(),
            message: format!("{count} modes requested but the fine mesh has only {n} DOFs"),
        });
    }
    let sigma = shift_estimate(mesh, field);
    let (lam, x) =
        lowest_eigenpairs_refined(&k, &m, n, sigma, rigid + count).map_err(|message| {
            RocketError::Basis {
                field: field.name(),
                message,
            }
        })?;
    let first_elastic = lam[rigid];
    let rigid_gap = (0..rigid)
        .map(|i| lam[i].abs() / first_elastic)
        .fold(0.0f64, f64::max);
    // With the shift-invert solution the rigid eigenvalues are zero up to ~eps·σ; the gap to the
    // first elastic one must be many orders of magnitude, or the rigid/elastic split is not clean.
    if first_elastic.is_nan() || first_elastic <= 0.0 || rigid_gap > 1e-6 {
        return Err(RocketError::Basis {
            field: field.name(),
            message: format!(
                "rigid modes not separated: |λ_rigid|/λ_elastic = {rigid_gap:.3e}, λ₁ = {first_elastic:.3e}"
            ),
        });
    }
    let nose = match field {
        Field::Bending => n - 2,
        Field::Axial => n - 1,
    };
    let mut omega = Vec::with_capacity(count);
    let mut coeffs = Vec::with_capacity(count);
    for j in rigid..rigid + count {
        omega.push(lam[j].max(0.0).sqrt());
        let scale = x[(nose, j)];
        if scale.abs() < 1e-300 {
            return Err(RocketError::Basis {
                field: field.name(),
                message: format!("mode {} has a node at the free nose", j - rigid + 1),
            });
        }
        coeffs.push((0..n).map(|i| x[(i, j)] / scale).collect());
    }
    Ok(ModeSet {
        field,
        omega,
        coeffs,
        rigid_gap,
    })
}

/// The full basis: axial and bending eigenfunctions on one fine mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Basis {
    pub mesh: FineMesh,
    pub axial: ModeSet,
    pub bending: ModeSet,
}

impl Basis {
    pub fn new(body: &Body, modes: usize) -> Result<Basis, RocketError> {
        let mesh = FineMesh::new(body, fine_elements(modes));
        let axial = elastic_modes(&mesh, Field::Axial, modes)?;
        let bending = elastic_modes(&mesh, Field::Bending, modes)?;
        Ok(Basis {
            mesh,
            axial,
            bending,
        })
    }

    pub fn modes(&self) -> usize {
        self.axial.count()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::rocket::body::{Body, Segment};
    use crate::rocket::integrals::QuadTable;
    use data::scene::InitialShape;

    /// A body of uniform stages only (no burn, no masses) for basis tests.
    pub(crate) fn stepped_body(stages: &[(f64, f64, f64, f64)]) -> Body {
        let mut x = 0.0;
        let segments = stages
            .iter()
            .map(|&(len, ea, ei, m)| {
                let s = Segment {
                    x0: x,
                    x1: x + len,
                    ea,
                    ei,
                    mass0: m,
                };
                x += len;
                s
            })
            .collect();
        Body {
            length: x,
            segments,
            burn: None,
            gravity: 1.0,
            launch_angle: 0.0,
            exhaust_velocity: 0.0,
            pressure_force: 0.0,
            nozzle_angle: 0.0,
            masses: vec![],
            couplings: vec![],
            initial_shape: InitialShape::Straight,
        }
    }

    /// k-th positive root of cos x cosh x = 1 (free-free beam), by bisection to 1e-14 on
    /// f(x) = cos x − 1/cosh x, which has exactly one root in (kπ, (k+1)π) for k ≥ 1.
    fn free_free_root(k: usize) -> f64 {
        let f = |x: f64| x.cos() - 1.0 / x.cosh();
        let (mut lo, mut hi) = (k as f64 * PI, (k as f64 + 1.0) * PI);
        let flo = f(lo);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (f(mid) > 0.0) == (flo > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-14 {
                break;
            }
        }
        0.5 * (lo + hi)
    }
    use std::f64::consts::PI;

    #[test]
    fn sys_uniform_free_free_bending_roots() {
        // uniform beam L = 2, EI = 3, m = 1.5: ω_k = (β_k L)² / L² · sqrt(EI/m)
        let (l, ei, m) = (2.0, 3.0, 1.5);
        let body = stepped_body(&[(l, 1.0, ei, m)]);
        let mesh = FineMesh::new(&body, fine_elements(6));
        let set = elastic_modes(&mesh, Field::Bending, 6).unwrap();
        let root1 = free_free_root(1);
        assert!(
            (root1 - 4.730040744862704).abs() < 1e-9,
            "reference root itself"
        );
        let h = l / mesh.elements.len() as f64;
        for k in 0..6 {
            let beta_l = (set.omega[k] * (m / ei).sqrt()).sqrt() * l;
            let exact = free_free_root(k + 1);
            let rel = (beta_l - exact).abs() / exact;
            // Hermite cubic, consistent mass: λ error ≈ (βh)⁴/720, so βL error ≈ (βh)⁴/2880
            // (observed to match this leading term); 25 % for the next term, plus the
            // eigen-solver round-off (1e-11)
            let tol = 1.25 * (exact * h / l).powi(4) / 2880.0 + 1e-11;
            eprintln!(
                "mode {}: βL rel error {rel:.3e} (tolerance {tol:.3e})",
                k + 1
            );
            assert!(
                rel < tol,
                "mode {}: βL = {beta_l}, exact {exact}, rel {rel:e}",
                k + 1
            );
        }
        // rigid modes separated by many orders of magnitude
        eprintln!("rigid gap {:e}", set.rigid_gap);
        assert!(set.rigid_gap < 1e-8, "rigid gap {}", set.rigid_gap);
    }

    #[test]
    fn sys_uniform_free_free_axial_frequencies() {
        let (l, ea, m) = (3.0, 5.0, 2.0);
        let body = stepped_body(&[(l, ea, 1.0, m)]);
        let mesh = FineMesh::new(&body, fine_elements(6));
        let set = elastic_modes(&mesh, Field::Axial, 6).unwrap();
        let h = l / mesh.elements.len() as f64;
        for k in 0..6 {
            let exact = (k + 1) as f64 * PI / l * (ea / m).sqrt();
            let rel = (set.omega[k] - exact).abs() / exact;
            // quadratic Lagrange, consistent mass: ω error ≈ (kh)⁴/1440 with kh = (k+1)πh/L
            // (observed to match this leading term); 25 % for the next term plus round-off
            let kh = (k + 1) as f64 * PI * h / l;
            let tol = 1.25 * kh.powi(4) / 1440.0 + 1e-11;
            eprintln!(
                "axial mode {}: rel error {rel:.3e} (tolerance {tol:.3e})",
                k + 1
            );
            assert!(rel < tol, "axial mode {}: rel {rel:e}", k + 1);
        }
    }

    #[test]
    fn conv_bending_frequency_error_is_fourth_order() {
        // Hermite cubic: error in ω ∝ h⁴. Observed order from 12 → 24 elements on mode 3.
        let (l, ei, m) = (1.0, 1.0, 1.0);
        let body = stepped_body(&[(l, 1.0, ei, m)]);
        let exact = free_free_root(3).powi(2);
        let err = |ne: usize| {
            let mesh = FineMesh::new(&body, ne);
            (elastic_modes(&mesh, Field::Bending, 3).unwrap().omega[2] - exact).abs() / exact
        };
        let (e1, e2) = (err(12), err(24));
        let order = (e1 / e2).log2();
        // theory 4; asymptotic regime reached at these meshes (βh ≤ 0.9)
        assert!((order - 4.0).abs() < 0.3, "observed order {order}");
    }

    #[test]
    fn sys_stepped_modes_orthogonal_to_rigid_and_each_other() {
        let body = stepped_body(&[
            (100.0, 2.259e8, 2.79e9, 0.011),
            (50.0, 1.5e8, 1.5e9, 0.0078),
        ]);
        let basis = Basis::new(&body, 8).unwrap();
        let t = QuadTable::new(&basis, 4);
        let m0 = t.moments(|g, _| basis.mesh.elements[t.element[g]].mass0);
        let n = 8;
        for k in 0..n {
            let mu = m0.uu[k * n + k];
            let mw = m0.ww[k * n + k];
            // rigid orthogonality relative to the natural scale ∫m₀|φ| L: round-off of the
            // dense eigen-solver (~eps·cond ≈ 1e-9)
            let scale_u = (mu * m0.total).sqrt();
            let scale_w = (mw * m0.total).sqrt();
            assert!(m0.u[k].abs() < 1e-8 * scale_u, "∫m0 U_{k} = {}", m0.u[k]);
            assert!(m0.w[k].abs() < 1e-8 * scale_w, "∫m0 W_{k} = {}", m0.w[k]);
            assert!(m0.xw[k].abs() < 1e-8 * scale_w * body.length, "∫m0 x W_{k}");
            for l in 0..n {
                if l != k {
                    let cu = m0.uu[k * n + l] / (mu * m0.uu[l * n + l]).sqrt();
                    let cw = m0.ww[k * n + l] / (mw * m0.ww[l * n + l]).sqrt();
                    assert!(
                        cu.abs() < 1e-9 && cw.abs() < 1e-9,
                        "({k},{l}): {cu:e} {cw:e}"
                    );
                }
            }
            // unit nose value
            let (wl, _, _) = basis.bending.eval(&basis.mesh, k, body.length);
            let (ul, _, _) = basis.axial.eval(&basis.mesh, k, body.length);
            assert!((wl - 1.0).abs() < 1e-12 && (ul - 1.0).abs() < 1e-12);
        }
        // stiffness is diagonal in the eigenbasis with K_kk = ω_k² M_kk
        let (ka, kb) = t.stiffness(&basis);
        for k in 0..n {
            let wa = basis.axial.omega[k];
            let wb = basis.bending.omega[k];
            let ea = (ka[k * n + k] - wa * wa * m0.uu[k * n + k]).abs() / ka[k * n + k];
            let eb = (kb[k * n + k] - wb * wb * m0.ww[k * n + k]).abs() / kb[k * n + k];
            eprintln!("mode {k}: Rayleigh quotient vs eigenvalue: axial {ea:e}, bending {eb:e}");
            assert!(ea < 1e-9 && eb < 1e-9);
            for l in 0..n {
                if l != k {
                    assert!(kb[k * n + l].abs() < 1e-9 * (kb[k * n + k] * kb[l * n + l]).sqrt());
                    assert!(ka[k * n + l].abs() < 1e-9 * (ka[k * n + k] * ka[l * n + l]).sqrt());
                }
            }
        }
    }

    #[test]
    fn sys_stepped_bending_shapes_satisfy_junction_conditions() {
        // Across a stage step: w, w' continuous (built in), and the bending moment EI w''
        // continuous (natural condition, satisfied only as the mesh converges).
        let body = stepped_body(&[(100.0, 1.0, 2.79e9, 0.011), (50.0, 1.0, 1.5e9, 0.0078)]);
        let basis = Basis::new(&body, 4).unwrap();
        let mesh = &basis.mesh;
        // element just left / right of x = 100
        let (el, _) = mesh.locate(100.0 - 1e-9);
        let (er, _) = mesh.locate(100.0 + 1e-9);
        assert_eq!(er, el + 1);
        for k in 0..4 {
            let c = &basis.bending.coeffs[k];
            let moment = |e: usize, s: f64| {
                let elm = &mesh.elements[e];
                let (_, _, dd) = hermite(s, elm.h);
                let map = FineMesh::bending_map(e);
                elm.ei * (0..4).map(|a| dd[a] * c[map[a]]).sum::<f64>()
            };
            let (ml, mr) = (moment(el, 1.0), moment(er, 0.0));
            let peak = (0..mesh.elements.len())
                .map(|e| moment(e, 0.5).abs())
                .fold(0.0, f64::max);
            // FE moments are discontinuous at O(h²) relative to the peak: h = 0.78, βh ≲ 0.2
            assert!(
                (ml - mr).abs() < 2e-2 * peak,
                "mode {k}: {ml} vs {mr}, peak {peak}"
            );
        }
    }
}
