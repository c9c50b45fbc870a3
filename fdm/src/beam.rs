//! Finite-difference cantilever (clamped–free Euler–Bernoulli beam) on equal steps h.
//!
//! Stations 0…r; w₀ = 0 and the clamped ghost node w₋₁ = w₁ (zero slope by central difference);
//! the free end has the ghost nodes of the report's 5.32 (zero moment and shear). As for the
//! rocket, the stiffness is the Hessian of the discrete bending energy
//! V = ½ Σ_{i=0}^{r−1} c_i h EI κ_i², κ_i = (w_{i+1} − 2w_i + w_{i−1})/h², c₀ = ½ (half cell at
//! the clamp, κ₀ = 2w₁/h² from the ghost node), κ_r = 0 (free end), with trapezoid-lumped masses
//! (h inside, h/2 + tip mass at the free end). Its rows equal the ghost-node stencils
//! EI δ⁴w/h⁴ (tested), so the frequencies converge at O(h²).

use data::{
    BackendKind, Cost, DofPlan, ModalResult, ModeShape, Scene, StaticResult,
    scene::{PlanarChain, PrescribedMotion},
};
use faer::prelude::Solve;
use faer::{Mat, Side};

use crate::error::FdmError;
use crate::settings::ValidatedSettings;

/// Default stations for beams.
pub const DEFAULT_STATIONS: usize = 41;

/// The clamped-free beam of a supported scene.
#[derive(Debug, Clone)]
pub struct Cantilever {
    pub stations: usize,
    pub h: f64,
    pub length: f64,
    pub ei: f64,
    pub rho_a: f64,
    pub tip_mass: f64,
    /// Constant hub rate Ω (rotating beam), 0 for the cantilever.
    pub spin: f64,
    pub foreshortening: bool,
}

impl Cantilever {
    /// Accepts single clamped links of `pc`, the chain of `scene`, whose switched-on physics
    /// this module builds.
    pub fn from_planar_chain(
        scene: &Scene,
        pc: &PlanarChain,
        stations: Option<usize>,
    ) -> Result<Self, FdmError> {
        if pc.links.len() != 1 {
            return Err(FdmError::Unsupported(format!(
                "fdm: `{}` has {} links; only the single clamped link (cantilever family) is implemented for beams",
                scene.name,
                pc.links.len()
            )));
        }
        let l = &pc.links[0];
        let spin = match l.joint.prescribed {
            Some(PrescribedMotion::Fixed) => 0.0,
            Some(PrescribedMotion::ConstantRate { rate }) => l.joint.initial_rate + rate,
            _ => {
                return Err(FdmError::Unsupported(format!(
                    "fdm: modes/statics of `{}` need a fixed or constant-rate hub (its hub moves otherwise); use `run`",
                    scene.name
                )));
            }
        };
        FdmError::check_switches(
            &format!("`{}`", scene.name),
            "beam",
            &[
                ("axial", l.axial),
                ("shear", l.shear),
                ("rotary_inertia", l.rotary_inertia),
                ("kelvin_voigt", l.kelvin_voigt.is_some()),
                ("tip_inertia", l.tip_inertia.is_some()),
                ("gravity", pc.gravity.as_ref().is_some()),
                ("contact", !pc.contacts.is_empty()),
            ],
        )?;
        let n = stations.unwrap_or(DEFAULT_STATIONS);
        Ok(Cantilever {
            stations: n,
            h: l.length / (n - 1) as f64,
            length: l.length,
            ei: l.bending_stiffness,
            rho_a: l.mass_per_length,
            tip_mass: l.tip_mass.unwrap_or(0.0),
            spin,
            foreshortening: l.foreshortening,
        })
    }

    /// Unknowns w₁…w_r.
    pub fn dofs(&self) -> usize {
        self.stations - 1
    }

    /// Stiffness K (dense, symmetric) = Hessian of the bending energy in w₁…w_r.
    pub fn stiffness(&self) -> Mat<f64> {
        let n = self.dofs();
        let h = self.h;
        let mut k = Mat::<f64>::zeros(n, n);
        let c = self.ei / (h * h * h); // h·EI·(1/h²)²
        // κ₀ = 2 w₁ / h² with weight ½
        k[(0, 0)] += 0.5 * c * 4.0;
        // κ_i for i = 1…r−1 involves w_{i−1}, w_i, w_{i+1} (w₀ = 0 is not an unknown)
        for i in 1..n {
            let idx = [i as isize - 2, i as isize - 1, i as isize];
            let coef = [1.0, -2.0, 1.0];
            for a in 0..3 {
                for b in 0..3 {
                    if idx[a] >= 0 && idx[b] >= 0 {
                        k[(idx[a] as usize, idx[b] as usize)] += c * coef[a] * coef[b];
                    }
                }
            }
        }
        k
    }

