//! Tip contact of a link with a fixed rigid surface (a straight line, Barhorst's work surface,
//! or a circle, seed 001's wall): gap, constraint rows, impact map, the constrained (index-1)
//! accelerations and Coulomb friction with stick–slip.
//!
//! **Geometry.** The gap is the scene's signed distance, positive on the free side:
//! g = n̂·(r_tip − p₀) for a line (n̂ the unit normal to the free side), g = R − |r_tip − c| for
//! a circle (free side inside; this is the normalized form of seed 001's
//! Φ = X² + Y² − L², chosen so that the multiplier is the normal force in newtons:
//! ∇g = −(r − c)/|r − c| = n̂ has unit length). The tangent is t̂ = (n̂_y, −n̂_x) (for the circle
//! about the hub: the counter-clockwise direction). With the inertial tip Jacobian J(q) (free
//! coordinates only) the rows are G = n̂ᵀJ and T = t̂ᵀJ, the tangential (slip) velocity
//! v_t = T q̇, and the second derivative of the gap along a motion is
//! g̈ = G q̈ + n̂·c(q, q̇) − κ v_t² (c the convective tip acceleration, κ = 1/|r − c| for the
//! circle, 0 for the line).
//!
//! **Unilateral, frictionless** (seed 000):
//! * impact (perfectly plastic): M(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0 ⇒ Λ = −G q̇⁻ / (G M⁻¹ Gᵀ),
//!   positions unchanged;
//! * constrained motion: M q̈ = f + Gᵀλ, g̈ = 0 ⇒ λ = −(G M⁻¹f + n̂·c − κv_t²) / (G M⁻¹ Gᵀ);
//! * release when λ (the normal force, positive pushing the tip to the free side) crosses zero.
//!
//! **Bilateral with Coulomb friction** (seed 001): the constraint g = 0 holds for all time (no
//! release, λ may take either sign). While the tip slides in direction s = sign v_t the friction
//! force −μ|λ| s t̂ enters as the generalized force −μ s |λ| Tᵀ, so
//!
//!   M q̈ = f + (Gᵀ − μ s σ Tᵀ) λ,  σ = sign λ,
//!   λ (G M⁻¹Gᵀ − μ s σ G M⁻¹Tᵀ) = −(G M⁻¹ f + n̂·c − κ v_t²),
//!
//! linear in λ for a fixed σ. If G M⁻¹Gᵀ > μ |G M⁻¹Tᵀ| both denominators are positive, so
//! σ = sign of the right-hand side is the unique consistent choice; otherwise the problem has no
//! or several solutions (Painlevé's paradox) and the run stops with that diagnosis. Friction
//! dissipates μ|λ||v_t| (ledger term `friction`).
//!
//! **Stick–slip.** s·v_t is the event function while sliding. At its located zero the tip is
//! held tangentially as a second constraint (tip fixed: J q̈ + c = 0, forces λ_n n̂ + λ_t t̂
//! from the 2 × 2 system with G M⁻¹Gᵀ, G M⁻¹Tᵀ, T M⁻¹Tᵀ) and the Coulomb cone decides: stick
//! if |λ_t| ≤ μ|λ_n|, else slide on in direction s = −sign λ_t (the direction in which the
//! unbalanced tangential load drives the tip; a reversal when s changes). While sticking the
//! event function is μ|λ_n| − |λ_t|; at its located zero slip resumes in direction −sign λ_t.
//! A run that starts at rest makes the same test at t = 0. Events are located on the dense
//! output, never stepped through, so there is no chattering between phases.

use data::scene::{ContactMode, PlanarChain, Surface};

use crate::error::ModalError;

/// The rigid surface of a contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wall {
    /// Unit normal to the free side and a point of the line.
    Line { normal: [f64; 2], point: [f64; 2] },
    /// Free side inside.
    Circle { center: [f64; 2], radius: f64 },
}

