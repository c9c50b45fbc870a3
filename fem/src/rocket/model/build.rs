//! Building the rocket [`Model`] in named phases: refusals of what the model does not cover,
//! the quadrature points (4-point Gauss on each part of an element between stage junctions),
//! the constant operators integrated on them, the discrete masses and their couplings, the
//! reference and rigid-translation vectors, and the mean-axis functionals.

use std::collections::BTreeMap;

use data::scene::Rocket;

use super::{
    Attached, Coupling, DOFS_PER_NODE, Model, Quad, Triplets, dofs_of, mesh_point, slopes,
};
use crate::element::quadrature::gauss01;
use crate::element::{Shapes, bar_shapes, hermite_cubic};
use crate::error::FemError;

/// The constant operators before conversion to triplets: the burning stage's unit mass, the
/// non-burning mass, the beam stiffness, and the jet-Coriolis load vectors.
struct Operators {
    mb: BTreeMap<(usize, usize), f64>,
    mf: BTreeMap<(usize, usize), f64>,
    kb: BTreeMap<(usize, usize), f64>,
    cor_u: Vec<f64>,
    cor_w: Vec<f64>,
}

/// Reference positions x_ref and the unit translations along ξ and η, of the whole body and
/// of the case only (the mean axis weights the case alone).
struct Reference {
    x_ref: Vec<f64>,
    t_xi: Vec<f64>,
    t_eta: Vec<f64>,
    t_xi_case: Vec<f64>,
    t_eta_case: Vec<f64>,
}

impl Model {
    pub fn new(r: &Rocket, elements: usize) -> Result<Self, FemError> {
        refuse_unsupported(r)?;
        let g = r.gravity;
        let length = r.length();
        let h = length / elements as f64;
        let nodes = elements + 1;
        let nm = r.discrete_masses.len();
        let n = DOFS_PER_NODE * nodes + 2 * nm;
        let l1 = r.stages[0].length;
        let quad = quadrature_points(r, elements, h);
        let ops = integrate_operators(&quad, h, l1, n);
        let masses = discrete_masses(r, elements, h)?;
        let couplings = mass_couplings(r, nm)?;
        refuse_free_masses(&masses, &couplings)?;
        let rf = reference_vectors(nodes, h, &masses, n);
        let s1 = &r.stages[0];
        let m1_0 = s1.weight_per_length / g;
        let m1_casing = s1.casing_weight_per_length.unwrap_or(0.0) / g;
        let mut model = Model {
            elements,
            nodes,
            n,
            h,
            length,
            l1,
            theta0: r.launch_angle_deg.to_radians(),
            g,
            gamma: r.nozzle_angle_deg.to_radians(),
            m1_0,
            m1_casing,
            burn_rate: s1.burn_rate / g,
            exhaust_velocity: r.exhaust_velocity,
            pressure_force: r.chamber_pressure * r.port_area,
            m_burn: Triplets::from_map(ops.mb),
            m_fixed: Triplets::from_map(ops.mf),
            k_beam: Triplets::from_map(ops.kb),
            quad,
            masses,
            couplings,
            pressure_point: mesh_point(l1, h, elements),
            x_ref: rf.x_ref,
            t_xi: rf.t_xi,
            t_eta: rf.t_eta,
            m0: 0.0,
            x_bar: 0.0,
            a_c_xi: Vec::new(),
            a_c_eta: Vec::new(),
            a_s_xi: Vec::new(),
            a_s_eta: Vec::new(),
            b_s_xi: Vec::new(),
            b_s_eta: Vec::new(),
            cor_u: ops.cor_u,
            cor_w: ops.cor_w,
        };
        model.set_mean_axis_functionals(&rf.t_xi_case, &rf.t_eta_case);
        Ok(model)
    }

