//! The chain as a [`System`]: the trait's operations are the chain's own passes (the residual
//! and its groups, the Newton matrices, energies, ∂T/∂q), plus the midpoint-rule works of the
//! joints and loads that the energy-consistent method books.

use super::{AugmentedLayout, Chain, NONE};
use crate::band::BorderedBand;
use crate::linalg::dot;
use crate::system::{Augmentation, NewtonCoefficients, Parts, System, Works};

impl Augmentation for AugmentedLayout {
    fn map(&self) -> &[usize] {
        &self.map
    }
    fn size(&self) -> usize {
        self.n
    }
}

impl System for Chain {
    type Augmented = AugmentedLayout;

    #[inline]
    fn ndof(&self) -> usize {
        self.ndof
    }

    #[inline]
    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]) {
        Chain::residual(self, t, q, qd, qdd, res);
    }

    #[inline]
    fn residual_parts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        Chain::residual_parts(self, t, q, qd, qdd, parts, res);
    }

    #[inline]
    fn residual_parts_at_last_q(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        Chain::residual_parts_at_last_q(self, t, q, qd, parts, res);
    }

    #[inline]
    fn add_kinetic_gradient(&mut self, t: f64, q: &[f64], x: &[f64], sign: f64, out: &mut [f64]) {
        Chain::add_kinetic_gradient(self, t, q, x, sign, out);
    }

    #[inline]
    fn energies(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        Chain::energies(self, t, q, qd)
    }

    #[inline]
    fn potential_at_last_q(&mut self, t: f64, q: &[f64]) -> [f64; 3] {
        Chain::potential_at_last_q(self, t, q)
    }

    #[inline]
    fn has_massless_dofs(&self) -> bool {
        Chain::has_massless_dofs(self)
    }

    #[inline]
    fn new_matrix(&self) -> BorderedBand {
        Chain::new_matrix(self)
    }

    #[inline]
    fn newton_matrix(&self, q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        Chain::newton_matrix(self, q, c, s);
    }

    /// The augmented layout of the running sums, for chains with foreshortening.
    fn exact_layout(&self) -> Option<AugmentedLayout> {
        self.has_foreshortening()
            .then(|| Chain::augmented_layout(self))
    }

    fn new_augmented_matrix(&self, layout: &AugmentedLayout) -> BorderedBand {
        Chain::new_augmented_matrix(self, layout)
    }

    #[inline]
    fn exact_newton_matrix(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        c: NewtonCoefficients,
        layout: &AugmentedLayout,
        s: &mut BorderedBand,
    ) {
        Chain::exact_newton_matrix(self, q, qd, qdd, c, layout, s);
    }

    /// Applied torques τ(t_mid)Δθ and joint dampers D θ̄̇Δθ of the free joints, Kelvin–Voigt
    /// h v̄ᵀC v̄; the applied loads (tip force, distributed load) are the rest of the total
    /// work. `joint_torque` holds the laws at `t_law` (the torque channel adds a free joint's
    /// spring and damper at the sample: `crate::run`).
    fn midpoint_works(
        &mut self,
        h: f64,
        t_mid: f64,
        t_law: f64,
        dq: &[f64],
        vbar: &[f64],
        minus_q: &[f64],
    ) -> Works {
        let mut works = Works::default();
        let (_, p_kv) = self.dissipation_power(t_mid, vbar);
        works.kelvin_voigt = p_kv * h;
        for li in 0..self.links.len() {
            let j = &self.links[li].joint;
            if j.dof == NONE {
                continue;
            }
            let dth = dq[j.dof];
            let law = j.applied(t_mid);
            works.applied_torque += law * dth;
            works.joint_damper += j.damping * vbar[j.dof] * dth;
            // the law at the sample time; the channel adds the spring and damper
            self.joint_torque[li] = j.applied(t_law);
        }
        if self.tip_load != 0.0 || self.distributed_load != 0.0 {
            let total = -dot(minus_q, dq);
            works.applied_load =
                total - works.applied_torque + works.joint_damper + works.kelvin_voigt;
        }
        works
    }
}
