//! The model side of the backend: a semi-discrete mechanical system q̇ = v, v̇ = a(t, q, v)
//! (physics only: state layout, accelerations, powers, stored energies, the step bound of its
//! spectrum). Time stepping lives in [`crate::method`], events in [`crate::events`],
//! the loop in [`crate::driver`] and the output mapping in
//! [`crate::output`].
//!
//! **Step bound.** A model reports the report's σ = min_i σ_i (5.43–5.45) at time t: 2/ω_max
//! of its discrete operator per segment or station, times [`damped_step_factor`] where a
//! Kelvin–Voigt or discrete damper acts. The method scales it by its own factor
//! ([`crate::method::Stepper::bound_factor`]) and the user's safety factor.

use data::scene::{LinkField, TorqueLaw};

/// Which stability bound is binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundKind {
    Axial,
    Transverse,
    /// Bending plus the string-like geometric stiffness of a tension (the centrifugal tension
    /// N(x) of a spinning link's foreshortening): ω² ≤ (bending row + N row)/m per station.
    TransverseTension,
    /// A discrete mass on its springs (not in the report's 5.45; checked so that no step is ever
    /// taken above a known limit).
    DiscreteMass,
    /// One elastic field of the 3-D payload link (its lumped operator's bound).
    LinkField(LinkField),
}

impl BoundKind {
    pub fn name(self) -> &'static str {
        match self {
            BoundKind::Axial => "axial",
            BoundKind::Transverse => "transverse",
            BoundKind::TransverseTension => "transverse (bending + centrifugal tension)",
            BoundKind::DiscreteMass => "discrete-mass",
            BoundKind::LinkField(f) => match f {
                LinkField::Axial => "axial (u)",
                LinkField::Horizontal => "horizontal (v)",
                LinkField::Vertical => "vertical (w)",
                LinkField::Torsion => "torsion (phi)",
            },
        }
    }
}

/// Factor on the undamped limit 2/ω for a mode with damping ratio ζ: the one-step velocity
/// form (damping evaluated at the predicted velocity) is stable for ωτ ≤ 2(√(1 + 4ζ²) − 2ζ).
pub fn damped_step_factor(zeta: f64) -> f64 {
    (1.0 + 4.0 * zeta * zeta).sqrt() - 2.0 * zeta
}

/// The report's step limit σ = min_i σ_i (5.43–5.45) at some time, and where it is attained.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub sigma: f64,
    pub kind: BoundKind,
    /// Segment (or discrete-mass) index where the minimum is attained.
    pub site: usize,
}

