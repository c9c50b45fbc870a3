//! Implicit midpoint rule for the payload link, Newton on the midpoint acceleration.
//!
//! With q = (d, θ), v = q̇ and a = (v₁ − v₀)/h: v̄ = v₀ + ½h a, q̄ = q₀ + ½h v̄, and
//! R(a) = M(q̄) a − f(q̄, v̄, t + ½h) = 0, where (the equations of the module doc)
//! * R_d = b(d)a_θ + M a_d + θ̇(Gᵀ − G)ḋ − θ̇²(j₁ + K_c d) + K_s d + Cḋ + f_g,
//! * R_θ = J(d)a_θ + b(d)·a_d + 2θ̇(j₁ + K_c d)·ḋ + ḋᵀGḋ − T_mot + b_m θ̇ + K(θ − θ₀).
//!
//! The Newton matrix ∂R/∂a = ∂R/∂a + ½h ∂R/∂v̄ + ¼h² ∂R/∂q̄ is analytic: a band block in d
//! (M + ½h(θ̇(Gᵀ − G) + C) + ¼h²(K_s − θ̇²K_c + a_θGᵀ)) bordered by the dense θ row and column.
//! It is factorized by faer's sparse LU in the fixed bordered-band pattern of
//! [`crate::band::BorderedBand`] (symbolic factorization once, numeric each iteration; no
//! allocation in the step). A prescribed base has no θ unknown: a_θ = (θ̇(t₁) − θ̇(t₀))/h.

use crate::band::BorderedBand;
use crate::error::FemError;
use crate::method::FixedStepCounters;

use super::model::{Band, Model};
use crate::linalg::{dot, max_abs};

/// Newton iterations before a step is declared failed.
const MAX_NEWTON: usize = 25;

/// State of the link: field DOFs, their rates, base angle and rate.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub t: f64,
    pub d: Vec<f64>,
    pub dd: Vec<f64>,
    pub theta: f64,
    pub rate: f64,
}

/// Works accumulated with the scheme's midpoint quadrature.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Works {
    pub applied_torque: f64,
    pub prescribed_motion: f64,
    pub joint_damper: f64,
    /// Per damped field, in the order of `Model::c_field`.
    pub kelvin_voigt: Vec<f64>,
}

pub struct Stepper {
    pub model: Model,
    pub state: State,
    pub works: Works,
    pub counters: FixedStepCounters,
    /// Torque of the base at the last step's midpoint (applied law or what prescription needs).
    pub torque_mid: f64,
    newton: BorderedBand,
    // Scratch (allocated once): the midpoint acceleration, rate and displacement, the residual,
    // and the operator products of the current iterate.
    a: Vec<f64>,
    a_theta: f64,
    dbar: Vec<f64>,
    vbar: Vec<f64>,
    rhs: Vec<f64>,
    /// b(d̄) = b₀ + Gᵀd̄.
    bd: Vec<f64>,
    /// j₁ + K_c d̄.
    jd: Vec<f64>,
    /// G v̄, Gᵀ v̄, K_c v̄, G a_d.
    gv: Vec<f64>,
    gtv: Vec<f64>,
    kcv: Vec<f64>,
    ga: Vec<f64>,
    tmp: Vec<f64>,
    /// Newton-matrix d-block as A₀ + θ̇B_g + θ̇²B_k + a_θB_t for the step length `combo_h`:
    /// A₀ = M + ½hC + ¼h²K_s, B_g = ½h(Gᵀ − G), B_k = −¼h²K_c, B_t = ¼h²Gᵀ.
    combo_h: f64,
    combo: [Band; 4],
}

/// Midpoint quantities of one Newton iterate.
#[derive(Debug, Clone, Copy)]
struct Mid {
    t: f64,
    theta: f64,
    rate: f64,
}