/// Contact model and the quantities of the last evaluation.
#[derive(Debug, Clone)]
pub struct ContactState {
    /// Index of the link whose tip touches the surface.
    pub link: usize,
    pub wall: Wall,
    /// The constraint can never be released (seed 001's wall).
    pub bilateral: bool,
    /// Coulomb friction coefficient μ (only with `bilateral`).
    pub mu: f64,
    /// Constrained phase (tip on the surface, λ unknown) or free flight. Always true when
    /// bilateral.
    pub constrained: bool,
    /// Stick phase of a friction contact (tip held tangentially at `stick_point`).
    pub sticking: bool,
    /// Sliding direction s = ±1 of a friction contact while not sticking.
    pub slip_dir: f64,
    pub stick_point: [f64; 2],
    /// Unit normal (to the free side) and tangent at the current tip position.
    pub normal: [f64; 2],
    pub tangent: [f64; 2],
    /// Curvature κ of the surface (0 for a line).
    pub curvature: f64,
    /// Normal force λ of the last evaluation (0 in free flight; positive pushes the tip to the
    /// free side) and the tangential (friction) force λ_t along t̂.
    pub lambda: f64,
    pub lambda_t: f64,
    /// Gap, normal tip velocity G q̇, slip velocity T q̇ and G M⁻¹ Gᵀ of the last evaluation.
    pub gap: f64,
    pub normal_velocity: f64,
    pub slip_velocity: f64,
    pub gmg: f64,
    /// Tangential tip offset t̂·(r − stick point) while sticking (drift measure).
    pub stick_offset: f64,
    /// Power dissipated by friction μ|λ||v_t| at the last evaluation.
    pub friction_power: f64,
    /// G M⁻¹ Gᵀ ≤ μ|G M⁻¹ Tᵀ| at the last evaluation (Painlevé: no unique λ).
    pub painleve: bool,
    /// G, T (free columns), M⁻¹Gᵀ and M⁻¹Tᵀ of the last evaluation.
    pub g_row: Vec<f64>,
    pub t_row: Vec<f64>,
    pub minv_gt: Vec<f64>,
    pub minv_tt: Vec<f64>,
    /// Tip Jacobian (2 × N) work array.
    pub jac: Vec<f64>,
    /// Cumulative kinetic energy lost in impacts.
    pub impact_loss: f64,
}

impl ContactState {
    /// The single tip contact of the planar chain `pc`.
    pub fn from_planar_chain(
        pc: &PlanarChain,
        n: usize,
        nf: usize,
    ) -> Result<Option<Self>, ModalError> {
        let Some(c) = pc.contacts.first() else {
            return Ok(None);
        };
        check(pc)?;
        let link = pc
            .links
            .iter()
            .position(|l| l.name == c.link)
            .ok_or_else(|| {
                ModalError::invalid("contact.link", format!("no link named `{}`", c.link))
            })?;
        let wall = match c.surface {
            Surface::Line { point, normal } => {
                let len = normal[0].hypot(normal[1]);
                Wall::Line {
                    normal: [normal[0] / len, normal[1] / len],
                    point,
                }
            }
            Surface::Circle { center, radius } => Wall::Circle { center, radius },
        };
        let bilateral = c.mode == ContactMode::Bilateral;
        Ok(Some(ContactState {
            link,
            wall,
            bilateral,
            mu: c.friction,
            constrained: bilateral,
            sticking: false,
            slip_dir: 1.0,
            stick_point: [0.0; 2],
            normal: [0.0; 2],
            tangent: [0.0; 2],
            curvature: 0.0,
            lambda: 0.0,
            lambda_t: 0.0,
            gap: 0.0,
            normal_velocity: 0.0,
            slip_velocity: 0.0,
            gmg: 0.0,
            stick_offset: 0.0,
            friction_power: 0.0,
            painleve: false,
            g_row: vec![0.0; nf],
            t_row: vec![0.0; nf],
            minv_gt: vec![0.0; nf],
            minv_tt: vec![0.0; nf],
            jac: vec![0.0; 2 * n],
            impact_loss: 0.0,
        }))
    }

    /// Whether the contact has Coulomb friction (and hence stick–slip events).
    pub fn has_friction(&self) -> bool {
        self.mu > 0.0
    }

    /// μsσ of sliding friction at the last evaluation (s the sliding direction, σ = sign λ):
    /// the tangential force −μs|λ| = −μsσλ rides on λ, so the contact force acts along
    /// Gᵀ − μsσTᵀ.
    pub fn sliding_friction_slope(&self) -> f64 {
        let sigma = if self.lambda >= 0.0 { 1.0 } else { -1.0 };
        self.mu * self.slip_dir * sigma
    }

