//! Station grid, segment properties and mass bookkeeping of the rocket (report §5.2: equal
//! spatial steps h, stations 0…r, uniform segments).

use data::scene::Rocket;

use crate::error::FdmError;

/// One discrete mass attached between two stations (linear interpolation weights, so that the
/// attachment need not fall on a station; with h = 2 in, x = 125 in lies half-way).
#[derive(Debug, Clone)]
pub struct Attachment {
    pub station: usize,
    pub alpha: f64,
    pub x: f64,
    pub mass: f64,
    pub ku: f64,
    pub kw: f64,
    pub cu: f64,
    pub cw: f64,
}

/// Spring/damper between two discrete masses.
#[derive(Debug, Clone)]
pub struct Coupling {
    pub a: usize,
    pub b: usize,
    pub ku: f64,
    pub kw: f64,
    pub cu: f64,
    pub cw: f64,
}

/// The discretized rocket: everything that does not change during a run.
#[derive(Debug, Clone)]
pub struct RocketModel {
    pub stations: usize,
    pub h: f64,
    pub length: f64,
    pub l1: f64,
    pub g: f64,
    pub theta0: f64,
    /// Per segment (stations s, s+1): axial and bending stiffness (series average where a
    /// segment straddles a stage junction), non-burning mass per length, stage-1 fraction.
    pub ea: Vec<f64>,
    pub ei: Vec<f64>,
    pub seg_fixed_mass: Vec<f64>,
    pub seg_burn_frac: Vec<f64>,
    pub seg_stage: Vec<usize>,
    /// Per station: EI averaged over the two adjacent half-segments (bending energy weight).
    pub ei_station: Vec<f64>,
    /// Per station: lumped non-burning mass, and the station's stage-1 length (trapezoid weight).
    pub st_fixed_mass: Vec<f64>,
    pub st_burn_len: Vec<f64>,
    /// Stage-1 mass per length at ignition, casing floor, burn rate (mass per length per time).
    pub m1_0: f64,
    pub m1_casing: f64,
    pub burn_rate: f64,
    pub exhaust_velocity: f64,
    pub gamma: f64,
    /// Chamber-pressure force p·A_f (p − p_e acting on the port area).
    pub pressure_force: f64,
    /// Station index and weight of the forward pressure force at x = L₁.
    pub l1_station: usize,
    pub l1_alpha: f64,
    /// Per station: ∫ hat_i (L₁ − x)₊ dx over stage 1, the weight of m_f v = ṁ (L₁ − x).
    pub flow_weight: Vec<f64>,
    pub masses: Vec<Attachment>,
    pub couplings: Vec<Coupling>,
}

