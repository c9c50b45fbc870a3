//! The discretized system as the methods see it: the [`System`] trait.
//!
//! A system is a set of n second-order equations in the generalized coordinates q,
//!
//!   R(t, q, q̇, q̈) = M(q) q̈ + F_in(q, q̇) + ∂V/∂q(t, q) − Q(t, q, q̇) = 0,
//!
//! with M(q) symmetric positive semi-definite (zero rows: massless directions), F_in the
//! velocity terms of the inertia (for T = ½q̇ᵀM(q)q̇: Ṁq̇ − ∂T/∂q), V the potential (strain,
//! springs, gravity) and Q the non-conservative generalized forces (applied forces and
//! torques, dampers, internal damping). R is affine in q̈. The residual splits into the three
//! groups of [`Parts`] — inertia M q̈ + F_in, conservative ∂V/∂q, non-conservative −Q — whose
//! sum is the full residual; the inertia group alone at zero rates gives the mass product
//! M(q)x = R_in(q, 0, x).
//!
//! Newton matrix: S = c_a ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q ([`NewtonCoefficients`]) at the state
//! of the last full residual, stored in the crate's bordered-band pattern ([`BorderedBand`]).
//! A system whose exact S is dense in q but sparse with auxiliary unknowns (the running sums of
//! a chain's foreshortening) gives its [`System::Augmented`] layout; the methods then solve the
//! augmented system with zero auxiliary right-hand sides ([`crate::method::newton`]).
//!
//! M may also depend on t (the burning rocket, [`crate::rocket::system`]: M(t)q̈ = F, the
//! burnt mass leaving at the local velocity). Every evaluation takes it at the time it is given,
//! the Newton matrix at the time of the last full residual; a method that steps such a system
//! keeps no M from one step to the next (the capability
//! [`crate::method::Capabilities::variable_mass`]).
//!
//! Energies E = T + V with T = ½q̇ᵀM(q)q̇, and the gradient ∂T/∂q(q, x) of T at generalized
//! velocity x: the energy-consistent method ([`crate::method::energy_midpoint`]) builds its
//! discrete gradient from them. Its ledger books the works of a step with the same midpoint
//! quadrature ([`System::midpoint_works`]), so E₁ − E₀ equals the booked work to the Newton
//! tolerance; the other methods leave the booking to their driver.
//!
//! The trait is the problem of the problem / method / events split: methods
//! ([`crate::method`]) step any `S: System`, a held constraint
//! ([`crate::method::StepConstraint`]) is implemented for a particular system (the tip contact
//! for [`crate::chain::Chain`], which needs its tip kinematics).

use crate::band::BorderedBand;

/// Which force groups [`System::residual_parts`] includes. The energy-consistent integrator
/// needs them apart: the inertial operator alone gives mass products M(q)x = R_in(q, 0, x) and
/// the velocity terms R_in(q, v, 0) = Ṁv − ∂T/∂q; the conservative group is ∇V; the rest is −Q.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parts {
    /// Σ m Jᵀ r̈ (with hub and tip rotary inertias).
    pub inertia: bool,
    /// ∂V/∂q: strain, joint springs, gravity.
    pub conservative: bool,
    /// −Q: applied joint torques and loads, joint dampers, Kelvin–Voigt.
    pub nonconservative: bool,
}

impl Parts {
    pub const ALL: Parts = Parts {
        inertia: true,
        conservative: true,
        nonconservative: true,
    };
    pub const INERTIA: Parts = Parts {
        inertia: true,
        conservative: false,
        nonconservative: false,
    };
    pub const CONSERVATIVE: Parts = Parts {
        inertia: false,
        conservative: true,
        nonconservative: false,
    };
    pub const NONCONSERVATIVE: Parts = Parts {
        inertia: false,
        conservative: false,
        nonconservative: true,
    };
}

/// What the Newton matrix is a derivative of: S = c_a ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q.
#[derive(Debug, Clone, Copy)]
pub struct NewtonCoefficients {
    pub c_a: f64,
    pub c_v: f64,
    pub c_q: f64,
}

/// Running energy-ledger integrals (cumulative works), one per ledger term.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Works {
    pub applied_torque: f64,
    pub applied_load: f64,
    pub prescribed_motion: f64,
    pub joint_damper: f64,
    pub kelvin_voigt: f64,
    /// Strain energy removed by projecting the massless section rotations onto their balance
    /// (`crate::events::massless`, ledger `numerical_massless`).
    pub numerical_massless: f64,
}

/// The auxiliary unknowns of an augmented Newton matrix: where the n system DOFs sit among
/// its rows; the other rows carry zero right-hand sides.
pub trait Augmentation {
    /// Augmented index of every system DOF.
    fn map(&self) -> &[usize];
    /// Number of augmented unknowns (DOFs and auxiliary ones).
    fn size(&self) -> usize;
}

