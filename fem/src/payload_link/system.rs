//! The payload link as a [`System`]: the equations of the module doc of [`super`] in the
//! generalized coordinates the methods step.
//!
//! A free base has q = (d, θ) (n + 1 unknowns, θ last); a prescribed base has q = d, and the
//! system evaluates θ̇(t), θ̈(t) of the law at the time it is given. Residual groups
//! ([`Parts`]):
//! * free base — inertia: the Lagrangian terms of T = ½J(d)θ̇² + θ̇ b(d)·ḋ + ½ḋᵀMḋ,
//!   R_d = M d̈ + b(d)θ̈ + θ̇(Gᵀ − G)ḋ − θ̇²(j₁ + K_c d),
//!   R_θ = J(d)θ̈ + b(d)·d̈ + 2θ̇(j₁ + K_c d)·ḋ + ḋᵀGḋ;
//!   conservative: K_s d + f_g and K(θ − θ₀); non-conservative: Cḋ and b_mθ̇ − T_mot(t);
//! * prescribed base — T = ½ḋᵀMḋ (the mass of the unknowns, constant): inertia M d̈;
//!   conservative K_s d + f_g; non-conservative Cḋ and the forces of the moving frame,
//!   b(d)θ̈ + θ̇(Gᵀ − G)ḋ − θ̇²(j₁ + K_c d), which do the prescribed motion's work on the field.
//!   [`System::energies`] reports that T (the mass the energy-consistent method's discrete
//!   gradient is built on); the run's ledger reports the full kinetic energy
//!   ([`Model::kinetic`]) against the work of the torque the motion needs.
//!
//! Newton matrix S = c_a ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q, analytic, in the bordered band
//! (band block in d, dense θ row and column for a free base):
//! * d block: c_a M + c_v (C + θ̇(Gᵀ − G)) + c_q (K_s − θ̇²K_c + θ̈Gᵀ);
//! * θ column (∂R_d/∂θ̈, ∂R_d/∂θ̇; R_d does not depend on θ):
//!   c_a b(d) + c_v [(Gᵀ − G)ḋ − 2θ̇(j₁ + K_c d)];
//! * θ row: c_a b(d) + c_v [2θ̇(j₁ + K_c d) + (G + Gᵀ)ḋ] + c_q [2θ̈(j₁ + K_c d) + G d̈ + 2θ̇K_c ḋ];
//! * corner: c_a J(d) + c_v (b_m + 2(j₁ + K_c d)·ḋ) + c_q K.
//!
//! With the midpoint rule's coefficients (1, h/2, h²/4) this is the matrix the link's former
//! hand-written stepper assembled; its constant operators are combined per formation (one
//! pass over the band, no allocation).

use crate::band::BorderedBand;
use crate::linalg::dot;
use crate::system::{NewtonCoefficients, NoAugmentation, Parts, System, Works};

use super::model::{Band, Model};

/// The payload link's equations of motion (module docs).
#[derive(Debug, Clone)]
pub struct LinkSystem {
    pub model: Model,
    /// Gᵀ and Gᵀ − G as bands (constant).
    gt: Band,
    gskew: Band,
    /// Point data of the last residual: base rate and acceleration, b(d), j₁ + K_c d, G ḋ,
    /// Gᵀḋ, K_c ḋ, G d̈.
    rate: f64,
    acc: f64,
    /// J(d) and (j₁ + K_c d)·ḋ.
    polar: f64,
    jd_dot_v: f64,
    bd: Vec<f64>,
    jd: Vec<f64>,
    gv: Vec<f64>,
    gtv: Vec<f64>,
    kcv: Vec<f64>,
    ga: Vec<f64>,
    tmp: Vec<f64>,
    /// Scratch of the kinetic gradient (K_c d, G x), apart from the point data.
    grad: [Vec<f64>; 2],
    zero: Vec<f64>,
}

