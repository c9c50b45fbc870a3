//! The rocket as a [`System`]: accelerations from the rigid/elastic split (5.38, 5.40).
//!
//! Coordinates (report 5.1): q = [X, Y, θ, u_0…u_r, w_0…w_r, U_1…U_n, W_1…W_n], v = q̇ =
//! [R, S, T, p…, q…, P…, Q…]. X, Y are the body-axis components of the aft-end origin O, θ the
//! attitude from the inertial horizontal. Every station (lumped mass m_i, 5.14) and discrete mass
//! obeys m_i A_i = F_i, with the absolute acceleration in body components (5.5, 5.6)
//!
//! A_x = Ṙ − Ṫ(Y + r_y) − 2T(S + q) − T²(X + r_x) + ṗ,
//! A_y = Ṡ + Ṫ(X + r_x) + 2T(R + p) − T²(Y + r_y) + q̇,  r = (x + u, w).
//!
//! Summing over all masses and taking moments about O gives the rigid equations 5.26–5.28; with
//! the report's assumption 5.37 (m{ṗ} = m{q̇} = m{r × (ṗ, q̇)} = 0) they form a 3×3 system
//! \[A₁₁\] for (Ṙ, Ṡ, Ṫ) (5.38). The elastic accelerations then follow with \[A₂₂\] = 1 (5.40):
//! ṗ_i = F_x,i/m_i − (A_x,i without ṗ). These satisfy 5.37 exactly (their momentum and moment
//! about O vanish by construction), so the split is not an approximation here.
//! Mass-loss terms F_M (3.43) cancel the ṁ part of d/dt(∂L/∂q̇) and do not appear.
//!
//! Initial shape and outputs. The scene's w(x, 0) is an elastic shape: its rigid-body part with
//! respect to the case's ignition mass m₀ is removed (see [`RocketSystem::initial_state`]).
//! The elastic channels `rocket.u@k`, `rocket.w@k`, `rocket.mass{j}.u/.w` are displacements
//! relative to the case's mean axis with respect to m₀ (the frame in which Σm₀u = Σm₀w =
//! Σm₀xw = 0 over the case stations, discrete masses excluded), and `rocket.theta` is the angle
//! of that axis; this is the definition of the modal backend, whose elastic modes are
//! m₀-orthogonal to the rigid motions, so the channels do not depend on how either backend
//! fixes its body frame. `rocket.X/Y` are the inertial mass centre of case and discrete masses.
//!
//! Loads. Thrust (at angle γ), the chamber-pressure pair ∓p·A_f and the jet Coriolis force
//! 2θ̇ m_f v are directed by that same mean axis (angle α = atan(slope) from this body axis,
//! θ̇ = T + α̇), not by this backend's body axis: the frame-invariant definition of
//! docs/rocket.md, shared by the fem and modal backends.

use std::ops::Range;

use data::{channel, ledger_term};

use crate::output::Outputs;
use crate::rocket::model::RocketModel;
use crate::rocket::operators;
use crate::system::{Bound, BoundKind, System};

/// The rocket system with its per-step scratch (no allocation in `accel`).
#[derive(Debug, Clone)]
pub struct RocketSystem {
    pub model: RocketModel,
    field_stations: usize,
    fu: Vec<f64>,
    fw: Vec<f64>,
    gu: Vec<f64>,
    gw: Vec<f64>,
    lumped: Vec<f64>,
    /// Powers at the last accel: thrust, pressure, coriolis_flow | discrete_damper, mass_outflow.
    power: [f64; 5],
    /// Whether the evaluations close the burn: the step ends on burn-out, and the loads keep
    /// their values on the burning stretch ([`System::close_stretch_at`]).
    closing_burn: bool,
}

pub const IX: usize = 0;
pub const IY: usize = 1;
pub const ITH: usize = 2;

impl RocketSystem {
    pub fn new(model: RocketModel, field_stations: usize) -> Self {
        let n = model.stations;
        let nm = model.masses.len();
        RocketSystem {
            model,
            field_stations: field_stations.max(2),
            fu: vec![0.0; n],
            fw: vec![0.0; n],
            gu: vec![0.0; nm],
            gw: vec![0.0; nm],
            lumped: vec![0.0; n],
            power: [0.0; 5],
            closing_burn: false,
        }
    }

