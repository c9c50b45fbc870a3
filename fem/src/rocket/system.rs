//! The rocket as a [`System`]: R(t, q, q̇, q̈) = M(t) q̈ − F(t, q, q̇) (equations of [`super`]).
//!
//! Residual groups ([`Parts`]):
//! * inertia M(t) q̈, M(t) = M_fixed + m₁(t)M_burn + diag(M_j). There are no velocity terms:
//!   M does not depend on q, and the Ṁq̇ of the time-varying mass cancels against the momentum
//!   the burnt mass carries off at the local case velocity (report eqs. 3.16–3.18, 3.43);
//! * conservative ∂V/∂q − M(t)G + the discrete springs (beam strain with its cubic term,
//!   gravity of the current mass);
//! * non-conservative: the dampers, thrust, chamber pressure and jet Coriolis (the loads'
//!   directions follow the mean axis).
//!
//! **Time-varying mass.** Every evaluation takes M at the time it is given; the Newton matrix
//! takes M at the time of the last full residual ([`System::newton_matrix`] has no time
//! argument). No method caches M across steps: the implicit methods form S at the first Newton
//! iteration of every step, central difference forms M(t₁) every step (module docs of
//! [`crate::method::central_difference`]). Methods with the [`Capabilities::variable_mass`]
//! capability step the rocket; energy-midpoint does not (its momentum form
//! M(q₁)v₁ − M(q₀)v₀ would book the burnt mass's momentum as a force).
//!
//! **Newton matrix** S = c_a M(t) + c_v C + c_q K with C, K the dampers and the beam and spring
//! stiffness in launch axes (constant). The loads' and the mass-to-mass springs' dependence on
//! the mean axes and the cubic strain term are not in S (their derivative is ~1e-5 of S at the
//! catalog scenes): a quasi-Newton matrix the methods' iterations converge with at that rate.
//! With the implicit midpoint rule's coefficients (1, h/2, h²/4) S = M(t_m) + ¼h²K + ½hC.
//!
//! [`Capabilities::variable_mass`]: crate::method::Capabilities::variable_mass

use crate::band::BorderedBand;
use crate::linalg::dot;
use crate::system::{NewtonCoefficients, NoAugmentation, Parts, System, Works};

use super::model::{DOFS_PER_NODE, Model};

/// Powers of the loads at one evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub struct Powers {
    pub thrust: f64,
    pub pressure: f64,
    pub coriolis: f64,
    pub damper: f64,
}

/// The rocket's equations of motion (module docs) and the scratch of their evaluation.
#[derive(Debug, Clone)]
pub struct RocketSystem {
    pub model: Model,
    /// Nodal gravity field G (launch axes).
    pub gravity: Vec<f64>,
    /// Linear spring and damper entries (i, j, k, c) in launch axes.
    springs: Vec<(usize, usize, f64, f64)>,
    /// Time of the last full residual (the Newton matrix's M).
    t_last: f64,
    f: Vec<f64>,
    g: Vec<f64>,
    zero: Vec<f64>,
}

impl RocketSystem {
    pub fn new(model: Model) -> Self {
        let n = model.n;
        let (g_xi, g_eta) = model.gravity();
        let gravity = (0..n)
            .map(|i| g_xi * model.t_xi[i] + g_eta * model.t_eta[i])
            .collect();
        let springs = model.spring_entries();
        RocketSystem {
            model,
            gravity,
            springs,
            t_last: 0.0,
            f: vec![0.0; n],
            g: vec![0.0; n],
            zero: vec![0.0; n],
        }
    }

    /// Generalized forces F(t, q, v) (everything but inertia) into `f`; returns the loads'
    /// powers at velocity v.
    pub fn loads(
        model: &Model,
        gravity: &[f64],
        t: f64,
        q: &[f64],
        v: &[f64],
        f: &mut [f64],
    ) -> Powers {
        f.iter_mut().for_each(|x| *x = 0.0);
        model.mass_mul_add(model.m1(t), 1.0, gravity, f);
        model.add_elastic_forces(q, f);
        let axis = model.mean_axis(q, v);
        let (_, damper) = model.add_spring_forces(axis.phi, q, v, f);
        let mut p = Powers {
            damper,
            ..Default::default()
        };
        if model.burning(t) {
            let flow = model.mass_flow(t);
            let thrust = flow * model.exhaust_velocity;
            let (dc, ds) = (
                (axis.phi + model.gamma).cos(),
                (axis.phi + model.gamma).sin(),
            );
            f[0] += thrust * dc;
            f[1] += thrust * ds;
            p.thrust = thrust * (dc * v[0] + ds * v[1]);
            let (ec, es) = (axis.phi.cos(), axis.phi.sin());
            let pa = model.pressure_force;
            f[0] -= pa * ec;
            f[1] -= pa * es;
            model.add_point_force(&model.pressure_point, (pa * ec, pa * es), f);
            let (ul, wl) = model.at(&model.pressure_point, v);
            p.pressure = pa * (ec * (ul - v[0]) + es * (wl - v[1]));
            let c = 2.0 * axis.rate * flow;
            if c != 0.0 {
                let (nx, ny) = (-es, ec);
                for i in 0..model.n {
                    let fi = c * (nx * model.cor_u[i] + ny * model.cor_w[i]);
                    f[i] += fi;
                    p.coriolis += fi * v[i];
                }
            }
        }
        p
    }