    /// The mean-axis functionals with the case's ignition mass M₀ (discrete masses excluded):
    /// m₀ = t_ξᵀM₀t_ξ, x̄ = (M₀t_ξ)·x_ref/m₀, a_c = M₀t/m₀ (centroid), a_s = M₀ℓ with ℓ the
    /// linear field (x − x̄) (first moments); and the whole body's b_s about its centroid x̄_b,
    /// b_s·R = a_s·R + m₀(x̄ − x̄_b)c + Σ_j M_j(x_j − x̄_b)R_j.
    fn set_mean_axis_functionals(&mut self, t_xi_case: &[f64], t_eta_case: &[f64]) {
        let (n, nodes, h) = (self.n, self.nodes, self.h);
        let m0_apply = |m: &Model, x: &[f64]| {
            let mut y = vec![0.0; n];
            m.m_fixed.mul_add(1.0, x, &mut y);
            m.m_burn.mul_add(m.m1_0, x, &mut y);
            y
        };
        let a_xi = m0_apply(self, t_xi_case);
        let a_eta = m0_apply(self, t_eta_case);
        let m0 = crate::linalg::dot(&a_xi, t_xi_case);
        let x_bar = crate::linalg::dot(&a_xi, &self.x_ref) / m0;
        let mut lin_u = vec![0.0; n];
        let mut lin_w = vec![0.0; n];
        for i in 0..nodes {
            lin_u[DOFS_PER_NODE * i] = i as f64 * h - x_bar;
            lin_w[DOFS_PER_NODE * i + 1] = i as f64 * h - x_bar;
            lin_w[DOFS_PER_NODE * i + 2] = 1.0;
        }
        self.a_s_xi = m0_apply(self, &lin_u);
        self.a_s_eta = m0_apply(self, &lin_w);
        let masses_total: f64 = self.masses.iter().map(|m| m.mass).sum();
        let x_body = (m0 * x_bar + self.masses.iter().map(|m| m.mass * m.at.x).sum::<f64>())
            / (m0 + masses_total);
        let shift = |a_s: &[f64], a_total: &[f64]| -> Vec<f64> {
            a_s.iter()
                .zip(a_total)
                .map(|(s, t)| s + (x_bar - x_body) * t)
                .collect()
        };
        self.b_s_xi = shift(&self.a_s_xi, &a_xi);
        self.b_s_eta = shift(&self.a_s_eta, &a_eta);
        for j in 0..self.masses.len() {
            let (iu, iw) = self.mass_dofs(j);
            let moment = self.masses[j].mass * (self.masses[j].at.x - x_body);
            self.b_s_xi[iu] += moment;
            self.b_s_eta[iw] += moment;
        }
        self.a_c_xi = a_xi.iter().map(|v| v / m0).collect();
        self.a_c_eta = a_eta.iter().map(|v| v / m0).collect();
        self.m0 = m0;
        self.x_bar = x_bar;
    }
}

/// Refuses a rocket without stages, a non-zero exit pressure (the report's vacuum expansion,
/// eq. 5.16, assumes p_e = 0) and a burning upper stage.
fn refuse_unsupported(r: &Rocket) -> Result<(), FemError> {
    if r.stages.is_empty() {
        return Err(FemError::unsupported("rocket without stages"));
    }
    if r.exit_pressure != 0.0 {
        return Err(FemError::unsupported(
            "rocket exit pressure p_e ≠ 0 (the report's vacuum expansion, eq. 5.16, assumes p_e = 0)",
        ));
    }
    if r.stages.iter().skip(1).any(|s| s.burn_rate != 0.0) {
        return Err(FemError::unsupported(
            "rocket: only the first (aft) stage may burn",
        ));
    }
    Ok(())
}

/// 4-point Gauss points on each part of each element between stage junctions, with the
/// stage's section (EA, EI) and non-burning mass per length (the burning stage 0 carries its
/// mass through m₁(t)).
fn quadrature_points(r: &Rocket, elements: usize, h: f64) -> Vec<Quad> {
    let g = r.gravity;
    let e_mod = r.youngs_modulus;
    let mut bounds = Vec::new();
    let mut a = 0.0;
    for s in &r.stages {
        bounds.push((a, a + s.length));
        a += s.length;
    }
    let mut quad = Vec::new();
    for el in 0..elements {
        let (xa, xb) = (el as f64 * h, (el + 1) as f64 * h);
        for (k, (st, &(ba, bb))) in r.stages.iter().zip(&bounds).enumerate() {
            let (lo, hi) = (ba.max(xa), bb.min(xb));
            if hi - lo <= 1e-12 * h {
                continue;
            }
            let (nodes, weights) = gauss01(4);
            for (&z, &wg) in nodes.iter().zip(weights) {
                let x = lo + (hi - lo) * z;
                quad.push(Quad {
                    element: el,
                    s: (x - xa) / h,
                    weight: (hi - lo) * wg,
                    ea: e_mod * st.area,
                    ei: e_mod * st.inertia,
                    fixed_mass: if k == 0 {
                        0.0
                    } else {
                        st.weight_per_length / g
                    },
                    burning: k == 0,
                    slopes: slopes((x - xa) / h, h),
                });
            }
        }
    }
    quad
}