    pub fn u_range(&self) -> Range<usize> {
        3..3 + self.model.stations
    }
    pub fn w_range(&self) -> Range<usize> {
        let n = self.model.stations;
        3 + n..3 + 2 * n
    }
    pub fn mu_range(&self) -> Range<usize> {
        let n = self.model.stations;
        let nm = self.model.masses.len();
        3 + 2 * n..3 + 2 * n + nm
    }
    pub fn mw_range(&self) -> Range<usize> {
        let n = self.model.stations;
        let nm = self.model.masses.len();
        3 + 2 * n + nm..3 + 2 * n + 2 * nm
    }

    /// Initial state: rest, attitude θ₀, transverse shape w(x, 0) (report §5.3) taken as an
    /// *elastic* shape: its rigid-body part with respect to the case's ignition mass (the
    /// weighted least-squares line c₀ + c₁x with the lumped station masses, discrete masses
    /// excluded) is removed, so that ∑mᵢwᵢ = ∑mᵢxᵢwᵢ = 0 and the body axis is the case's mean
    /// axis. The report's shapes satisfy this for a uniform case; for the stepped case the line
    /// is about 5e-6 in offset and 1e-7 rad in slope, enough to shift the thrust line (which
    /// follows the body axis) and the initial stretch of the discrete masses' springs (they
    /// start at U = W = 0).
    pub fn initial_state(&self, shape: &data::scene::InitialShape) -> (Vec<f64>, Vec<f64>) {
        let n = self.dofs();
        let mut q = vec![0.0; n];
        q[ITH] = self.model.theta0;
        let m = &self.model;
        let fit = mean_axis(m, |i| (0.0, shape.deflection(i as f64 * m.h, m.length)));
        let (c0, c1) = (fit.offset, fit.slope);
        let wr = self.w_range();
        for (i, k) in wr.enumerate() {
            let x = i as f64 * m.h;
            q[k] = shape.deflection(x, m.length) - (c0 + c1 * x);
        }
        (q, vec![0.0; n])
    }

    /// Gravity in body components (5.2, 5.3): (−g sin θ, −g cos θ).
    fn gravity(&self, theta: f64) -> (f64, f64) {
        (-self.model.g * theta.sin(), -self.model.g * theta.cos())
    }

    /// Field value at x by linear interpolation between stations.
    fn interp(&self, field: &[f64], x: f64) -> f64 {
        let pos = (x / self.model.h).clamp(0.0, (self.model.stations - 1) as f64);
        let i = (pos.floor() as usize).min(self.model.stations - 2);
        let a = pos - i as f64;
        field[i] * (1.0 - a) + field[i + 1] * a
    }

    /// Mass moments m{r_x}, m{r_y}, m{p}, m{q} (5.14).
    fn moments(&self, t: f64, q: &[f64], v: &[f64]) -> (f64, f64, f64, f64, f64) {
        let m = &self.model;
        let m1 = m.m1(t);
        let (u, w) = (&q[self.u_range()], &q[self.w_range()]);
        let (p, qq) = (&v[self.u_range()], &v[self.w_range()]);
        let (mut mt, mut mx, mut my, mut mp, mut mq) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..m.stations {
            let mi = m.station_mass(i, m1);
            mt += mi;
            mx += mi * (i as f64 * m.h + u[i]);
            my += mi * w[i];
            mp += mi * p[i];
            mq += mi * qq[i];
        }
        let (mu, mw) = (&q[self.mu_range()], &q[self.mw_range()]);
        let (mpv, mqv) = (&v[self.mu_range()], &v[self.mw_range()]);
        for (k, a) in m.masses.iter().enumerate() {
            mt += a.mass;
            mx += a.mass * (a.x + mu[k]);
            my += a.mass * mw[k];
            mp += a.mass * mpv[k];
            mq += a.mass * mqv[k];
        }
        (mt, mx, my, mp, mq)
    }
}