    /// The loads' powers at (t, q, v) (one evaluation of F).
    pub fn powers(&mut self, t: f64, q: &[f64], v: &[f64]) -> Powers {
        Self::loads(&self.model, &self.gravity, t, q, v, &mut self.f)
    }

    /// The conservative forces −(∂V/∂q − M(t)G + springs) at (t, q) into `out`: F at zero
    /// velocity without the loads ([`Self::loads`] with the burn off).
    fn conservative_forces(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let m = &self.model;
        out.iter_mut().for_each(|x| *x = 0.0);
        m.mass_mul_add(m.m1(t), 1.0, &self.gravity, out);
        m.add_elastic_forces(q, out);
        let axis = m.mean_axis(q, &self.zero);
        m.add_spring_forces(axis.phi, q, &self.zero, out);
    }
}

impl System for RocketSystem {
    type Augmented = NoAugmentation;

    fn ndof(&self) -> usize {
        self.model.n
    }

    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]) {
        self.t_last = t;
        let m = &self.model;
        Self::loads(m, &self.gravity, t, q, qd, res);
        res.iter_mut().for_each(|r| *r = -*r);
        m.mass_mul_add(m.m1(t), 1.0, qdd, res);
    }

    fn residual_parts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        if parts == Parts::ALL {
            self.residual(t, q, qd, qdd, res);
            return;
        }
        res.iter_mut().for_each(|r| *r = 0.0);
        let m1 = self.model.m1(t);
        if parts.inertia {
            self.model.mass_mul_add(m1, 1.0, qdd, res);
        }
        let mut g = std::mem::take(&mut self.g);
        if parts.conservative || parts.nonconservative {
            self.conservative_forces(t, q, &mut g);
        }
        if parts.nonconservative {
            // −Q = −(F − F_conservative).
            Self::loads(&self.model, &self.gravity, t, q, qd, &mut self.f);
            for i in 0..res.len() {
                res[i] -= self.f[i] - g[i];
            }
        }
        if parts.conservative {
            for i in 0..res.len() {
                res[i] -= g[i];
            }
        }
        self.g = g;
    }

    fn residual_parts_at_last_q(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        let zero = std::mem::take(&mut self.zero);
        self.residual_parts(t, q, qd, &zero, parts, res);
        self.zero = zero;
    }

    fn add_kinetic_gradient(
        &mut self,
        _t: f64,
        _q: &[f64],
        _x: &[f64],
        _sign: f64,
        _out: &mut [f64],
    ) {
        // T = ½xᵀM(t)x does not depend on q.
    }

    /// Kinetic ½vᵀM(t)v, strain V, discrete springs, gravity −GᵀM(t)(x_ref + q).
    fn energies(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        let m = &self.model;
        let m1 = m.m1(t);
        let kinetic = 0.5 * m.mass_form(m1, qd, qd);
        let strain = m.strain_energy(q);
        let pos: Vec<f64> = (0..m.n).map(|i| m.x_ref[i] + q[i]).collect();
        let gravity = -m.mass_form(m1, &self.gravity, &pos);
        let axis = m.mean_axis(q, qd);
        let mut scratch = vec![0.0; m.n];
        let (spring, _) = m.add_spring_forces(axis.phi, q, qd, &mut scratch);
        [kinetic, strain, spring, gravity]
    }

    fn has_massless_dofs(&self) -> bool {
        false
    }

    fn new_matrix(&self) -> BorderedBand {
        let ni = DOFS_PER_NODE * self.model.nodes;
        BorderedBand::new(ni, self.model.n - ni, 2 * DOFS_PER_NODE - 1)
    }

    fn newton_matrix(&self, _q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        let m = &self.model;
        let m1 = m.m1(self.t_last);
        s.clear();
        if c.c_a != 0.0 {
            for &(i, j, val) in &m.m_fixed.0 {
                s.add(i, j, c.c_a * val);
            }
            for &(i, j, val) in &m.m_burn.0 {
                s.add(i, j, c.c_a * m1 * val);
            }
            for (j, dm) in m.masses.iter().enumerate() {
                let (iu, iw) = m.mass_dofs(j);
                s.add(iu, iu, c.c_a * dm.mass);
                s.add(iw, iw, c.c_a * dm.mass);
            }
        }
        if c.c_q != 0.0 {
            for &(i, j, val) in &m.k_beam.0 {
                s.add(i, j, c.c_q * val);
            }
        }
        for &(i, j, k, d) in &self.springs {
            s.add(i, j, c.c_q * k + c.c_v * d);
        }
    }

    /// Not the rocket's ledger (the rocket's driver books thrust, pressure, Coriolis and the
    /// dampers apart, [`super::driver`]): the whole non-conservative work −minus_q·Δq as an
    /// applied load. Only the energy-consistent method calls it, and it does not step the
    /// rocket (module docs).
    fn midpoint_works(
        &mut self,
        _h: f64,
        _t_mid: f64,
        _t_law: f64,
        dq: &[f64],
        _vbar: &[f64],
        minus_q: &[f64],
    ) -> Works {
        Works {
            applied_load: -dot(minus_q, dq),
            ..Works::default()
        }
    }
}