impl Stepper {
    pub fn new(model: Model, state: State) -> Self {
        let n = model.n;
        let nb = usize::from(model.free_base());
        let newton = BorderedBand::new(n, nb, model.layout.half_bandwidth());
        let kv = model.c_field.len();
        let z = vec![0.0; n];
        Stepper {
            model,
            state,
            works: Works {
                kelvin_voigt: vec![0.0; kv],
                ..Default::default()
            },
            counters: FixedStepCounters::default(),
            torque_mid: 0.0,
            newton,
            a: z.clone(),
            a_theta: 0.0,
            dbar: z.clone(),
            vbar: z.clone(),
            rhs: vec![0.0; n + 1],
            bd: z.clone(),
            jd: z.clone(),
            gv: z.clone(),
            gtv: z.clone(),
            kcv: z.clone(),
            ga: z.clone(),
            tmp: z,
            combo_h: f64::NAN,
            combo: std::array::from_fn(|_| Band::zeros(0, 0)),
        }
    }

    /// Sets the midpoint iterate from the acceleration guess.
    fn midpoint(&mut self, h: f64) -> Mid {
        let s = &self.state;
        for i in 0..self.model.n {
            self.vbar[i] = s.dd[i] + 0.5 * h * self.a[i];
            self.dbar[i] = s.d[i] + 0.5 * h * self.vbar[i];
        }
        let rate = s.rate + 0.5 * h * self.a_theta;
        Mid {
            t: s.t + 0.5 * h,
            theta: s.theta + 0.5 * h * rate,
            rate,
        }
    }

    /// Residual R(a) into `rhs` (d rows, then θ) and the operator products the Newton matrix
    /// needs; returns the torque the base must supply at the midpoint.
    fn residual(&mut self, mid: &Mid) -> f64 {
        let md = &self.model;
        let n = md.n;
        let w = mid.rate;
        md.g.matvec_transpose(&self.dbar, &mut self.bd);
        md.kc.matvec(&self.dbar, &mut self.jd);
        md.g.matvec(&self.vbar, &mut self.gv);
        md.g.matvec_transpose(&self.vbar, &mut self.gtv);
        md.kc.matvec(&self.vbar, &mut self.kcv);
        md.g.matvec(&self.a, &mut self.ga);
        for i in 0..n {
            self.bd[i] += md.b0[i];
            self.jd[i] += md.j1[i];
        }
        md.m.matvec(&self.a, &mut self.rhs[..n]);
        for i in 0..n {
            self.rhs[i] += self.bd[i] * self.a_theta + w * (self.gtv[i] - self.gv[i])
                - w * w * self.jd[i]
                + md.fg[i];
        }
        md.ks.matvec(&self.dbar, &mut self.tmp);
        for i in 0..n {
            self.rhs[i] += self.tmp[i];
        }
        md.c.matvec(&self.vbar, &mut self.tmp);
        for i in 0..n {
            self.rhs[i] += self.tmp[i];
        }
        let inertial = md.polar(&self.dbar) * self.a_theta
            + dot(&self.bd, &self.a)
            + 2.0 * w * dot(&self.jd, &self.vbar)
            + dot(&self.vbar, &self.gv);
        let (k, th0) = md.spring();
        let needed = inertial + md.motor_friction * w + k * (mid.theta - th0);
        self.rhs[n] = needed - md.motor_torque(mid.t);
        self.counters.residuals += 1;
        needed
    }

    /// Assembles and factorizes the Newton matrix ∂R/∂a at the iterate of the last residual.
    fn newton_matrix(&mut self, h: f64, mid: &Mid) -> Result<(), FemError> {
        self.assemble_newton(h, mid);
        self.newton.factorize()?;
        self.counters.factorizations += 1;
        Ok(())
    }