impl System for RocketSystem {
    fn dofs(&self) -> usize {
        3 + 2 * self.model.stations + 2 * self.model.masses.len()
    }

    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        let ns = self.model.stations;
        let (ur, wr, mur, mwr) = (
            self.u_range(),
            self.w_range(),
            self.mu_range(),
            self.mw_range(),
        );
        let m = &self.model;
        let (xo, yo, th) = (q[IX], q[IY], q[ITH]);
        let (rr, ss, tt) = (v[IX], v[IY], v[ITH]);
        let (u, w) = (&q[ur.clone()], &q[wr.clone()]);
        let (p, qv) = (&v[ur.clone()], &v[wr.clone()]);
        let (mu, mw) = (&q[mur.clone()], &q[mwr.clone()]);
        let (mp, mq) = (&v[mur.clone()], &v[mwr.clone()]);
        let (gx, gy) = self.gravity(th);
        let m1 = m.m1(t);
        let burning = self.closing_burn || m.burning(t);

        // --- forces on stations and discrete masses (body components) ---
        self.fu.iter_mut().for_each(|f| *f = 0.0);
        self.fw.iter_mut().for_each(|f| *f = 0.0);
        operators::add_axial_forces(m.h, &m.ea, u, w, &mut self.fu, &mut self.fw);
        operators::add_bending_forces(m.h, &m.ei_station, w, &mut self.fw);
        for i in 0..ns {
            let mi = m.station_mass(i, m1);
            self.lumped[i] = mi;
            self.fu[i] += mi * gx;
            self.fw[i] += mi * gy;
        }
        let (mut p_thrust, mut p_press, mut p_cor, mut p_damp, mut p_out) =
            (0.0, 0.0, 0.0, 0.0, 0.0);
        // inertial velocity of station i in body components
        let vel = |i: usize| -> (f64, f64) {
            let (rx, ry) = (i as f64 * m.h + u[i], w[i]);
            (rr - tt * (yo + ry) + p[i], ss + tt * (xo + rx) + qv[i])
        };
        if burning {
            // Thrust, chamber pressure and jet Coriolis force are directed by the case's mean
            // axis (docs/rocket.md): angle α from this body axis, rate α̇.
            let axis = mean_axis(m, |i| (u[i], w[i]));
            let axis_rate = mean_axis(m, |i| (p[i], qv[i]));
            let alpha = axis.slope.atan();
            let alpha_rate = axis_rate.slope / (1.0 + axis.slope * axis.slope);
            let (ac, as_) = (alpha.cos(), alpha.sin());
            let flow = m.mass_flow(burning);
            let thrust = flow * m.exhaust_velocity;
            let (tx, ty) = (
                thrust * (m.gamma + alpha).cos(),
                thrust * (m.gamma + alpha).sin(),
            );
            let (px, py) = (m.pressure_force * ac, m.pressure_force * as_);
            self.fu[0] += tx - px;
            self.fw[0] += ty - py;
            let (l, al) = (m.l1_station, m.l1_alpha);
            self.fu[l] += (1.0 - al) * px;
            self.fu[l + 1] += al * px;
            self.fw[l] += (1.0 - al) * py;
            self.fw[l + 1] += al * py;
            let v0 = vel(0);
            p_thrust = tx * v0.0 + ty * v0.1;
            let (vl, vl1) = (vel(l), vel(l + 1));
            p_press = px * (-v0.0 + (1.0 - al) * vl.0 + al * vl1.0)
                + py * (-v0.1 + (1.0 - al) * vl.1 + al * vl1.1);
            // Coriolis force of the internal flow, 2θ̇ m_f v normal to the mean axis with
            // m_f v = ṁ (L₁ − x) (3.36, 5.18), θ̇ the mean axis' rate.
            let rate = tt + alpha_rate;
            if rate != 0.0 {
                for i in 0..ns {
                    let f = 2.0 * rate * m.burn_rate * m.flow_weight[i];
                    if f != 0.0 {
                        let (fx, fy) = (-f * as_, f * ac);
                        self.fu[i] += fx;
                        self.fw[i] += fy;
                        let vi = vel(i);
                        p_cor += fx * vi.0 + fy * vi.1;
                    }
                }
            }
            // Kinetic + potential energy carried away by the burnt mass (−ṁ_i per station).
            let (st, ct) = (th.sin(), th.cos());
            for i in 0..ns {
                let dm = m.burn_rate * m.st_burn_len[i];
                if dm > 0.0 {
                    let (vx, vy) = vel(i);
                    let (rx, ry) = (xo + i as f64 * m.h + u[i], yo + w[i]);
                    let height = st * rx + ct * ry;
                    p_out += dm * (0.5 * (vx * vx + vy * vy) + m.g * height);
                }
            }
        }
        // discrete masses: springs to the case, springs between masses, gravity
        for k in 0..m.masses.len() {
            let at = &m.masses[k];
            self.gu[k] = at.mass * gx;
            self.gw[k] = at.mass * gy;
            let (i, al) = (at.station, at.alpha);
            let uc = (1.0 - al) * u[i] + al * u[i + 1];
            let wc = (1.0 - al) * w[i] + al * w[i + 1];
            let pc = (1.0 - al) * p[i] + al * p[i + 1];
            let qc = (1.0 - al) * qv[i] + al * qv[i + 1];
            let fu = -at.ku * (mu[k] - uc) - at.cu * (mp[k] - pc);
            let fw = -at.kw * (mw[k] - wc) - at.cw * (mq[k] - qc);
            self.gu[k] += fu;
            self.gw[k] += fw;
            self.fu[i] -= (1.0 - al) * fu;
            self.fu[i + 1] -= al * fu;
            self.fw[i] -= (1.0 - al) * fw;
            self.fw[i + 1] -= al * fw;
            p_damp += at.cu * (mp[k] - pc).powi(2) + at.cw * (mq[k] - qc).powi(2);
        }
        for c in &m.couplings {
            let fu = -c.ku * (mu[c.a] - mu[c.b]) - c.cu * (mp[c.a] - mp[c.b]);
            let fw = -c.kw * (mw[c.a] - mw[c.b]) - c.cw * (mq[c.a] - mq[c.b]);
            self.gu[c.a] += fu;
            self.gu[c.b] -= fu;
            self.gw[c.a] += fw;
            self.gw[c.b] -= fw;
            p_damp += c.cu * (mp[c.a] - mp[c.b]).powi(2) + c.cw * (mq[c.a] - mq[c.b]).powi(2);
        }
        self.power = [p_thrust, p_press, p_cor, p_damp, p_out];

