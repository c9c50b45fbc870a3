//! The pieces a chain is assembled from: a joint's law and a link's shape functions, precomputed
//! integrals, lumped extras and DOF offsets. Shared by the body terms ([`super::body`]) and the
//! chain assembly ([`super::chain`]).

use data::scene::{PrescribedMotion, TorqueLaw};

use super::integrals::LinkIntegrals;
use super::section::Section;
use crate::basis::ShapeSet;

/// One joint: its law and initial state.
#[derive(Debug, Clone)]
pub struct JointModel {
    pub initial_angle: f64,
    pub initial_rate: f64,
    pub stiffness: f64,
    pub set_point: f64,
    pub damping: f64,
    pub torque: Option<TorqueLaw>,
    pub prescribed: Option<PrescribedMotion>,
}

impl JointModel {
    /// (θ, θ̇, θ̈) of a prescribed joint.
    pub fn prescribed_state(&self, t: f64) -> Option<(f64, f64, f64)> {
        self.prescribed.as_ref().map(|p| {
            let (a, r, acc) = p.kinematics(t);
            (self.initial_angle + a, r, acc)
        })
    }
}

/// One link: shape functions, precomputed integrals, lumped extras and its DOF offsets.
#[derive(Debug, Clone)]
pub struct LinkModel {
    pub name: String,
    pub transverse: ShapeSet,
    pub axial: Option<ShapeSet>,
    pub ints: LinkIntegrals,
    pub foreshortening: bool,
    pub tip_mass: f64,
    pub tip_inertia: f64,
    pub hub_inertia: f64,
    /// Section rotation ψ, rotary inertia, and the stiffness/Kelvin–Voigt matrices of the
    /// bending block [b, c] ([`super::section`]).
    pub section: Section,
    pub theta: usize,
    pub a0: usize,
    pub b0: usize,
}

impl LinkModel {
    pub fn na(&self) -> usize {
        self.ints.na
    }
    pub fn nb(&self) -> usize {
        self.ints.nb
    }
    /// Number of section-rotation coordinates c (Timoshenko with rotary inertia; else 0).
    pub fn nc(&self) -> usize {
        self.section.nc
    }
    /// Number of elastic coordinates na + nb + nc (contiguous from `a0`).
    pub fn ne(&self) -> usize {
        self.na() + self.nb() + self.nc()
    }
    /// Size of the bending block [b, c] (contiguous from `b0`).
    pub fn nbc(&self) -> usize {
        self.nb() + self.nc()
    }
    /// Body dimension 3 + na + nb + nc.
    pub fn body_dim(&self) -> usize {
        3 + self.ne()
    }
    /// Kelvin–Voigt on.
    pub fn has_kelvin_voigt(&self) -> bool {
        !self.section.dbc.is_empty()
    }
}