/// A semi-discrete mechanical system q̇ = v, v̇ = a(t, q, v).
pub trait System {
    /// Number of generalized coordinates (length of q, v, a).
    fn dofs(&self) -> usize;
    /// Accelerations; also stores the input/dissipation powers at this state for the ledger.
    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]);
    /// Accelerations with the dissipative and applied forces at `v` (the predicted step-end
    /// velocity) and the inertia terms quadratic in the velocities, Γ(q)[q̇, q̇] =
    /// (∂p/∂q)q̇ − ∂T/∂q, from the drift velocities: (1 + w)Γ[v_{j+½}] − wΓ[v_{j−½}]
    /// ([`crate::method::velocity_form`]). Systems without velocity-quadratic inertia terms
    /// keep the default, [`System::accel`] at `v`.
    fn accel_split(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        inertia: DriftVelocities,
        a: &mut [f64],
    ) {
        let _ = inertia;
        self.accel(t, q, v, a);
    }
    /// Whether the kinetic energy depends on the configuration, so that [`System::accel_split`]
    /// has inertia terms quadratic in the velocities (the velocity form then evaluates them
    /// time-symmetrically without implicit damping: [`crate::method::velocity_form`]).
    fn has_velocity_quadratic_inertia(&self) -> bool {
        false
    }
    /// The velocity form's closing kick with the damping implicit (Crank–Nicolson in the
    /// damping across the step): writes a with (M + ½τC) a = F(q, v_{j+½}) (damping C at the
    /// drift velocity `inertia.current`, inertia terms as [`System::accel_split`], other
    /// velocity-dependent forces at the drift or the predicted velocity as the system
    /// documents), so that
    /// v_{j+1} = v_{j+½} + ½τa carries −½τM⁻¹C v_{j+1}; stores the powers at v_{j+1}. Returns
    /// false (a untouched) for systems whose damping is explicit (the default).
    fn implicit_kick(
        &mut self,
        t: f64,
        q: &[f64],
        inertia: DriftVelocities,
        tau: f64,
        a: &mut [f64],
    ) -> bool {
        let _ = (t, q, inertia, tau, a);
        false
    }
    /// Powers stored by the last [`System::accel`] call: inputs then dissipations (the order
    /// of [`crate::output::Outputs::ledger_names`]).
    fn powers(&self, out: &mut [f64]);
    /// The report's step bound σ at time t (before the method factor and safety factor).
    fn bound(&self, t: f64) -> Bound;
    /// Projects the positions of a new level onto the active holonomic constraints, before its
    /// force evaluation (event objects switch constraints on and off: [`crate::events`]).
    /// Default: no constraints.
    fn project_position(&mut self, q: &mut [f64]) {
        let _ = q;
    }
    /// Projects the step-end velocities onto the active constraints, after the final kick.
    fn project_velocity(&mut self, v: &mut [f64]) {
        let _ = v;
    }
    /// Stored energies at (t, q, v), in the order of the ledger's stored terms.
    fn stored_energies(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]);
    /// Coordinates whose growth is monitored for the computational mode (elastic DOFs).
    fn monitored(&self) -> std::ops::Range<usize>;
    /// Whether any force depends on the velocities through damping or a velocity-coupled
    /// (gyroscopic) term: the two-step scheme's computational mode can then grow.
    fn damped(&self) -> bool;
    /// Times t > 0 where an applied law jumps (torque switches, burn-out): the driver steps onto
    /// them ([`crate::method::AtJumps`]).
    /// Default: none.
    fn jumps(&self) -> Vec<f64> {
        Vec::new()
    }
    /// While `Some(t_jump)`, the force and power evaluations take the applied laws at their
    /// value on the stretch that ends at t_jump, their left limit there, whatever time they are
    /// at: the driver sets it for a step that ends on that jump, every evaluation of which
    /// (the closing kick, an event's re-taken steps) lies inside the stretch. `None` (the
    /// default): the laws at the evaluation's time, right-continuous.
    fn close_stretch_at(&mut self, jump: Option<f64>) {
        let _ = jump;
    }
    /// The first link whose transverse tip deflection exceeds its length at q: beyond it the
    /// beam models (linear or small-strain floating frame) no longer describe the link, and
    /// the driver stops the run with a diagnostic. Default: no link to check.
    fn overextended(&self, q: &[f64]) -> Option<Overextension> {
        let _ = q;
        None
    }
}

/// A link whose transverse tip deflection left the model's range ([`System::overextended`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overextension {
    /// 1-based link number.
    pub link: usize,
    pub deflection: f64,
    pub length: f64,
    /// Which model's range the deflection left.
    pub model: DeflectionModel,
}

/// The beam model whose range a deflection left ([`Overextension`]): it decides the diagnostic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeflectionModel {
    /// A linear link (no geometric stiffening): spun above its first bending frequency it has
    /// no centrifugal stiffness left and grows without bound.
    Linear,
    /// A small-strain floating-frame link with foreshortening.
    SmallStrain,
    /// The two-link chain: its bending energy and foreshortening are small-slope ones about
    /// each link's tip chord (its coordinates), so each clamp slope against the chord must
    /// stay well below 1.
    ChordFrames,
}