        // --- sums for the rigid equations (5.26–5.28 with 5.37) ---
        let (mut mt, mut mrx, mut mry, mut mr2, mut mp_, mut mq_, mut mrv) =
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut fx, mut fy, mut mom) = (0.0, 0.0, 0.0);
        for i in 0..ns {
            let mi = self.lumped[i];
            let (rx, ry) = (i as f64 * m.h + u[i], w[i]);
            mt += mi;
            mrx += mi * rx;
            mry += mi * ry;
            mr2 += mi * (rx * rx + ry * ry);
            mp_ += mi * p[i];
            mq_ += mi * qv[i];
            mrv += mi * (rx * p[i] + ry * qv[i]);
            fx += self.fu[i];
            fy += self.fw[i];
            mom += rx * self.fw[i] - ry * self.fu[i];
        }
        for (k, at) in m.masses.iter().enumerate() {
            let mi = at.mass;
            let (rx, ry) = (at.x + mu[k], mw[k]);
            mt += mi;
            mrx += mi * rx;
            mry += mi * ry;
            mr2 += mi * (rx * rx + ry * ry);
            mp_ += mi * mp[k];
            mq_ += mi * mq[k];
            mrv += mi * (rx * mp[k] + ry * mq[k]);
            fx += self.gu[k];
            fy += self.gw[k];
            mom += rx * self.gw[k] - ry * self.gu[k];
        }
        let b1 = fx + 2.0 * tt * (mt * ss + mq_) + tt * tt * (mt * xo + mrx);
        let b2 = fy - 2.0 * tt * (mt * rr + mp_) + tt * tt * (mt * yo + mry);
        let b3 = mom - 2.0 * tt * (rr * mrx + ss * mry + mrv) + tt * tt * (yo * mrx - xo * mry);
        let c1 = mt * yo + mry;
        let c2 = mt * xo + mrx;
        let d = xo * mrx + yo * mry + mr2;
        // Eliminate Ṙ, Ṡ: the pivot is the moment of inertia about the mass centre.
        let i_cm = d - (mry * c1 + mrx * c2) / mt;
        let tdot = (b3 + (mry * b1 - mrx * b2) / mt) / i_cm;
        let rdot = (b1 + tdot * c1) / mt;
        let sdot = (b2 - tdot * c2) / mt;
        a[IX] = rdot;
        a[IY] = sdot;
        a[ITH] = tdot;

        // --- elastic accelerations (5.40): F/m minus the rigid-frame acceleration ---
        for i in 0..ns {
            let (rx, ry) = (i as f64 * m.h + u[i], w[i]);
            let ax = rdot - tdot * (yo + ry) - 2.0 * tt * (ss + qv[i]) - tt * tt * (xo + rx);
            let ay = sdot + tdot * (xo + rx) + 2.0 * tt * (rr + p[i]) - tt * tt * (yo + ry);
            a[ur.start + i] = self.fu[i] / self.lumped[i] - ax;
            a[wr.start + i] = self.fw[i] / self.lumped[i] - ay;
        }
        for (k, at) in m.masses.iter().enumerate() {
            let (rx, ry) = (at.x + mu[k], mw[k]);
            let ax = rdot - tdot * (yo + ry) - 2.0 * tt * (ss + mq[k]) - tt * tt * (xo + rx);
            let ay = sdot + tdot * (xo + rx) + 2.0 * tt * (rr + mp[k]) - tt * tt * (yo + ry);
            a[mur.start + k] = self.gu[k] / at.mass - ax;
            a[mwr.start + k] = self.gw[k] / at.mass - ay;
        }
    }

    fn powers(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.power);
    }

    fn bound(&self, t: f64) -> Bound {
        let m = &self.model;
        let h2 = m.h * m.h;
        let mut best = Bound {
            sigma: f64::INFINITY,
            kind: BoundKind::Axial,
            site: 0,
        };
        let mut best2 = f64::INFINITY;
        for s in 0..m.segments() {
            let ms = m.seg_mass(s, t);
            let ax = h2 * ms / m.ea[s]; // 5.43
            let tr = h2 * h2 * ms / (4.0 * m.ei[s]); // 5.44
            if ax < best2 {
                best2 = ax;
                best.kind = BoundKind::Axial;
                best.site = s;
            }
            if tr < best2 {
                best2 = tr;
                best.kind = BoundKind::Transverse;
                best.site = s;
            }
        }
        // Discrete masses on springs: σ = 2/ω with ω² = Σk/M (same one-step limit as 5.41),
        // reduced for the dampers' ratio ζ = Σc/(2Mω).
        for (k, (at, (kk, cc))) in m.masses.iter().zip(spring_sums(m)).enumerate() {
            if kk > 0.0 {
                let omega = (kk / at.mass).sqrt();
                let f = crate::system::damped_step_factor(cc / (2.0 * at.mass * omega));
                let s2 = 4.0 * at.mass / kk * f * f;
                if s2 < best2 {
                    best2 = s2;
                    best.kind = BoundKind::DiscreteMass;
                    best.site = k;
                }
            }
        }
        best.sigma = best2.sqrt();
        best
    }

    fn stored_energies(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let m = &self.model;
        let m1 = m.m1(t);
        let (xo, yo, th) = (q[IX], q[IY], q[ITH]);
        let (rr, ss, tt) = (v[IX], v[IY], v[ITH]);
        let (u, w) = (&q[self.u_range()], &q[self.w_range()]);
        let (p, qv) = (&v[self.u_range()], &v[self.w_range()]);
        let (mu, mw) = (&q[self.mu_range()], &q[self.mw_range()]);
        let (mp, mq) = (&v[self.mu_range()], &v[self.mw_range()]);
        let (st, ct) = (th.sin(), th.cos());
        let (mut ke, mut pe) = (0.0, 0.0);
        let mut point = |mass: f64, rx: f64, ry: f64, pu: f64, qw: f64| {
            let vx = rr - tt * (yo + ry) + pu;
            let vy = ss + tt * (xo + rx) + qw;
            ke += 0.5 * mass * (vx * vx + vy * vy);
            pe += mass * m.g * (st * (xo + rx) + ct * (yo + ry));
        };
        for i in 0..m.stations {
            point(
                m.station_mass(i, m1),
                i as f64 * m.h + u[i],
                w[i],
                p[i],
                qv[i],
            );
        }
        for (k, at) in m.masses.iter().enumerate() {
            point(at.mass, at.x + mu[k], mw[k], mp[k], mq[k]);
        }
        let strain = operators::strain_energy(m.h, &m.ea, &m.ei_station, u, w);
        let mut spring = 0.0;
        for (k, at) in m.masses.iter().enumerate() {
            let (i, al) = (at.station, at.alpha);
            let uc = (1.0 - al) * u[i] + al * u[i + 1];
            let wc = (1.0 - al) * w[i] + al * w[i + 1];
            spring += 0.5 * at.ku * (mu[k] - uc).powi(2) + 0.5 * at.kw * (mw[k] - wc).powi(2);
        }
        for c in &m.couplings {
            spring +=
                0.5 * c.ku * (mu[c.a] - mu[c.b]).powi(2) + 0.5 * c.kw * (mw[c.a] - mw[c.b]).powi(2);
        }
        out.copy_from_slice(&[ke, strain, pe, spring]);
    }

    fn monitored(&self) -> Range<usize> {
        3..self.dofs()
    }

    fn damped(&self) -> bool {
        self.model.damped()
    }

    /// Burn-out, where thrust, chamber pressure, the jet's Coriolis force and the mass flow
    /// switch off (the mass per length keeps its value, with a kink).
    fn jumps(&self) -> Vec<f64> {
        let burnout = self.model.burnout_time();
        if burnout.is_finite() && burnout > 0.0 {
            vec![burnout]
        } else {
            Vec::new()
        }
    }

    fn close_stretch_at(&mut self, jump: Option<f64>) {
        self.closing_burn = jump.is_some();
    }
}