impl LinkSystem {
    pub fn new(model: Model) -> Self {
        let (n, b) = (model.n, model.m.b);
        let mut gt = Band::zeros(n, b);
        let mut gskew = Band::zeros(n, b);
        for i in 0..n {
            for j in model.m.cols(i) {
                let (gij, gji) = (model.g.get(i, j), model.g.get(j, i));
                gt.add(i, j, gji);
                gskew.add(i, j, gji - gij);
            }
        }
        let z = vec![0.0; n];
        let zero = vec![0.0; n + usize::from(model.free_base())];
        LinkSystem {
            model,
            gt,
            gskew,
            rate: 0.0,
            acc: 0.0,
            polar: 0.0,
            jd_dot_v: 0.0,
            bd: z.clone(),
            jd: z.clone(),
            gv: z.clone(),
            gtv: z.clone(),
            kcv: z.clone(),
            ga: z.clone(),
            tmp: z.clone(),
            grad: [z.clone(), z.clone()],
            zero,
        }
    }

    /// Whether θ is an unknown (index n).
    pub fn free_base(&self) -> bool {
        self.model.free_base()
    }

    /// (θ, θ̇, θ̈) of the base at (t, q, q̇, q̈): the unknowns of a free base, the law of a
    /// prescribed one.
    pub fn base(&self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> (f64, f64, f64) {
        let n = self.model.n;
        match self.model.prescribed(t) {
            Some(k) => k,
            None => (q[n], qd[n], qdd[n]),
        }
    }

    /// Fills the point data of the base equation at (d, ḋ): b(d), j₁ + K_c d, J(d) and
    /// (j₁ + K_c d)·ḋ, G ḋ.
    fn point_base(&mut self, d: &[f64], dd: &[f64]) {
        let md = &self.model;
        md.g.matvec_transpose(d, &mut self.bd);
        md.kc.matvec(d, &mut self.jd);
        md.g.matvec(dd, &mut self.gv);
        for i in 0..md.n {
            self.bd[i] += md.b0[i];
            self.jd[i] += md.j1[i];
        }
        // J(d) = J₀ + 2j₁·d + dᵀK_c d = J₀ + j₁·d + d·(j₁ + K_c d).
        self.polar = md.j0 + dot(&md.j1, d) + dot(d, &self.jd);
        self.jd_dot_v = dot(&self.jd, dd);
    }

    /// Fills the point data of the residual and the Newton matrix at (d, ḋ, d̈): that of
    /// [`Self::point_base`], Gᵀḋ, and for a free base (its border) K_c ḋ and G d̈.
    fn point(&mut self, d: &[f64], dd: &[f64], ddd: &[f64]) {
        self.point_base(d, dd);
        let md = &self.model;
        md.g.matvec_transpose(dd, &mut self.gtv);
        if md.free_base() {
            md.kc.matvec(dd, &mut self.kcv);
            md.g.matvec(ddd, &mut self.ga);
        }
    }

    /// Inertial part of the base equation at the point data of the last [`Self::point_base`]:
    /// J(d)θ̈ + b(d)·d̈ + 2θ̇(j₁ + K_c d)·ḋ + ḋᵀGḋ.
    fn base_inertia(&self, dd: &[f64], ddd: &[f64], rate: f64, acc: f64) -> f64 {
        self.polar * acc + dot(&self.bd, ddd) + 2.0 * rate * self.jd_dot_v + dot(dd, &self.gv)
    }

    /// The torque the base needs at (t, q, q̇, q̈): the left side of the base equation,
    /// J(d)θ̈ + b(d)·d̈ + 2θ̇(j₁ + K_c d)·ḋ + ḋᵀGḋ + b_mθ̇ + K(θ − θ₀) (for a free base its
    /// residual plus T_mot(t)). Overwrites the point data.
    pub fn base_torque(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> f64 {
        let n = self.model.n;
        let (theta, rate, acc) = self.base(t, q, qd, qdd);
        self.point_base(&q[..n], &qd[..n]);
        let (k, th0) = self.model.spring();
        self.base_inertia(&qd[..n], &qdd[..n], rate, acc)
            + self.model.motor_friction * rate
            + k * (theta - th0)
    }

    /// The works of a step over which the state went from (q₀, q̇₀) to (q₁, q̇₁), by the
    /// midpoint rule (every force at t_mid, q̄ = ½(q₀ + q₁), v̄ = Δq/h, ā = Δq̇/h): a free base's
    /// applied torque T_mot(t_mid)Δθ and joint damper h b_m v̄_θ²; a prescribed base's needed
    /// torque times h θ̇(t_mid); the Kelvin–Voigt dissipation h v̄ᵀC_f v̄ of each damped field
    /// into `kelvin_voigt` (the order of [`Model::c_field`]). `scratch`: three vectors of the
    /// system's size. For the implicit midpoint rule, the scheme's own quadrature.
    #[allow(clippy::too_many_arguments)]
    pub fn step_works(
        &mut self,
        t0: f64,
        h: f64,
        (q0, q1): (&[f64], &[f64]),
        (qd0, qd1): (&[f64], &[f64]),
        scratch: &mut [Vec<f64>; 3],
        works: &mut LinkWorks,
    ) {
        let n = self.model.n;
        let [qbar, vbar, abar] = scratch;
        for i in 0..q0.len() {
            qbar[i] = 0.5 * (q0[i] + q1[i]);
            vbar[i] = (q1[i] - q0[i]) / h;
            abar[i] = (qd1[i] - qd0[i]) / h;
        }
        let t_mid = t0 + 0.5 * h;
        let md = &self.model;
        if md.free_base() {
            let w = vbar[n];
            works.applied_torque += h * md.motor_torque(t_mid) * w;
            works.joint_damper += h * md.motor_friction * w * w;
        } else {
            let (_, rate, _) = self.base(t_mid, qbar, vbar, abar);
            let needed = self.base_torque(t_mid, qbar, vbar, abar);
            works.prescribed_motion += h * needed * rate;
            works.joint_damper += h * self.model.motor_friction * rate * rate;
        }
        for (k, (_, band)) in self.model.c_field.iter().enumerate() {
            works.kelvin_voigt[k] += h * band.form(&vbar[..n], &vbar[..n]);
        }
    }
}

/// The link's ledger works (cumulative), with Kelvin–Voigt per damped field (at most the four
/// fields, in the order of [`Model::c_field`]); fixed size, so a step books without allocating.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkWorks {
    pub applied_torque: f64,
    pub prescribed_motion: f64,
    pub joint_damper: f64,
    pub kelvin_voigt: [f64; 4],
}

impl System for LinkSystem {
    type Augmented = NoAugmentation;