impl RocketModel {
    pub fn new(r: &Rocket, stations: usize) -> Result<Self, FdmError> {
        if r.stages.is_empty() {
            return Err(FdmError::Unsupported("rocket without stages".into()));
        }
        if r.exit_pressure != 0.0 {
            return Err(FdmError::Unsupported(
                "rocket exit pressure p_e ≠ 0 (the report's vacuum expansion, 5.16, assumes p_e = 0)"
                    .into(),
            ));
        }
        let g = r.gravity;
        let length = r.length();
        let nseg = stations - 1;
        let h = length / nseg as f64;
        let mut bounds = Vec::new();
        let mut a = 0.0;
        for s in &r.stages {
            bounds.push((a, a + s.length));
            a += s.length;
        }
        let l1 = r.stages[0].length;
        let e = r.youngs_modulus;
        let (mut ea, mut ei, mut fixed, mut frac, mut stage) = (
            vec![0.0; nseg],
            vec![0.0; nseg],
            vec![0.0; nseg],
            vec![0.0; nseg],
            vec![0; nseg],
        );
        for s in 0..nseg {
            let (xa, xb) = (s as f64 * h, (s + 1) as f64 * h);
            let (mut inv_ea, mut inv_ei, mut best) = (0.0, 0.0, (0.0, 0));
            for (k, (st, (ba, bb))) in r.stages.iter().zip(&bounds).enumerate() {
                let o = (bb.min(xb) - ba.max(xa)).max(0.0) / h;
                if o <= 0.0 {
                    continue;
                }
                inv_ea += o / (e * st.area);
                inv_ei += o / (e * st.inertia);
                if k == 0 {
                    frac[s] = o;
                } else {
                    fixed[s] += o * st.weight_per_length / g;
                }
                if o > best.0 {
                    best = (o, k);
                }
            }
            ea[s] = 1.0 / inv_ea;
            ei[s] = 1.0 / inv_ei;
            stage[s] = best.1;
        }
        let mut ei_station = vec![0.0; stations];
        let mut st_fixed = vec![0.0; stations];
        let mut st_burn = vec![0.0; stations];
        let mut flow_weight = vec![0.0; stations];
        for i in 0..stations {
            let mut w = 0.0;
            let mut eis = 0.0;
            for s in [i.wrapping_sub(1), i] {
                if s < nseg {
                    st_fixed[i] += 0.5 * h * fixed[s];
                    st_burn[i] += 0.5 * h * frac[s];
                    eis += ei[s];
                    w += 1.0;
                }
            }
            ei_station[i] = eis / w;
            flow_weight[i] = st_burn[i] * (l1 - i as f64 * h).max(0.0);
        }
        let s1 = &r.stages[0];
        let m1_0 = s1.weight_per_length / g;
        let m1_casing = s1.casing_weight_per_length.unwrap_or(0.0) / g;
        let burn_rate = s1.burn_rate / g;
        let l1_pos = l1 / h;
        let l1_station = (l1_pos.floor() as usize).min(nseg - 1);
        let l1_alpha = l1_pos - l1_station as f64;
        let mut masses = Vec::new();
        for (k, dm) in r.discrete_masses.iter().enumerate() {
            if !(0.0..=length).contains(&dm.position) {
                return Err(FdmError::invalid(
                    "rocket.discrete_mass",
                    format!(
                        "mass {} at x = {} lies outside the body",
                        k + 1,
                        dm.position
                    ),
                ));
            }
            let pos = dm.position / h;
            let st = (pos.floor() as usize).min(nseg - 1);
            masses.push(Attachment {
                station: st,
                alpha: pos - st as f64,
                x: dm.position,
                mass: dm.weight / g,
                ku: dm.axial_stiffness,
                kw: dm.transverse_stiffness,
                cu: dm.axial_damping,
                cw: dm.transverse_damping,
            });
        }
        let mut couplings = Vec::new();
        for sp in &r.springs {
            let [a, b] = sp.between;
            if a >= masses.len() || b >= masses.len() || a == b {
                return Err(FdmError::invalid(
                    "rocket.spring",
                    format!("spring between masses {a} and {b}: no such pair"),
                ));
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
        Ok(RocketModel {
            stations,
            h,
            length,
            l1,
            g,
            theta0: r.launch_angle_deg.to_radians(),
            ea,
            ei,
            seg_fixed_mass: fixed,
            seg_burn_frac: frac,
            seg_stage: stage,
            ei_station,
            st_fixed_mass: st_fixed,
            st_burn_len: st_burn,
            m1_0,
            m1_casing,
            burn_rate,
            exhaust_velocity: r.exhaust_velocity,
            gamma: r.nozzle_angle_deg.to_radians(),
            pressure_force: r.chamber_pressure * r.port_area,
            l1_station,
            l1_alpha,
            flow_weight,
            masses,
            couplings,
        })
    }

    pub fn segments(&self) -> usize {
        self.stations - 1
    }

    /// Time at which stage 1 reaches its casing mass (∞ if it never burns).
    pub fn burnout_time(&self) -> f64 {
        if self.burn_rate > 0.0 {
            (self.m1_0 - self.m1_casing) / self.burn_rate
        } else {
            f64::INFINITY
        }
    }

    pub fn burning(&self, t: f64) -> bool {
        t < self.burnout_time()
    }

    /// Stage-1 mass per length at time t.
    pub fn m1(&self, t: f64) -> f64 {
        (self.m1_0 - self.burn_rate * t).max(self.m1_casing)
    }

    /// Mass per length of segment s at time t.
    pub fn seg_mass(&self, s: usize, t: f64) -> f64 {
        self.seg_fixed_mass[s] + self.seg_burn_frac[s] * self.m1(t)
    }

    /// Lumped (trapezoid-weighted) mass of station i at time t (5.14).
    pub fn station_mass(&self, i: usize, m1: f64) -> f64 {
        self.st_fixed_mass[i] + self.st_burn_len[i] * m1
    }

    /// Mass flow leaving through the nozzle while the stage burns, ṁ_total = ∫₀^{L₁} ṁ dx =
    /// m_f(0) v_e (5.18); 0 after burn-out.
    pub fn mass_flow(&self, burning: bool) -> f64 {
        if burning {
            self.burn_rate * self.st_burn_len.iter().sum::<f64>()
        } else {
            0.0
        }
    }

    /// Total mass M(t) = m{1} (5.14 with f = 1), discrete masses included.
    pub fn total_mass(&self, t: f64) -> f64 {
        let m1 = self.m1(t);
        (0..self.stations)
            .map(|i| self.station_mass(i, m1))
            .sum::<f64>()
            + self.masses.iter().map(|m| m.mass).sum::<f64>()
    }

    pub fn damped(&self) -> bool {
        self.masses.iter().any(|m| m.cu > 0.0 || m.cw > 0.0)
            || self.couplings.iter().any(|c| c.cu > 0.0 || c.cw > 0.0)
    }
}