    /// Lumped masses of w₁…w_r.
    pub fn masses(&self) -> Vec<f64> {
        let n = self.dofs();
        let mut m = vec![self.rho_a * self.h; n];
        m[n - 1] = 0.5 * self.rho_a * self.h + self.tip_mass;
        m
    }

    /// Stiffness of small in-plane vibrations about the straight beam spinning at Ω:
    /// K + Ω²(K_Φ − M) with K_Φ the Hessian of Φ = ½ Σ_seg h W_seg g_seg²,
    /// W_seg = Σ_{i > seg} m_i x_i (centrifugal tension from foreshortening; see [`crate::link`])
    /// and −Ω²M the in-plane centrifugal softening.
    pub fn rotating_stiffness(&self) -> Mat<f64> {
        let mut k = self.stiffness();
        if self.spin == 0.0 {
            return k;
        }
        let n = self.dofs();
        let m = self.masses();
        let w2 = self.spin * self.spin;
        for (i, mi) in m.iter().enumerate() {
            k[(i, i)] -= w2 * mi;
        }
        if self.foreshortening {
            // W_seg over segments 0…r−1 (segment s joins stations s, s+1; unknown j ↔ station j+1)
            let mut acc = 0.0;
            for seg in (0..n).rev() {
                acc += m[seg] * (seg + 1) as f64 * self.h;
                let c = w2 * acc / self.h;
                let (a, b) = (seg as isize - 1, seg);
                k[(b, b)] += c;
                if a >= 0 {
                    let a = a as usize;
                    k[(a, a)] += c;
                    k[(a, b)] -= c;
                    k[(b, a)] -= c;
                }
            }
        }
        k
    }

    /// Natural angular frequencies (ascending) and mass-normalized shapes (columns, w₁…w_r).
    pub fn eigen(&self) -> Result<(Vec<f64>, Mat<f64>), FdmError> {
        let k = self.rotating_stiffness();
        let m = self.masses();
        let n = self.dofs();
        let s: Vec<f64> = m.iter().map(|x| 1.0 / x.sqrt()).collect();
        let c = Mat::<f64>::from_fn(n, n, |i, j| s[i] * k[(i, j)] * s[j]);
        let evd = c
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| FdmError::Numerical {
                t: 0.0,
                message: format!("eigen decomposition failed: {e:?}"),
            })?;
        let lam = evd.S().column_vector();
        let u = evd.U();
        // A negative eigenvalue (linear model spun above its first frequency) is a divergent
        // mode: reported as −√|λ| so that it cannot pass for a frequency.
        let omega: Vec<f64> = (0..n)
            .map(|i| {
                if lam[i] >= 0.0 {
                    lam[i].sqrt()
                } else {
                    -(-lam[i]).sqrt()
                }
            })
            .collect();
        let shapes = Mat::<f64>::from_fn(n, n, |i, j| s[i] * u[(i, j)]);
        Ok((omega, shapes))
    }

    /// Static deflection under a tip force P and a uniform load q (trapezoid-lumped).
    pub fn static_deflection(&self, tip_force: f64, q: f64) -> Result<Vec<f64>, FdmError> {
        let n = self.dofs();
        let k = self.stiffness();
        let mut f = Mat::<f64>::zeros(n, 1);
        for i in 0..n {
            f[(i, 0)] = q * self.h;
        }
        f[(n - 1, 0)] = 0.5 * q * self.h + tip_force;
        let llt = k.llt(Side::Lower).map_err(|e| FdmError::Numerical {
            t: 0.0,
            message: format!("stiffness not positive definite: {e:?}"),
        })?;
        let x = llt.solve(&f);
        let mut w = vec![0.0];
        w.extend((0..n).map(|i| x[(i, 0)]));
        Ok(w)
    }
}

pub fn dof_plan(
    scene: &Scene,
    pc: &PlanarChain,
    stations: Option<usize>,
) -> Result<DofPlan, FdmError> {
    let c = Cantilever::from_planar_chain(scene, pc, stations)?;
    let mut plan = DofPlan::default();
    plan.add("transverse w at stations (clamp excluded)", c.dofs());
    if c.spin != 0.0 && c.foreshortening {
        plan.builds
            .push("foreshortening (centrifugal) stiffening".into());
    }
    if c.tip_mass > 0.0 {
        plan.builds
            .push("tip mass in the free-end shear condition".into());
    }
    Ok(plan)
}