    /// Gap, unit normal, tangent and curvature at the tip position r.
    pub fn set_geometry(&mut self, r: [f64; 2]) {
        match self.wall {
            Wall::Line { normal, point } => {
                self.normal = normal;
                self.gap = normal[0] * (r[0] - point[0]) + normal[1] * (r[1] - point[1]);
                self.curvature = 0.0;
            }
            Wall::Circle { center, radius } => {
                let d = [r[0] - center[0], r[1] - center[1]];
                let rho = d[0].hypot(d[1]);
                // The tip at the centre has no normal; any direction keeps the numbers finite
                // (it cannot be on the wall there, so no event depends on it).
                let rho_safe = rho.max(f64::MIN_POSITIVE);
                self.normal = if rho > 0.0 {
                    [-d[0] / rho_safe, -d[1] / rho_safe]
                } else {
                    [-1.0, 0.0]
                };
                self.gap = radius - rho;
                self.curvature = 1.0 / rho_safe;
            }
        }
        self.tangent = [self.normal[1], -self.normal[0]];
        if self.sticking {
            self.stick_offset = self.tangent[0] * (r[0] - self.stick_point[0])
                + self.tangent[1] * (r[1] - self.stick_point[1]);
        }
    }
}

/// Rejects the contact features this backend does not model, with a precise message.
pub fn check(pc: &PlanarChain) -> Result<(), ModalError> {
    if pc.contacts.len() > 1 {
        return Err(ModalError::Unsupported(format!(
            "modal: {} contacts; only one tip contact is implemented",
            pc.contacts.len()
        )));
    }
    let Some(c) = pc.contacts.first() else {
        return Ok(());
    };
    let unilateral = c.mode == ContactMode::Unilateral;
    if unilateral && c.friction != 0.0 {
        return Err(ModalError::Unsupported(format!(
            "modal: Coulomb friction μ = {} on the unilateral contact of link `{}` (friction and \
             stick–slip are implemented for bilateral contacts only; impacts with friction are not)",
            c.friction, c.link
        )));
    }
    if pc.links.iter().any(|l| l.joint.prescribed.is_some()) {
        return Err(ModalError::Unsupported(
            "modal: contact together with a prescribed joint motion".into(),
        ));
    }
    if let (false, [l], Surface::Circle { center, radius }) =
        (unilateral, pc.links.as_slice(), &c.surface)
    {
        // An inextensible link (linear or foreshortening kinematics) has |r_tip − hub| ≤ L with
        // equality only when it is straight (∫v'² ≥ v(L)²/L), so on the circle of radius L
        // about its hub the gap has a double root at b = 0: G = 0, λ is undetermined and the
        // link is held straight — the rigid model, whose wall load needs the axial field.
        let tol = 1e-12 * l.length;
        if !l.axial && center[0].hypot(center[1]) <= tol && (*radius - l.length).abs() <= tol {
            return Err(ModalError::Unsupported(format!(
                "modal: bilateral circle of radius L about the hub for the inextensible link \
                 `{}`: the tip can stay at radius L only if the link stays straight, so this \
                 model degenerates to the rigid link (constraint gradient zero, normal force \
                 undetermined); use `axial = true` (Euler model) or the rigid closed form",
                l.name
            )));
        }
    }
    if unilateral && pc.links.iter().any(|l| l.axial) {
        return Err(ModalError::Unsupported(
            "modal: unilateral contact of a chain with axial fields (impacts are implemented for \
             inextensible links only; bilateral contacts accept axial links)"
                .into(),
        ));
    }
    Ok(())
}

/// Root of a scalar function on [a, b] with f(a) > 0 ≥ f(b) (Illinois regula falsi) to the
/// bracket width `tol`. Returns (t, f(t), final bracket width) with f(t) ≤ 0: the located time
/// is the first sampled point on the far side of the crossing. An iterate with f = 0 exactly
/// does not end the search: f may have crossed before it, so the bracket is shrunk to `tol`
/// like any other (bisection then, as regula falsi returns b itself).
pub fn locate_crossing(
    mut f: impl FnMut(f64) -> f64,
    mut a: f64,
    mut fa: f64,
    mut b: f64,
    mut fb: f64,
    tol: f64,
) -> (f64, f64, f64) {
    let mut side = 0i8;
    let mut fb_true = fb;
    for _ in 0..200 {
        if b - a <= tol {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        // Keep the iterate strictly inside; fall back to bisection if regula falsi stalls.
        if !(c > a && c < b && c.is_finite()) {
            c = 0.5 * (a + b);
        }
        let fc = f(c);
        if fc > 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            fb_true = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    (b, fb_true, b - a)
}