    /// Residual R(a) and the dense Newton matrix ∂R/∂a of a step of length h from the current
    /// state at the midpoint acceleration (a_d, a_θ); a prescribed base takes a_θ from its law.
    /// For tests of the analytic matrix against finite differences of the residual.
    pub fn residual_and_newton(
        &mut self,
        h: f64,
        a: &[f64],
        a_theta: f64,
    ) -> (Vec<f64>, faer::Mat<f64>) {
        let n = self.model.n;
        self.a.copy_from_slice(a);
        self.a_theta = a_theta;
        let mid = self.midpoint(h);
        self.residual(&mid);
        self.assemble_newton(h, &mid);
        let nn = n + usize::from(self.model.free_base());
        let jac = faer::Mat::from_fn(nn, nn, |i, j| self.newton.get(i, j));
        (self.rhs[..nn].to_vec(), jac)
    }

    fn assemble_newton(&mut self, h: f64, mid: &Mid) {
        let md = &self.model;
        let n = md.n;
        let (ch, cq) = (0.5 * h, 0.25 * h * h);
        let w = mid.rate;
        if self.combo_h != h {
            // Once per step length (fixed steps: once per run).
            let (n, b) = (md.n, md.m.b);
            let mut c = std::array::from_fn(|_| Band::zeros(n, b));
            c[0].add_scaled(1.0, &md.m);
            c[0].add_scaled(ch, &md.c);
            c[0].add_scaled(cq, &md.ks);
            c[2].add_scaled(-cq, &md.kc);
            for i in 0..n {
                for j in md.m.cols(i) {
                    let (gij, gji) = (md.g.get(i, j), md.g.get(j, i));
                    c[1].add(i, j, ch * (gji - gij));
                    c[3].add(i, j, cq * gji);
                }
            }
            self.combo = c;
            self.combo_h = h;
        }
        let nb = &mut self.newton;
        nb.clear();
        let [a0, bg, bk, bt] = &self.combo;
        let (s1, s2, s3) = (w, w * w, self.a_theta);
        for i in 0..n {
            for j in md.m.cols(i) {
                let k = a0.index(i, j);
                let v = a0.data[k] + s1 * bg.data[k] + s2 * bk.data[k] + s3 * bt.data[k];
                if v != 0.0 {
                    nb.add(i, j, v);
                }
            }
        }
        if md.free_base() {
            for i in 0..n {
                // ∂R_d/∂a_θ = b(d) + ½h[(Gᵀ − G)ḋ − 2θ̇(j₁ + K_c d)].
                let col = self.bd[i] + ch * (self.gtv[i] - self.gv[i] - 2.0 * w * self.jd[i]);
                // ∂R_θ/∂a_d = b(d) + ½h[2θ̇(j₁ + K_c d) + (G + Gᵀ)ḋ]
                //            + ¼h²[2a_θ(j₁ + K_c d) + G a_d + 2θ̇K_c ḋ].
                let row = self.bd[i]
                    + ch * (2.0 * w * self.jd[i] + self.gv[i] + self.gtv[i])
                    + cq * (2.0 * self.a_theta * self.jd[i] + self.ga[i] + 2.0 * w * self.kcv[i]);
                nb.add(i, n, col);
                nb.add(n, i, row);
            }
            let (k, _) = md.spring();
            let tt = md.polar(&self.dbar)
                + ch * (md.motor_friction + 2.0 * dot(&self.jd, &self.vbar))
                + cq * k;
            nb.add(n, n, tt);
        }
    }