impl Outputs for RocketSystem {
    fn describe(&self, b: &Bound) -> String {
        let m = &self.model;
        match b.kind {
            BoundKind::DiscreteMass => {
                format!("discrete mass {} at x = {}", b.site + 1, m.masses[b.site].x)
            }
            _ => format!(
                "station {}, segment {} (x = {:.4}–{:.4}), stage {}",
                b.site,
                b.site,
                b.site as f64 * m.h,
                (b.site + 1) as f64 * m.h,
                m.seg_stage[b.site] + 1
            ),
        }
    }

    fn channels(&self) -> Vec<(String, &'static str)> {
        let mut c = vec![
            channel::spec::rocket_x(),
            channel::spec::rocket_y(),
            channel::spec::rocket_theta(),
            channel::spec::rocket_mass(),
            channel::spec::rocket_vx(),
            channel::spec::rocket_vy(),
        ];
        for k in 0..self.field_stations {
            c.push(channel::spec::rocket_axial(k));
        }
        for k in 0..self.field_stations {
            c.push(channel::spec::rocket_transverse(k));
        }
        for j in 1..=self.model.masses.len() {
            c.push(channel::spec::rocket_mass_axial(j));
            c.push(channel::spec::rocket_mass_transverse(j));
        }
        c
    }

    fn observe(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let (mt, mx, my, mp, mq) = self.moments(t, q, v);
        let (xo, yo, th) = (q[IX], q[IY], q[ITH]);
        let (rr, ss, tt) = (v[IX], v[IY], v[ITH]);
        let (cx, cy) = (xo + mx / mt, yo + my / mt);
        let (c, s) = (th.cos(), th.sin());
        // Rigid-body velocity of the body-frame point at the mass centre (what the rocket
        // equation describes). The elastic momentum m{p}, m{q} is zero by 5.37 up to what the
        // burnt mass carries away (Σ ṁ_i p_i), and is not part of the rigid translation.
        let _ = (mp, mq);
        let vbx = rr - tt * cy;
        let vby = ss + tt * cx;
        out[0] = c * cx - s * cy;
        out[1] = s * cx + c * cy;
        // Elastic channels are reported relative to the case's mean axis (ignition mass), the
        // frame-invariant definition shared with the modal backend, whose elastic modes are
        // m₀-orthogonal to the rigid motions; θ is the angle of that axis.
        let (u, w) = (&q[self.u_range()], &q[self.w_range()]);
        let axis = mean_axis(&self.model, |i| (u[i], w[i]));
        out[2] = th + axis.slope;
        out[3] = mt;
        out[4] = c * vbx - s * vby;
        out[5] = s * vbx + c * vby;
        let mut o = 6;
        let nf = self.field_stations;
        for k in 0..nf {
            out[o] = self.interp(u, k as f64 * self.model.length / (nf - 1) as f64) - axis.axial;
            o += 1;
        }
        for k in 0..nf {
            let x = k as f64 * self.model.length / (nf - 1) as f64;
            out[o] = self.interp(w, x) - axis.at(x);
            o += 1;
        }
        let (mu, mw) = (&q[self.mu_range()], &q[self.mw_range()]);
        for (k, at) in self.model.masses.iter().enumerate() {
            out[o] = mu[k] - axis.axial;
            out[o + 1] = mw[k] - axis.at(at.x);
            o += 2;
        }
    }

    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        (
            vec![
                ledger_term::KINETIC,
                ledger_term::STRAIN,
                ledger_term::GRAVITY,
                ledger_term::DISCRETE_SPRING,
            ],
            vec![
                ledger_term::THRUST,
                ledger_term::PRESSURE,
                ledger_term::CORIOLIS_FLOW,
            ],
            vec![ledger_term::DISCRETE_DAMPER, ledger_term::MASS_OUTFLOW],
        )
    }

    fn dof_name(&self, i: usize) -> String {
        let h = self.model.h;
        let (ur, wr, mur, mwr) = (
            self.u_range(),
            self.w_range(),
            self.mu_range(),
            self.mw_range(),
        );
        match i {
            IX => "rigid X".into(),
            IY => "rigid Y".into(),
            ITH => "attitude θ".into(),
            _ if ur.contains(&i) => format!(
                "axial u at station {} (x = {:.4})",
                i - ur.start,
                (i - ur.start) as f64 * h
            ),
            _ if wr.contains(&i) => format!(
                "transverse w at station {} (x = {:.4})",
                i - wr.start,
                (i - wr.start) as f64 * h
            ),
            _ if mur.contains(&i) => format!("axial U of discrete mass {}", i - mur.start + 1),
            _ if mwr.contains(&i) => format!("transverse W of discrete mass {}", i - mwr.start + 1),
            _ => format!("coordinate {i}"),
        }
    }
}