/// The augmentation of a system whose band Newton matrix is exact: no value exists, so
/// [`System::exact_newton_matrix`] is never reached.
#[derive(Debug, Clone, Copy)]
pub enum NoAugmentation {}

impl Augmentation for NoAugmentation {
    fn map(&self) -> &[usize] {
        match *self {}
    }
    fn size(&self) -> usize {
        match *self {}
    }
}

/// A discretized system R(t, q, q̇, q̈) = 0 (module docs): the operations the time-integration
/// methods need. Methods that evaluate the Newton matrix first evaluate the full residual at
/// the same state (the matrix may read data of that pass).
pub trait System {
    /// Auxiliary unknowns of the exact Newton matrix ([`NoAugmentation`] where the band of
    /// [`System::new_matrix`] is exact).
    type Augmented: Augmentation;

    /// Number of unknowns n.
    fn ndof(&self) -> usize;

    /// R(t, q, q̇, q̈) into `res` (all groups); leaves the state data the Newton matrix reads.
    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]);

    /// The groups `parts` of R into `res` ([`Parts`]); with [`Parts::INERTIA`] and q̇ = 0 the
    /// mass product M(q)q̈.
    fn residual_parts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    );

    /// The groups `parts` (no inertia) at (t, q, q̇, 0), where the last evaluation of the
    /// residual or of its groups was at the same (t, q) (any rates, any groups): it may reuse
    /// that pass's configuration data (equal to [`System::residual_parts`] at (t, q, q̇, 0) up
    /// to the sign of exact zeros).
    fn residual_parts_at_last_q(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parts: Parts,
        res: &mut [f64],
    );

    /// Adds `sign`·∂T/∂q(t, q, x) to `out`, T = ½xᵀM(q)x the kinetic energy at generalized
    /// velocity x.
    fn add_kinetic_gradient(&mut self, t: f64, q: &[f64], x: &[f64], sign: f64, out: &mut [f64]);

    /// Stored energies at (t, q, q̇): kinetic T and the potential V in three parts (strain,
    /// springs, gravity; their sum is what the methods use).
    fn energies(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 4];

    /// The potential parts (strain, springs, gravity) of [`System::energies`] at (t, q), where
    /// the last evaluation of the residual or of its groups was at the same q (any time, rates
    /// and groups): it may reuse that pass's configuration data where they do not depend on
    /// time. By default the energies at (t, q, q), whose potential parts do not depend on the
    /// rates.
    fn potential_at_last_q(&mut self, t: f64, q: &[f64]) -> [f64; 3] {
        let [_, strain, springs, gravity] = self.energies(t, q, q);
        [strain, springs, gravity]
    }

    /// Whether M(q) has massless directions (zero rows): the start then treats them as
    /// algebraic ([`crate::method::start`]).
    fn has_massless_dofs(&self) -> bool;

    /// A Newton-matrix container with the pattern of the system DOFs.
    fn new_matrix(&self) -> BorderedBand;

    /// S = c_a M + c_v C + c_q K of the system DOFs into `s`, at the state of the last
    /// [`System::residual`] (exact where [`System::exact_layout`] is `None`).
    fn newton_matrix(&self, q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand);

    /// The augmentation of the exact Newton matrix, `None` (the default) where
    /// [`System::newton_matrix`] is exact.
    fn exact_layout(&self) -> Option<Self::Augmented> {
        None
    }

    /// A container with the pattern of `layout` (by default, for a system whose band matrix is
    /// exact, the band container).
    fn new_augmented_matrix(&self, _layout: &Self::Augmented) -> BorderedBand {
        self.new_matrix()
    }

    /// The exact S at (q, q̇, q̈) as the augmented matrix of `layout`; the last
    /// [`System::residual`] must have been at that state (by default, for a system whose band
    /// matrix is exact, [`System::newton_matrix`]).
    fn exact_newton_matrix(
        &self,
        q: &[f64],
        _qd: &[f64],
        _qdd: &[f64],
        c: NewtonCoefficients,
        _layout: &Self::Augmented,
        s: &mut BorderedBand,
    ) {
        self.newton_matrix(q, c, s);
    }

    /// The ledger terms of a step q₀ → q₀ + Δq of length h by the midpoint rule, every
    /// non-conservative force at t_mid and the mean velocity v̄ = Δq/h: an applied force books
    /// its work Q·Δq, a damper the energy it dissipates, −Q·Δq = h·P(v̄). `minus_q` is
    /// −Q(t_mid, q̄, v̄), the non-conservative group of R: the terms account for its whole work
    /// −minus_q·Δq. Also sets what the system reports as applied forces to their values at
    /// `t_law` (the step's sample time).
    fn midpoint_works(
        &mut self,
        h: f64,
        t_mid: f64,
        t_law: f64,
        dq: &[f64],
        vbar: &[f64],
        minus_q: &[f64],
    ) -> Works;
}