    /// One implicit-midpoint step of length h; books the works with the midpoint quadrature.
    pub fn step(&mut self, h: f64) -> Result<(), FemError> {
        let n = self.model.n;
        let free = self.model.free_base();
        let t0 = self.state.t;
        if let Some((_, r0, _)) = self.model.prescribed(t0) {
            let (_, r1, _) = self.model.prescribed(t0 + h).unwrap_or_default();
            self.state.rate = r0;
            self.a_theta = (r1 - r0) / h;
        }
        // Predictor: the previous step's acceleration (kept in `a`).
        let scale = self.model.length + self.state.theta.abs() + max_abs(&self.state.d);
        let mut converged = false;
        let mut mid = self.midpoint(h);
        for it in 0..MAX_NEWTON {
            self.residual(&mid);
            // Modified Newton: the matrix of the step's first iterate (its change over one
            // correction is tiny); refreshed every iteration should that converge slowly.
            if it == 0 || it >= 3 {
                self.newton_matrix(h, &mid)?;
            }
            self.counters.newton += 1;
            let nn = n + usize::from(free);
            for v in self.rhs[..nn].iter_mut() {
                *v = -*v;
            }
            self.newton.solve_in_place(&mut self.rhs[..nn]);
            let mut big = 0.0f64;
            for i in 0..n {
                self.a[i] += self.rhs[i];
                big = big.max(self.rhs[i].abs());
            }
            if free {
                self.a_theta += self.rhs[n];
                big = big.max(self.rhs[n].abs());
            }
            if !big.is_finite() {
                break;
            }
            mid = self.midpoint(h);
            if 0.25 * h * h * big <= 1e-14 * scale {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(FemError::Runaway {
                t: t0,
                what: "Newton iteration of the implicit midpoint step did not converge".into(),
                location: None,
                why: format!("step h = {h:.3e} s too long for the motion"),
                remedy: "reduce --dt".into(),
            });
        }
        let needed = self.residual(&mid);
        let md = &self.model;
        // Works over the step, midpoint quadrature.
        let w = mid.rate;
        if free {
            self.works.applied_torque += h * md.motor_torque(mid.t) * w;
            self.torque_mid = md.motor_torque(mid.t);
        } else {
            self.works.prescribed_motion += h * needed * w;
            self.torque_mid = needed;
        }
        self.works.joint_damper += h * md.motor_friction * w * w;
        for (k, (_, band)) in md.c_field.iter().enumerate() {
            self.works.kelvin_voigt[k] += h * band.form(&self.vbar, &self.vbar);
        }
        let s = &mut self.state;
        for i in 0..n {
            s.d[i] += h * self.vbar[i];
            s.dd[i] += h * self.a[i];
        }
        s.t = t0 + h;
        if let Some((th, rate, _)) = md.prescribed(s.t) {
            s.theta = th;
            s.rate = rate;
        } else {
            s.theta += h * w;
            s.rate += h * self.a_theta;
        }
        self.counters.steps += 1;
        Ok(())
    }

    /// Torque of the base at the current state: the motor law of a free base; for a prescribed
    /// base, the torque its motion needs (d̈ from the field equations with M factorized once).
    pub fn state_torque(&self, mass_lu: &mut BorderedBand, scratch: &mut [Vec<f64>; 4]) -> f64 {
        let md = &self.model;
        let s = &self.state;
        let Some((_, w, acc)) = md.prescribed(s.t) else {
            return md.motor_torque(s.t);
        };
        let n = md.n;
        let [bd, jd, rhs, tmp] = scratch;
        md.g.matvec_transpose(&s.d, bd);
        md.kc.matvec(&s.d, jd);
        for i in 0..n {
            bd[i] += md.b0[i];
            jd[i] += md.j1[i];
        }
        // M d̈ = −[b(d)θ̈ + θ̇(Gᵀ − G)ḋ − θ̇²(j₁ + K_c d) + K_s d + Cḋ + f_g].
        md.g.matvec_transpose(&s.dd, rhs);
        md.g.matvec(&s.dd, tmp);
        let gdd: f64 = dot(&s.dd, tmp);
        for i in 0..n {
            rhs[i] = -(bd[i] * acc + w * (rhs[i] - tmp[i]) - w * w * jd[i] + md.fg[i]);
        }
        md.ks.matvec(&s.d, tmp);
        for i in 0..n {
            rhs[i] -= tmp[i];
        }
        md.c.matvec(&s.dd, tmp);
        for i in 0..n {
            rhs[i] -= tmp[i];
        }
        mass_lu.solve_in_place(rhs);
        let inertial = md.polar(&s.d) * acc + dot(bd, rhs) + 2.0 * w * dot(jd, &s.dd) + gdd;
        inertial + md.motor_friction * w
    }
}
