//! The physical body read from a scene: stages, burn schedule, discrete masses, loads.
//!
//! Weights in the scene are turned into masses here (mass = weight / g); nothing downstream
//! sees a weight. Features the model does not implement are refused with a precise message.

use data::scene::{InitialShape, Rocket};

use super::error::RocketError;

/// One uniform stage segment x0 ≤ x ≤ x1 of the case.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    pub x0: f64,
    pub x1: f64,
    /// Axial stiffness E·A_c.
    pub ea: f64,
    /// Bending stiffness E·I.
    pub ei: f64,
    /// Mass per length at ignition.
    pub mass0: f64,
}

impl Segment {
    pub fn length(&self) -> f64 {
        self.x1 - self.x0
    }
}

/// Uniform burn of the first stage: m₁(t) = m₁(0) − burnt_per_length(t).
#[derive(Debug, Clone, PartialEq)]
pub struct Burn {
    /// End of the burning chamber (x = L₁); the burn covers 0 ≤ x ≤ L₁.
    pub chamber_end: f64,
    /// Mass burnt per length and time (ṁ).
    pub rate: f64,
    /// Mass per length that can burn (ignition mass − casing mass).
    pub burnable: f64,
}

impl Burn {
    /// Burn-out time: the burnable mass is gone.
    pub fn burnout_time(&self) -> f64 {
        self.burnable / self.rate
    }
    /// Fraction s ∈ [0, 1] of the burnable mass already burnt at time t.
    pub fn burnt_fraction(&self, t: f64) -> f64 {
        (t.max(0.0) / self.burnout_time()).min(1.0)
    }
    /// Total mass flow rate Q̇ = ṁ L₁ while burning.
    pub fn mass_flow(&self) -> f64 {
        self.rate * self.chamber_end
    }
}

/// Discrete mass M_j carried on springs k_u, k_w (and dampers) to the case at x_j.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMass {
    pub x: f64,
    pub mass: f64,
    pub ku: f64,
    pub kw: f64,
    pub cu: f64,
    pub cw: f64,
}

/// Spring (and damper) between two discrete masses.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupling {
    pub i: usize,
    pub j: usize,
    pub ku: f64,
    pub kw: f64,
    pub cu: f64,
    pub cw: f64,
}

/// Everything the reduced model needs from the scene, in consistent mass units.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub length: f64,
    pub segments: Vec<Segment>,
    /// None when no stage burns: no thrust, no chamber pressure, no internal flow.
    pub burn: Option<Burn>,
    pub gravity: f64,
    /// Launch angle θ₀ (rad) of the body axis from the horizontal.
    pub launch_angle: f64,
    pub exhaust_velocity: f64,
    /// Chamber pressure force p·A_f (acts while the stage burns).
    pub pressure_force: f64,
    /// Nozzle angle γ (rad) of the thrust from the body axis.
    pub nozzle_angle: f64,
    pub masses: Vec<PointMass>,
    pub couplings: Vec<Coupling>,
    pub initial_shape: InitialShape,
}

impl Body {
    pub fn from_rocket(r: &Rocket) -> Result<Body, RocketError> {
        let g = r.gravity;
        if r.exit_pressure != 0.0 {
            return Err(RocketError::Unsupported(
                "exit_pressure ≠ 0: the thrust term p_e·A_e needs the nozzle exit area, which the \
                 scene does not give (the report's runs expand to vacuum, p_e = 0)"
                    .into(),
            ));
        }
        let mut segments = Vec::with_capacity(r.stages.len());
        let mut x = 0.0;
        let mut burn = None;
        for (i, s) in r.stages.iter().enumerate() {
            let seg = Segment {
                x0: x,
                x1: x + s.length,
                ea: r.youngs_modulus * s.area,
                ei: r.youngs_modulus * s.inertia,
                mass0: s.weight_per_length / g,
            };
            if s.burn_rate > 0.0 {
                if i != 0 {
                    return Err(RocketError::Unsupported(format!(
                        "stage {} burns: only the first (aft) stage may burn in the seed-003 \
                         model (chamber 0 ≤ x ≤ L₁, nozzle at x = 0)",
                        i + 1
                    )));
                }
                let casing = s.casing_weight_per_length.ok_or_else(|| {
                    RocketError::Unsupported(
                        "burning stage without casing_weight_per_length".into(),
                    )
                })?;
                let burnable = (s.weight_per_length - casing) / g;
                if burnable > 0.0 {
                    burn = Some(Burn {
                        chamber_end: seg.x1,
                        rate: s.burn_rate / g,
                        burnable,
                    });
                }
            }
            x = seg.x1;
            segments.push(seg);
        }
        let masses = r
            .discrete_masses
            .iter()
            .map(|m| PointMass {
                x: m.position,
                mass: m.weight / g,
                ku: m.axial_stiffness,
                kw: m.transverse_stiffness,
                cu: m.axial_damping,
                cw: m.transverse_damping,
            })
            .collect::<Vec<_>>();
        let couplings = r
            .springs
            .iter()
            .map(|s| Coupling {
                i: s.between[0],
                j: s.between[1],
                ku: s.axial_stiffness,
                kw: s.transverse_stiffness,
                cu: s.axial_damping,
                cw: s.transverse_damping,
            })
            .collect::<Vec<_>>();
        // A free discrete mass (no spring anywhere) would be a rigid body of its own drifting
        // through the case: the model has no contact, so refuse it.
        for (j, m) in masses.iter().enumerate() {
            let connected_u = m.ku > 0.0
                || couplings
                    .iter()
                    .any(|c| (c.i == j || c.j == j) && c.ku > 0.0);
            let connected_w = m.kw > 0.0
                || couplings
                    .iter()
                    .any(|c| (c.i == j || c.j == j) && c.kw > 0.0);
            if !(connected_u && connected_w) {
                return Err(RocketError::Unsupported(format!(
                    "discrete mass {} has no axial or no transverse spring to the case or to \
                     another mass: it would drift freely (no contact model)",
                    j + 1
                )));
            }
        }
        Ok(Body {
            length: x,
            segments,
            burn,
            gravity: g,
            launch_angle: r.launch_angle_deg.to_radians(),
            exhaust_velocity: r.exhaust_velocity,
            pressure_force: r.chamber_pressure * r.port_area,
            nozzle_angle: r.nozzle_angle_deg.to_radians(),
            masses,
            couplings,
            initial_shape: r.initial_shape.clone(),
        })
    }

    pub fn has_dampers(&self) -> bool {
        self.masses.iter().any(|m| m.cu > 0.0 || m.cw > 0.0)
            || self.couplings.iter().any(|c| c.cu > 0.0 || c.cw > 0.0)
    }
}