pub fn modes(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
    count: usize,
) -> Result<ModalResult, FdmError> {
    let clock = std::time::Instant::now();
    let c = Cantilever::from_planar_chain(scene, pc, s.stations)?;
    let (omega, shapes) = c.eigen()?;
    let count = count.min(c.dofs());
    let x: Vec<f64> = (0..c.stations).map(|i| i as f64 * c.h).collect();
    let mut out_shapes = Vec::new();
    for j in 0..count {
        let mut t = vec![0.0];
        t.extend((0..c.dofs()).map(|i| shapes[(i, j)]));
        let mx = t
            .iter()
            .fold(0.0f64, |m, v| if v.abs() > m.abs() { *v } else { m });
        if mx != 0.0 {
            t.iter_mut().for_each(|v| *v /= mx);
        }
        out_shapes.push(ModeShape {
            link: 1,
            x: x.clone(),
            transverse: t,
        });
    }
    Ok(ModalResult {
        backend: BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        frequencies_hz: omega[..count]
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect(),
        kinds: vec!["bending".into(); count],
        shapes: out_shapes,
        cost: Cost {
            wall_time_s: clock.elapsed().as_secs_f64(),
            dofs: c.dofs(),
            factorizations: 1,
            ..Cost::default()
        },
    })
}

pub fn statics(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
) -> Result<StaticResult, FdmError> {
    if matches!(pc.links.as_slice(), [link] if link.shear) {
        return timoshenko_statics(scene, pc, s);
    }
    let clock = std::time::Instant::now();
    let c = Cantilever::from_planar_chain(scene, pc, s.stations)?;
    let st = pc
        .statics
        .as_ref()
        .ok_or_else(|| FdmError::Unsupported(format!("`{}` has no [statics] loads", scene.name)))?;
    let w = c.static_deflection(
        st.tip_force.unwrap_or(0.0),
        st.distributed_load.unwrap_or(0.0),
    )?;
    let r = w.len() - 1;
    // second-order one-sided slope at the free end
    let rot = (3.0 * w[r] - 4.0 * w[r - 1] + w[r - 2]) / (2.0 * c.h);
    Ok(StaticResult {
        backend: BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        tip_deflection: w[r],
        tip_rotation: rot,
        cost: Cost {
            wall_time_s: clock.elapsed().as_secs_f64(),
            dofs: c.dofs(),
            factorizations: 1,
            ..Cost::default()
        },
    })
}

/// Statics of a clamped Timoshenko cantilever (`cantilever-timoshenko`): the two-link chain's
/// discrete energy Σ ½EI(Δψ/h)²h + Σ ½κGA(Δv/h − ψ̄)²h on the link ([`crate::chain::timoshenko`]),
/// v₀ = ψ₀ = 0, tip force and lumped distributed load. Reported rotation: ψ(L) (the convention's
/// "slope"). Section rotary inertia does not enter statics (accepted); axial fields, tip
/// inertia, gravity and contact are refused as for the Euler beam.
fn timoshenko_statics(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
) -> Result<StaticResult, FdmError> {
    let clock = std::time::Instant::now();
    let l = &pc.links[0];
    if !matches!(l.joint.prescribed, Some(PrescribedMotion::Fixed)) {
        return Err(FdmError::Unsupported(format!(
            "fdm: statics of the Timoshenko link `{}` need a fixed clamp",
            scene.name
        )));
    }
    FdmError::check_switches(
        &format!("`{}`", scene.name),
        "Timoshenko beam statics",
        &[
            ("axial", l.axial),
            ("tip_inertia", l.tip_inertia.is_some()),
            ("gravity", pc.gravity.as_ref().is_some()),
            ("contact", !pc.contacts.is_empty()),
        ],
    )?;
    let kga = crate::chain::timoshenko::shear_stiffness(&scene.name, l)?;
    let st = pc
        .statics
        .as_ref()
        .ok_or_else(|| FdmError::Unsupported(format!("`{}` has no [statics] loads", scene.name)))?;
    let n = s.stations.unwrap_or(DEFAULT_STATIONS);
    let (v, psi) = crate::chain::timoshenko::TimoFields::cantilever_statics(
        l.length,
        l.bending_stiffness,
        kga,
        n - 1,
        st.tip_force.unwrap_or(0.0),
        st.distributed_load.unwrap_or(0.0),
    );
    Ok(StaticResult {
        backend: BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        tip_deflection: v,
        tip_rotation: psi,
        cost: Cost {
            wall_time_s: clock.elapsed().as_secs_f64(),
            dofs: 2 * (n - 1),
            factorizations: 1,
            ..Cost::default()
        },
    })
}

/// Dynamic beam scenes are not implemented in this backend.
pub fn simulate_unsupported(scene: &Scene) -> FdmError {
    FdmError::Unsupported(format!(
        "fdm: time integration of the clamped cantilever (`{}`) is not run (free vibration from \
         rest is trivial); use `modes`/`statics`",
        scene.name
    ))
}