/// Mean axis of the case with respect to its ignition mass m₀ (lumped station masses, discrete
/// masses excluded): the mass-weighted mean of u and the weighted least-squares line of w.
#[derive(Debug, Clone, Copy)]
pub struct MeanAxis {
    pub axial: f64,
    pub offset: f64,
    pub slope: f64,
}

impl MeanAxis {
    /// Transverse position of the mean axis at x.
    pub fn at(&self, x: f64) -> f64 {
        self.offset + self.slope * x
    }
}

/// [`MeanAxis`] of the station field `field(i) = (u_i, w_i)`.
pub fn mean_axis(m: &RocketModel, field: impl Fn(usize) -> (f64, f64)) -> MeanAxis {
    let m1 = m.m1(0.0);
    let (mut s0, mut s1, mut s2, mut ru, mut r0, mut r1) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for i in 0..m.stations {
        let (x, mi) = (i as f64 * m.h, m.station_mass(i, m1));
        let (u, w) = field(i);
        s0 += mi;
        s1 += mi * x;
        s2 += mi * x * x;
        ru += mi * u;
        r0 += mi * w;
        r1 += mi * x * w;
    }
    let det = s0 * s2 - s1 * s1;
    MeanAxis {
        axial: ru / s0,
        offset: (s2 * r0 - s1 * r1) / det,
        slope: (s0 * r1 - s1 * r0) / det,
    }
}

/// Per discrete mass, the sums of the spring and damper constants acting on it (larger of axial
/// and transverse), as an iterator (no allocation).
fn spring_sums(m: &RocketModel) -> impl Iterator<Item = (f64, f64)> + '_ {
    m.masses.iter().enumerate().map(move |(k, at)| {
        let (mut ku, mut kw, mut cu, mut cw) = (at.ku, at.kw, at.cu, at.cw);
        for c in &m.couplings {
            if c.a == k || c.b == k {
                ku += c.ku;
                kw += c.kw;
                cu += c.cu;
                cw += c.cw;
            }
        }
        (ku.max(kw), cu.max(cw))
    })
}