/// The consistent operators on the quadrature points: unit burning mass ∫ψψᵀ over stage 1,
/// non-burning mass ∫m ψψᵀ, stiffness ∫EA u′δu′ + ∫EI w″δw″, and the consistent loads of the
/// unit jet-Coriolis distribution (1 − x/L₁)₊ on stage 1.
fn integrate_operators(quad: &[Quad], h: f64, l1: f64, n: usize) -> Operators {
    let mut mb = BTreeMap::new();
    let mut mf = BTreeMap::new();
    let mut kb = BTreeMap::new();
    let mut cor_u = vec![0.0; n];
    let mut cor_w = vec![0.0; n];
    for q in quad {
        let (nu, du) = bar_shapes(q.s, h);
        let Shapes { n: hw, db: hdd, .. } = hermite_cubic().shapes(q.s, h);
        let (iu, iw) = dofs_of(q.element);
        let (mass_b, mass_f) = (
            if q.burning { q.weight } else { 0.0 },
            q.weight * q.fixed_mass,
        );
        for a in 0..2 {
            for b in 0..2 {
                *mb.entry((iu[a], iu[b])).or_insert(0.0) += mass_b * nu[a] * nu[b];
                *mf.entry((iu[a], iu[b])).or_insert(0.0) += mass_f * nu[a] * nu[b];
                *kb.entry((iu[a], iu[b])).or_insert(0.0) += q.weight * q.ea * du[a] * du[b];
            }
        }
        for a in 0..4 {
            for b in 0..4 {
                *mb.entry((iw[a], iw[b])).or_insert(0.0) += mass_b * hw[a] * hw[b];
                *mf.entry((iw[a], iw[b])).or_insert(0.0) += mass_f * hw[a] * hw[b];
                *kb.entry((iw[a], iw[b])).or_insert(0.0) += q.weight * q.ei * hdd[a] * hdd[b];
            }
        }
        let x = (q.element as f64 + q.s) * h;
        let flow = if q.burning {
            (1.0 - x / l1).max(0.0)
        } else {
            0.0
        };
        for a in 0..2 {
            cor_u[iu[a]] += q.weight * flow * nu[a];
        }
        for a in 0..4 {
            cor_w[iw[a]] += q.weight * flow * hw[a];
        }
    }
    Operators {
        mb,
        mf,
        kb,
        cor_u,
        cor_w,
    }
}

/// The discrete masses on springs to the case at their attachment points (inside the body).
fn discrete_masses(r: &Rocket, elements: usize, h: f64) -> Result<Vec<Attached>, FemError> {
    let (g, length) = (r.gravity, r.length());
    let mut masses = Vec::new();
    for (k, dm) in r.discrete_masses.iter().enumerate() {
        if !(0.0..=length).contains(&dm.position) {
            return Err(FemError::InvalidSettings {
                field: "rocket.discrete_mass".into(),
                message: format!(
                    "mass {} at x = {} lies outside the body",
                    k + 1,
                    dm.position
                ),
            });
        }
        masses.push(Attached {
            at: mesh_point(dm.position, h, elements),
            mass: dm.weight / g,
            ku: dm.axial_stiffness,
            kw: dm.transverse_stiffness,
            cu: dm.axial_damping,
            cw: dm.transverse_damping,
        });
    }
    Ok(masses)
}

/// The springs between pairs of distinct discrete masses.
fn mass_couplings(r: &Rocket, nm: usize) -> Result<Vec<Coupling>, FemError> {
    let mut couplings = Vec::new();
    for sp in &r.springs {
        let [a, b] = sp.between;
        if a >= nm || b >= nm || a == b {
            return Err(FemError::InvalidSettings {
                field: "rocket.spring".into(),
                message: format!("spring between masses {a} and {b}: no such pair"),
            });
        }
        couplings.push(Coupling {
            a,
            b,
            ku: sp.axial_stiffness,
            kw: sp.transverse_stiffness,
            cu: sp.axial_damping,
            cw: sp.transverse_damping,
        });
    }
    Ok(couplings)
}

/// A mass held by no spring in one direction would drift through the case as a rigid body of
/// its own (the model has no contact): refused, as modal does.
fn refuse_free_masses(masses: &[Attached], couplings: &[Coupling]) -> Result<(), FemError> {
    for (j, m) in masses.iter().enumerate() {
        let held = |own: f64, coupled: fn(&Coupling) -> f64| {
            own > 0.0
                || couplings
                    .iter()
                    .any(|c| (c.a == j || c.b == j) && coupled(c) > 0.0)
        };
        if !(held(m.ku, |c| c.ku) && held(m.kw, |c| c.kw)) {
            return Err(FemError::Unsupported(format!(
                "rocket.discrete_mass[{j}] has no axial or no transverse spring to the case \
                 or to another mass: it would drift freely (no contact model)"
            )));
        }
    }
    Ok(())
}

/// x on the nodes' u-DOFs and the masses' U, and unit translations along ξ (u, U) and η (w, W).
fn reference_vectors(nodes: usize, h: f64, masses: &[Attached], n: usize) -> Reference {
    let base = DOFS_PER_NODE * nodes;
    let nm = masses.len();
    let mut x_ref = vec![0.0; n];
    let mut t_xi = vec![0.0; n];
    let mut t_eta = vec![0.0; n];
    for i in 0..nodes {
        x_ref[DOFS_PER_NODE * i] = i as f64 * h;
        t_xi[DOFS_PER_NODE * i] = 1.0;
        t_eta[DOFS_PER_NODE * i + 1] = 1.0;
    }
    let (t_xi_case, t_eta_case) = (t_xi.clone(), t_eta.clone());
    for (j, m) in masses.iter().enumerate() {
        x_ref[base + j] = m.at.x;
        t_xi[base + j] = 1.0;
        t_eta[base + nm + j] = 1.0;
    }
    Reference {
        x_ref,
        t_xi,
        t_eta,
        t_xi_case,
        t_eta_case,
    }
}