    fn ndof(&self) -> usize {
        self.model.n + usize::from(self.free_base())
    }

    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]) {
        self.residual_parts(t, q, qd, qdd, Parts::ALL, res);
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
        let n = self.model.n;
        let free = self.free_base();
        let (theta, w, acc) = self.base(t, q, qd, qdd);
        let (d, dd, ddd) = (&q[..n], &qd[..n], &qdd[..n]);
        self.point(d, dd, ddd);
        self.rate = w;
        self.acc = acc;
        res.iter_mut().for_each(|r| *r = 0.0);
        let md = &self.model;
        // The moving frame's forces on the field: inertia of a free base, non-conservative
        // (the prescribed motion's) of a prescribed one.
        let frame = if free {
            parts.inertia
        } else {
            parts.nonconservative
        };
        if parts.inertia {
            md.m.matvec(ddd, &mut res[..n]);
        }
        if frame {
            for i in 0..n {
                res[i] += self.bd[i] * acc + w * (self.gtv[i] - self.gv[i]) - w * w * self.jd[i];
            }
        }
        if parts.conservative {
            md.ks.matvec(d, &mut self.tmp);
            for i in 0..n {
                res[i] += self.tmp[i] + md.fg[i];
            }
        }
        if parts.nonconservative {
            md.c.matvec(dd, &mut self.tmp);
            for i in 0..n {
                res[i] += self.tmp[i];
            }
        }
        if free {
            let (k, th0) = md.spring();
            let mut r = 0.0;
            if parts.inertia {
                r += self.base_inertia(dd, ddd, w, acc);
            }
            if parts.conservative {
                r += k * (theta - th0);
            }
            if parts.nonconservative {
                r += self.model.motor_friction * w - self.model.motor_torque(t);
            }
            res[n] = r;
        }
    }

    fn residual_parts_at_last_q(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        // The point data is a few band products: recomputed (R is affine in q̈; d̈ = 0 here).
        let zero = std::mem::take(&mut self.zero);
        self.residual_parts(t, q, qd, &zero, parts, res);
        self.zero = zero;
    }

    fn add_kinetic_gradient(&mut self, _t: f64, q: &[f64], x: &[f64], sign: f64, out: &mut [f64]) {
        // ∂T/∂d = x_θ²(j₁ + K_c d) + x_θ G x_d, ∂T/∂θ = 0 (free base); the prescribed base's T
        // = ½ḋᵀMḋ has a constant mass.
        if !self.free_base() {
            return;
        }
        let md = &self.model;
        let n = md.n;
        let xt = x[n];
        let [kcd, gx] = &mut self.grad;
        md.kc.matvec(&q[..n], kcd);
        md.g.matvec(&x[..n], gx);
        for i in 0..n {
            out[i] += sign * (xt * xt * (md.j1[i] + kcd[i]) + xt * gx[i]);
        }
    }

    fn energies(&self, _t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        let md = &self.model;
        let n = md.n;
        let (d, dd) = (&q[..n], &qd[..n]);
        let (kinetic, spring) = if self.free_base() {
            (md.kinetic(d, qd[n], dd), md.joint_spring(q[n]))
        } else {
            (0.5 * md.m.form(dd, dd), 0.0)
        };
        [kinetic, md.strain(d), spring, md.gravity(d)]
    }

    fn has_massless_dofs(&self) -> bool {
        false
    }

    fn new_matrix(&self) -> BorderedBand {
        let md = &self.model;
        BorderedBand::new(
            md.n,
            usize::from(md.free_base()),
            md.layout.half_bandwidth(),
        )
    }

    fn newton_matrix(&self, _q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        let md = &self.model;
        let n = md.n;
        let (w, acc) = (self.rate, self.acc);
        let (ca, cv, cq) = (c.c_a, c.c_v, c.c_q);
        s.clear();
        for i in 0..n {
            for j in md.m.cols(i) {
                let k = md.m.index(i, j);
                let v = ca * md.m.data[k]
                    + cv * (md.c.data[k] + w * self.gskew.data[k])
                    + cq * (md.ks.data[k] - w * w * md.kc.data[k] + acc * self.gt.data[k]);
                if v != 0.0 {
                    s.add(i, j, v);
                }
            }
        }
        if md.free_base() {
            for i in 0..n {
                let col = ca * self.bd[i] + cv * (self.gtv[i] - self.gv[i] - 2.0 * w * self.jd[i]);
                let row = ca * self.bd[i]
                    + cv * (2.0 * w * self.jd[i] + self.gv[i] + self.gtv[i])
                    + cq * (2.0 * acc * self.jd[i] + self.ga[i] + 2.0 * w * self.kcv[i]);
                s.add(i, n, col);
                s.add(n, i, row);
            }
            let (k, _) = md.spring();
            let corner = ca * self.polar + cv * (md.motor_friction + 2.0 * self.jd_dot_v) + cq * k;
            s.add(n, n, corner);
        }
    }

    /// The applied torque T_mot(t_mid)Δθ and the joint damper b_m v̄_θΔθ of a free base,
    /// Kelvin–Voigt h v̄ᵀC v̄ (all fields together); the rest of −minus_q·Δq is the moving
    /// frame's work on the field of a prescribed base (`prescribed_motion`). The run's ledger
    /// books per field with [`LinkSystem::step_works`], the same quadrature.
    fn midpoint_works(
        &mut self,
        h: f64,
        t_mid: f64,
        _t_law: f64,
        dq: &[f64],
        vbar: &[f64],
        minus_q: &[f64],
    ) -> Works {
        let md = &self.model;
        let n = md.n;
        let mut works = Works {
            kelvin_voigt: h * md.c.form(&vbar[..n], &vbar[..n]),
            ..Works::default()
        };
        if md.free_base() {
            works.applied_torque = md.motor_torque(t_mid) * dq[n];
            works.joint_damper = md.motor_friction * vbar[n] * dq[n];
        } else {
            works.prescribed_motion = works.kelvin_voigt - dot(minus_q, dq);
        }
        works
    }
}