/// The drift velocities of the velocity form for the inertia terms quadratic in q̇
/// ([`System::accel_split`]): Γ at the step end t_{j+1} is (1 + w)Γ(`current`) − wΓ(`previous`)
/// (both at q_{j+1}) — extrapolated linearly from v_{j+½} and v_{j−½}, or, with w = −½ and
/// `previous` an estimate of v_{j+3/2}, their time-symmetric mean.
#[derive(Debug, Clone, Copy)]
pub struct DriftVelocities<'a> {
    /// v_{j+½}, the drift velocity of the step just taken
    pub current: &'a [f64],
    /// v_{j−½}, the previous step's drift velocity (the first step: `current`, w = 0), or the
    /// estimate of v_{j+3/2} (w = −½)
    pub previous: &'a [f64],
    /// w = τ_{j+1}/(τ_{j+1} + τ_j) (½ for equal steps) to extrapolate; −½ for the mean; −1
    /// for `previous` alone (a restartable implicit kick passes the predicted velocity there)
    pub w: f64,
    /// v_pred = v_{j+½} + ½τa_j, the predicted step-end velocity (where
    /// [`System::accel_split`] takes the velocity-dependent forces; an implicit kick may take
    /// the forces other than the implicit damping there)
    pub predicted: &'a [f64],
}

/// An applied torque law at t, or at the left limit of the jump a closed stretch ends on
/// ([`System::close_stretch_at`]); 0 without a law.
pub(crate) fn law_torque(law: Option<&TorqueLaw>, t: f64, closing: Option<f64>) -> f64 {
    match (law, closing) {
        (Some(l), Some(jump)) => l.torque_before(jump),
        (Some(l), None) => l.torque(t),
        (None, _) => 0.0,
    }
}

/// The jump times t > 0 of `laws`, sorted, each once ([`System::jumps`]).
pub(crate) fn law_jumps<'a>(laws: impl IntoIterator<Item = &'a TorqueLaw>) -> Vec<f64> {
    let mut jumps: Vec<f64> = laws
        .into_iter()
        .flat_map(TorqueLaw::breakpoints)
        .filter(|t| *t > 0.0)
        .collect();
    jumps.sort_by(f64::total_cmp);
    jumps.dedup();
    jumps
}

#[cfg(test)]
mod tests {
    use super::{BoundKind, damped_step_factor};
    use data::scene::LinkField;

    /// The 3-D link's refusal names the field as the scene spells it: "axial (u)".
    #[test]
    fn elem_link_field_bound_names_field_and_symbol() {
        for f in LinkField::ALL {
            assert_eq!(
                BoundKind::LinkField(f).name(),
                format!("{} ({})", f.name(), f.symbol())
            );
        }
    }

    /// log of the spectral radius of the velocity form's step matrix on (x, v, a) for
    /// ẍ + cẋ + ω²x = 0, from ‖A^(2^k)‖ by repeated squaring.
    fn log_radius(w: f64, c: f64, t: f64) -> f64 {
        let mut a = [
            [1.0, t, 0.5 * t * t],
            [
                -t * w * w / 2.0,
                1.0 - t * (w * w * t + c) / 2.0,
                t / 2.0 - t * (w * w * t * t / 2.0 + c * t) / 2.0,
            ],
            [-w * w, -(w * w * t + c), -(w * w * t * t / 2.0 + c * t)],
        ];
        let mut log_scale = 0.0;
        let squarings = 14;
        for _ in 0..squarings {
            let mut b = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    b[i][j] = (0..3).map(|k| a[i][k] * a[k][j]).sum();
                }
            }
            let norm = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for row in &mut b {
                for v in row.iter_mut() {
                    *v /= norm;
                }
            }
            log_scale = 2.0 * log_scale + norm.ln();
            a = b;
        }
        log_scale / 2f64.powi(squarings)
    }

    #[test]
    fn elem_damped_velocity_form_limit_is_sharp() {
        for zeta in [0.05, 0.1, 0.3, 0.5, 1.0] {
            let limit = 2.0 * damped_step_factor(zeta);
            let (w, c) = (1.0, 2.0 * zeta);
            // inside: decays (log ρ < 0); outside by 2 %: grows (log ρ > 0). Repeated squaring to
            // 2^14 steps resolves |log ρ| down to ≈ 1e-3 relative to the transient polynomial factor.
            assert!(log_radius(w, c, 0.98 * limit) < 0.0, "ζ = {zeta} inside");
            assert!(log_radius(w, c, 1.02 * limit) > 0.0, "ζ = {zeta} outside");
        }
    }
}
