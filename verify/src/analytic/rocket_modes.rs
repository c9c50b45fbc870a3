//! Free-free natural frequencies of the rocket at ignition: the stepped beam with its discrete
//! masses on springs, by exact dynamic stiffness and the Wittrick–Williams count.
//!
//! ## Model (docs/rocket.md, linearized about the straight body at rest, no loads)
//!
//! The case is a chain of uniform members between nodes at the ends, the stage junctions and
//! the mass attachment points. Member e has EA, EI and ρA of its stage (ρA = weight per length
//! at ignition / g). Axial and transverse motions decouple exactly at this state.
//!
//! * **Axial member** (EA u″ + ρA ω² u = 0, k = ω √(ρA/EA)): end forces
//!   [P₁; P₂] = EA k / sin kL · [[cos kL, −1], [−1, cos kL]] [u₁; u₂].
//! * **Bending member** (EI w⁗ − ρA ω² w = 0, β⁴ = ρA ω²/EI): the end forces
//!   (EI w‴(0), −EI w″(0), −EI w‴(L), EI w″(L)) of the exact solution through the end values
//!   (w(0), w′(0), w(L), w′(L)). The solution is written in the basis cos βx, sin βx, e^{−βx},
//!   e^{−β(L−x)}, whose end-value matrix stays well conditioned for large βL (the cosh/sinh
//!   basis loses e^{βL} in cancellation); K = F D⁻¹ is then formed by an LU solve.
//! * **Discrete mass j** (mass M_j, springs k_j to the case point x_j, springs k_ij to other
//!   masses): its displacement q_j is a degree of freedom of the global dynamic stiffness with
//!   diagonal k_j + Σ_i k_ij − ω² M_j and couplings −k_j to the case node and −k_ij to mass i.
//!   Eliminating the q's exactly at each ω would give the frequency-dependent impedance
//!   k m ω²/(k − m ω²) of a single hanging mass (or its coupled matrix form); keeping them as
//!   degrees of freedom is the same equation without the poles.
//!
//! **Springs between masses ride with the body** (report eq. 3.50: u_i, w_i are measured in
//! the body axes). A transverse one stores ½k(q_a − q_b − φ(x_a − x_b))², φ the mean-axis
//! angle of the whole body (case and masses, ignition mass m₀): a rigid rotation stretches
//! nothing. The elastic modes are m₀-orthogonal to the rigid rotation r (r = x − x_c on the
//! case and at the masses, x_c the centre of mass), so φ = 0 on them and the spring reads
//! ½k(q_a − q_b)² there: the body-frame frequencies are those of the fixed-axis operator K₀
//! restricted to rᵀMy = 0, K₀y − λMy = μMr. Across the axial direction a rigid motion stretches
//! no spring; the axial count is unconstrained.
//!
//! ## Root count (Wittrick & Williams 1971)
//!
//! The number of natural frequencies below ω is J(ω) = J₀(ω) + s{K(ω)}: s the number of
//! negative eigenvalues of the global dynamic stiffness K(ω) (the sign count of its triangular
//! factors, by Sylvester's law of inertia; computed here with a symmetric eigensolver), J₀ the number of natural frequencies below
//! ω of the members with both ends fixed: ⌊kL/π⌋ axially; for a clamped–clamped beam,
//! J₀ = i − ½(1 − (−1)^i sgn(1 − cosh βL cos βL)), i = ⌊βL/π⌋. The point masses have no
//! interior modes. The rigid-body modes (one axial, two transverse) lie at ω = 0 and are counted
//! for every ω > 0. Each elastic frequency is found by bisection on J to 1e-14 relative: no root
//! can be missed or counted twice, coincident roots included.
//!
//! **The rotation constraint** (transverse). For the restricted operator, the bordered form
//! [[K₀ − λM, Mr], [rᵀM, 0]] has the inertia of K₀ − λM plus that of −f(λ),
//! f(λ) = rᵀM(K₀ − λM)⁻¹Mr, and (Haynsworth) the inertia of K₀ − λM on rᵀMy = 0 plus one
//! positive and one negative eigenvalue. Counting the rotation as the second rigid mode,
//! J(ω) = J₀ + s{K(ω)} + [f(λ) > 0]. f needs no member integral: −r/λ solves
//! (K₀ − λM)y = Mr up to K₀r = g, the forces the mass-to-mass springs exert on a rigidly
//! rotated body (g_a = −g_b = k(x_a − x_b)), which act at mass DOFs only; with z = K(ω)⁻¹g,
//! λ f(λ) = −I_c + (gᵀz − gᵀr)/λ, I_c = rᵀMr the rotary inertia about x_c. Without such
//! springs g = 0 and f = −I_c/λ < 0: the plain count.

use std::f64::consts::PI;

use data::scene::Rocket;

use super::error::{AnalyticError, Result, non_negative, positive};

mod free_vibration;
pub use free_vibration::{FreeVibration, TransverseState};

/// Which decoupled motion of the free-free body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Along the body axis (one rigid mode).
    Axial,
    /// Across the body axis, Euler–Bernoulli bending (two rigid modes).
    Transverse,
}

impl Motion {
    /// Number of rigid-body modes at ω = 0.
    pub fn rigid_modes(self) -> usize {
        match self {
            Motion::Axial => 1,
            Motion::Transverse => 2,
        }
    }
}

/// A uniform stage of the case, from the aft end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub length: f64,
    pub ea: f64,
    pub ei: f64,
    pub rho_a: f64,
}

/// A discrete mass on springs to the case point at `position`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SprungMass {
    pub position: f64,
    pub mass: f64,
    pub axial_stiffness: f64,
    pub transverse_stiffness: f64,
}

/// A spring between discrete masses `between[0]` and `between[1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    pub between: [usize; 2],
    pub axial_stiffness: f64,
    pub transverse_stiffness: f64,
}

#[derive(Debug, Clone, Copy)]
struct Member {
    length: f64,
    ea: f64,
    ei: f64,
    rho_a: f64,
}

/// The free-free stepped beam with its spring-mounted masses, ready for frequency counting.
#[derive(Debug, Clone)]
pub struct FreeFreeRocket {
    /// Node abscissae, ascending, from 0 to the total length.
    nodes: Vec<f64>,
    /// Member e joins nodes e and e + 1.
    members: Vec<Member>,
    masses: Vec<(usize, SprungMass)>,
    couplings: Vec<Coupling>,
    /// Centre of mass x_c of case and masses at ignition.
    centre: f64,
    /// Rotary inertia I_c = ∫ρA(x − x_c)² + Σ M_j(x_j − x_c)² about x_c.
    rotary_inertia: f64,
}

impl FreeFreeRocket {
    /// The body from its stages (aft to nose), masses and mass-to-mass springs.
    pub fn new(
        segments: &[Segment],
        masses: &[SprungMass],
        couplings: &[Coupling],
    ) -> Result<Self> {
        if segments.is_empty() {
            return Err(AnalyticError::Unsupported(
                "a free-free body needs at least one stage".into(),
            ));
        }
        let mut ends = vec![0.0];
        for s in segments {
            positive("stage length", s.length)?;
            positive("stage EA", s.ea)?;
            positive("stage EI", s.ei)?;
            positive("stage rho A", s.rho_a)?;
            ends.push(ends.last().copied().unwrap_or(0.0) + s.length);
        }
        let total = *ends.last().unwrap_or(&0.0);
        let mut nodes = ends.clone();
        for m in masses {
            positive("discrete mass", m.mass)?;
            non_negative("discrete mass axial stiffness", m.axial_stiffness)?;
            non_negative("discrete mass transverse stiffness", m.transverse_stiffness)?;
            if !(0.0..=total).contains(&m.position) {
                return Err(AnalyticError::InvalidParameter {
                    name: "discrete mass position",
                    value: m.position,
                    why: "must lie on the body",
                });
            }
            nodes.push(m.position);
        }
        nodes.sort_by(f64::total_cmp);
        nodes.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * total);
        for c in couplings {
            non_negative("coupling axial stiffness", c.axial_stiffness)?;
            non_negative("coupling transverse stiffness", c.transverse_stiffness)?;
            if c.between[0] >= masses.len()
                || c.between[1] >= masses.len()
                || c.between[0] == c.between[1]
            {
                return Err(AnalyticError::Unsupported(format!(
                    "spring between masses {:?}: {} masses",
                    c.between,
                    masses.len()
                )));
            }
        }
        let stage_of = |x: f64| {
            let mut e = 0;
            while e + 1 < segments.len() && x >= ends[e + 1] {
                e += 1;
            }
            segments[e]
        };
        let members: Vec<Member> = nodes
            .windows(2)
            .map(|w| {
                let s = stage_of(0.5 * (w[0] + w[1]));
                Member {
                    length: w[1] - w[0],
                    ea: s.ea,
                    ei: s.ei,
                    rho_a: s.rho_a,
                }
            })
            .collect();
        let node_of = |x: f64| {
            nodes
                .iter()
                .enumerate()
                .min_by(|a, b| (a.1 - x).abs().total_cmp(&(b.1 - x).abs()))
                .map_or(0, |(i, _)| i)
        };
        let masses: Vec<(usize, SprungMass)> =
            masses.iter().map(|m| (node_of(m.position), *m)).collect();
        // ∫ρA, ∫ρA x, ∫ρA x² over each uniform member, plus the point masses
        let (mut m0, mut m1, mut m2) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (w, m) in nodes.windows(2).zip(&members) {
            let (a, b): (f64, f64) = (w[0], w[1]);
            m0 += m.rho_a * (b - a);
            m1 += m.rho_a * (b * b - a * a) / 2.0;
            m2 += m.rho_a * (b.powi(3) - a.powi(3)) / 3.0;
        }
        for (_, m) in &masses {
            m0 += m.mass;
            m1 += m.mass * m.position;
            m2 += m.mass * m.position * m.position;
        }
        let centre = m1 / m0;
        let rotary_inertia = m2 - m0 * centre * centre;
        Ok(FreeFreeRocket {
            nodes,
            members,
            masses,
            couplings: couplings.to_vec(),
            centre,
            rotary_inertia,
        })
    }

    /// The rocket scene at ignition (stage-1 weight per length before any burn).
    pub fn from_rocket(r: &Rocket) -> Result<Self> {
        let g = positive("gravity", r.gravity)?;
        let e = positive("Young's modulus", r.youngs_modulus)?;
        let segments: Vec<Segment> = r
            .stages
            .iter()
            .map(|s| Segment {
                length: s.length,
                ea: e * s.area,
                ei: e * s.inertia,
                rho_a: s.weight_per_length / g,
            })
            .collect();
        let masses: Vec<SprungMass> = r
            .discrete_masses
            .iter()
            .map(|m| SprungMass {
                position: m.position,
                mass: m.weight / g,
                axial_stiffness: m.axial_stiffness,
                transverse_stiffness: m.transverse_stiffness,
            })
            .collect();
        let couplings: Vec<Coupling> = r
            .springs
            .iter()
            .map(|s| Coupling {
                between: s.between,
                axial_stiffness: s.axial_stiffness,
                transverse_stiffness: s.transverse_stiffness,
            })
            .collect();
        Self::new(&segments, &masses, &couplings)
    }

    /// Total length of the body.
    pub fn length(&self) -> f64 {
        *self.nodes.last().unwrap_or(&0.0)
    }

    fn dofs_per_node(motion: Motion) -> usize {
        match motion {
            Motion::Axial => 1,
            Motion::Transverse => 2,
        }
    }

    /// Global dynamic stiffness K(ω) (dense, row-major, n × n) and J₀(ω) of its members.
    fn dynamic_stiffness(&self, motion: Motion, omega: f64) -> Result<(Vec<f64>, usize, usize)> {
        let per = Self::dofs_per_node(motion);
        let nn = self.nodes.len() * per;
        let n = nn + self.masses.len();
        let mut k = vec![0.0; n * n];
        let mut j0 = 0usize;
        for (e, m) in self.members.iter().enumerate() {
            match motion {
                Motion::Axial => {
                    let kl = omega * (m.rho_a / m.ea).sqrt() * m.length;
                    j0 += (kl / PI).floor() as usize;
                    let scale = m.ea / m.length * kl / kl.sin();
                    let (d, o) = (scale * kl.cos(), -scale);
                    let (a, b) = (e, e + 1);
                    k[a * n + a] += d;
                    k[b * n + b] += d;
                    k[a * n + b] += o;
                    k[b * n + a] += o;
                }
                Motion::Transverse => {
                    let beta = (m.rho_a * omega * omega / m.ei).powf(0.25);
                    let lam = beta * m.length;
                    j0 += clamped_clamped_count(lam);
                    let ke = bending_member(m.ei, beta, m.length)?;
                    let dofs = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3];
                    for (p, &gp) in dofs.iter().enumerate() {
                        for (q, &gq) in dofs.iter().enumerate() {
                            k[gp * n + gq] += ke[p][q];
                        }
                    }
                }
            }
        }
        let spring = |m: &SprungMass| match motion {
            Motion::Axial => m.axial_stiffness,
            Motion::Transverse => m.transverse_stiffness,
        };
        for (j, (node, m)) in self.masses.iter().enumerate() {
            let (q, y) = (nn + j, node * per);
            let s = spring(m);
            k[q * n + q] += s - omega * omega * m.mass;
            k[y * n + y] += s;
            k[q * n + y] -= s;
            k[y * n + q] -= s;
        }
        for c in &self.couplings {
            let s = match motion {
                Motion::Axial => c.axial_stiffness,
                Motion::Transverse => c.transverse_stiffness,
            };
            let (a, b) = (nn + c.between[0], nn + c.between[1]);
            k[a * n + a] += s;
            k[b * n + b] += s;
            k[a * n + b] -= s;
            k[b * n + a] -= s;
        }
        Ok((k, n, j0))
    }

    /// J(ω): the number of natural frequencies (rigid modes included) strictly below ω [rad/s].
    pub fn count_below(&self, motion: Motion, omega: f64) -> Result<usize> {
        positive("omega", omega)?;
        let (k, n, j0) = self.dynamic_stiffness(motion, omega)?;
        let constraint = match motion {
            Motion::Axial => 0,
            Motion::Transverse => usize::from(self.rotation_constraint(&k, n, omega)? > 0.0),
        };
        Ok(j0 + negative_eigenvalues(&k, n)? + constraint)
    }

    /// The forces g = K₀r the mass-to-mass transverse springs exert when the body turns
    /// rigidly (zero everywhere but at the coupled masses' DOFs).
    fn rotation_spring_forces(&self, n: usize) -> Vec<f64> {
        let first_mass = n - self.masses.len();
        let mut g = vec![0.0; n];
        for c in &self.couplings {
            let dx = self.masses[c.between[0]].1.position - self.masses[c.between[1]].1.position;
            g[first_mass + c.between[0]] += c.transverse_stiffness * dx;
            g[first_mass + c.between[1]] -= c.transverse_stiffness * dx;
        }
        g
    }

    /// Whether transverse springs join masses at different stations (then the rotation
    /// constraint shapes the modes).
    fn has_rotation_springs(&self) -> bool {
        self.couplings.iter().any(|c| {
            c.transverse_stiffness != 0.0
                && self.masses[c.between[0]].1.position != self.masses[c.between[1]].1.position
        })
    }

    /// The rigid rotation about the centre of mass at the transverse DOFs (w = x − x_c,
    /// w′ = 1 at the nodes; x_j − x_c at the masses).
    fn rotation_dofs(&self, n: usize) -> Vec<f64> {
        let mut r = vec![0.0; n];
        for (i, x) in self.nodes.iter().enumerate() {
            r[2 * i] = x - self.centre;
            r[2 * i + 1] = 1.0;
        }
        let first_mass = n - self.masses.len();
        for (j, (_, m)) in self.masses.iter().enumerate() {
            r[first_mass + j] = m.position - self.centre;
        }
        r
    }

    /// λ f(λ) = −I_c + (gᵀz − gᵀr)/λ with K(ω) z = g (module docs): its sign adds the rotation
    /// constraint to the transverse count.
    fn rotation_constraint(&self, k: &[f64], n: usize, omega: f64) -> Result<f64> {
        if !self.has_rotation_springs() {
            return Ok(-self.rotary_inertia);
        }
        let g = self.rotation_spring_forces(n);
        let z = self.rotation_response(k, n, &g)?;
        let r = self.rotation_dofs(n);
        let gz: f64 = g.iter().zip(&z).map(|(a, b)| a * b).sum();
        let gr: f64 = g.iter().zip(&r).map(|(a, b)| a * b).sum();
        Ok(-self.rotary_inertia + (gz - gr) / (omega * omega))
    }

    /// z = K(ω)⁻¹ g by a pivoted dense LU.
    fn rotation_response(&self, k: &[f64], n: usize, g: &[f64]) -> Result<Vec<f64>> {
        use faer::prelude::Solve;
        let a = faer::Mat::<f64>::from_fn(n, n, |i, j| k[i * n + j]);
        let b = faer::Mat::<f64>::from_fn(n, 1, |i, _| g[i]);
        let z = a.partial_piv_lu().solve(&b);
        let z: Vec<f64> = (0..n).map(|i| z[(i, 0)]).collect();
        if let Some((i, v)) = z.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(AnalyticError::NonFinite {
                what: "response of the dynamic stiffness to the rotation spring forces",
                x: i as f64,
                value: *v,
            });
        }
        Ok(z)
    }

    /// The first `count` elastic natural frequencies [rad/s] of `motion`, ascending.
    pub fn elastic_omegas(&self, motion: Motion, count: usize) -> Result<Vec<f64>> {
        self.omegas_after(motion, motion.rigid_modes(), count)
    }

    /// `count` natural frequencies [rad/s] of `motion`, ascending, after the lowest `rigid`
    /// ones (taken to be at ω = 0).
    fn omegas_after(&self, motion: Motion, rigid: usize, count: usize) -> Result<Vec<f64>> {
        // a frequency of the order of the lowest member's first mode, to start bracketing
        let scale = self
            .members
            .iter()
            .map(|m| match motion {
                Motion::Axial => (m.ea / m.rho_a).sqrt() / m.length,
                Motion::Transverse => (m.ei / m.rho_a).sqrt() / (m.length * m.length),
            })
            .fold(f64::INFINITY, f64::min);
        let target = rigid + count;
        let mut hi = scale;
        let mut doublings = 0;
        while self.count_below(motion, hi)? < target {
            hi *= 2.0;
            doublings += 1;
            if doublings > 200 {
                return Err(AnalyticError::NoConvergence {
                    what: "bracketing the rocket's frequencies",
                    iterations: doublings,
                });
            }
        }
        let mut out = Vec::with_capacity(count);
        // J(0⁺) is the rigid count (not evaluated: below ~1e-6 of the spectrum the rigid
        // modes' −ω²M pivots drown in the round-off of the static stiffness).
        let mut lo = 0.0;
        for want in rigid + 1..=target {
            // smallest ω with J(ω) ≥ want: the want-th frequency
            let (mut a, mut b) = (lo, hi);
            let mut it = 0;
            while b - a > 1e-14 * b {
                let mid = 0.5 * (a + b);
                if self.count_below(motion, mid)? >= want {
                    b = mid;
                } else {
                    a = mid;
                }
                it += 1;
                if it > 200 {
                    return Err(AnalyticError::NoConvergence {
                        what: "bisection on the Wittrick-Williams count",
                        iterations: it,
                    });
                }
            }
            let root = 0.5 * (a + b);
            out.push(root);
            lo = a;
        }
        Ok(out)
    }

    /// The first `count` elastic natural frequencies (Hz) of `motion`, ascending.
    pub fn frequencies_hz(&self, motion: Motion, count: usize) -> Result<Vec<f64>> {
        Ok(self
            .elastic_omegas(motion, count)?
            .into_iter()
            .map(|w| w / (2.0 * PI))
            .collect())
    }
}

/// Number of natural frequencies below βL of a clamped–clamped uniform beam (Wittrick–Williams).
fn clamped_clamped_count(lam: f64) -> usize {
    let i = (lam / PI).floor() as usize;
    // sgn(1 − cosh λ cos λ) = sgn(sech λ − cos λ), without overflow
    let e = (-lam).exp();
    let sech = 2.0 * e / (1.0 + e * e);
    let sg = if sech - lam.cos() >= 0.0 { 1 } else { -1 };
    let parity = if i.is_multiple_of(2) { 1 } else { -1 };
    // i − ½(1 − (−1)^i sg)
    if parity * sg > 0 {
        i
    } else {
        i.saturating_sub(1)
    }
}

/// Derivatives 0…3 (rows) of the member basis φ1 = cos βx, φ2 = sin βx, φ3 = e^{−βx},
/// φ4 = e^{−β(L−x)} (columns) at x = 0 and at x = L.
fn basis_end_values(beta: f64, length: f64) -> ([[f64; 4]; 4], [[f64; 4]; 4]) {
    let b = beta;
    let (c, s) = ((b * length).cos(), (b * length).sin());
    let el = (-b * length).exp();
    let at0: [[f64; 4]; 4] = [
        [1.0, 0.0, 1.0, el],
        [0.0, b, -b, b * el],
        [-b * b, 0.0, b * b, b * b * el],
        [0.0, -b * b * b, -b * b * b, b * b * b * el],
    ];
    let at_l: [[f64; 4]; 4] = [
        [c, s, el, 1.0],
        [-b * s, b * c, -b * el, b],
        [-b * b * c, -b * b * s, b * b * el, b * b],
        [b * b * b * s, -b * b * b * c, -b * b * b * el, b * b * b],
    ];
    (at0, at_l)
}

/// Exact dynamic stiffness of a uniform Euler–Bernoulli member (DOFs w₁, θ₁, w₂, θ₂).
fn bending_member(ei: f64, beta: f64, length: f64) -> Result<[[f64; 4]; 4]> {
    let (at0, at_l) = basis_end_values(beta, length);
    // D: end values; F: end forces (virtual work of ½∫EI w″²).
    let d = [at0[0], at0[1], at_l[0], at_l[1]];
    let mut f = [[0.0; 4]; 4];
    for p in 0..4 {
        f[0][p] = ei * at0[3][p];
        f[1][p] = -ei * at0[2][p];
        f[2][p] = -ei * at_l[3][p];
        f[3][p] = ei * at_l[2][p];
    }
    // K = F D⁻¹  ⇔  Dᵀ Kᵀ = Fᵀ
    let mut dt = [[0.0; 4]; 4];
    let mut ft = [[0.0; 4]; 4];
    for p in 0..4 {
        for q in 0..4 {
            dt[p][q] = d[q][p];
            ft[p][q] = f[q][p];
        }
    }
    let kt = solve4(dt, ft)?;
    let mut k = [[0.0; 4]; 4];
    for p in 0..4 {
        for q in 0..4 {
            // symmetric in exact arithmetic: average away the round-off
            k[p][q] = 0.5 * (kt[q][p] + kt[p][q]);
        }
    }
    Ok(k)
}

/// Solves A X = B for 4 × 4 A by Gaussian elimination with partial pivoting.
fn solve4(mut a: [[f64; 4]; 4], mut b: [[f64; 4]; 4]) -> Result<[[f64; 4]; 4]> {
    for col in 0..4 {
        let piv = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        if a[piv][col] == 0.0 || !a[piv][col].is_finite() {
            return Err(AnalyticError::NonFinite {
                what: "pivot of a bending member's end-value matrix",
                x: col as f64,
                value: a[piv][col],
            });
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..4 {
            let f = a[r][col] / a[col][col];
            let (above, below) = a.split_at_mut(r);
            for (x, y) in below[0][col..].iter_mut().zip(&above[col][col..]) {
                *x -= f * y;
            }
            let (above, below) = b.split_at_mut(r);
            for (x, y) in below[0].iter_mut().zip(&above[col]) {
                *x -= f * y;
            }
        }
    }
    let mut x = [[0.0; 4]; 4];
    for q in 0..4 {
        for r in (0..4).rev() {
            let mut v = b[r][q];
            for p in r + 1..4 {
                v -= a[r][p] * x[p][q];
            }
            x[r][q] = v / a[r][r];
        }
    }
    Ok(x)
}

/// Number of negative eigenvalues of the symmetric n × n matrix `k` (row-major). The matrix is
/// first scaled by the congruence D K D, D = diag(1/√|K_ii|), which equilibrates the mixed
/// units of the deflection and slope rows and leaves the inertia unchanged (Sylvester); the
/// eigenvalues then come from a symmetric eigensolver, which needs no pivot to be non-zero
/// (plain LDLᵀ without pivoting breaks down on the symmetric body's exactly singular minors).
fn negative_eigenvalues(k: &[f64], n: usize) -> Result<usize> {
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let a = k[i * n + i].abs();
            if a > 0.0 { 1.0 / a.sqrt() } else { 1.0 }
        })
        .collect();
    let mut m = faer::Mat::<f64>::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            let v = k[i * n + j] * d[i] * d[j];
            if !v.is_finite() {
                return Err(AnalyticError::NonFinite {
                    what: "entry of the dynamic stiffness",
                    x: (i * n + j) as f64,
                    value: v,
                });
            }
            m[(i, j)] = v;
        }
    }
    let ev = m.self_adjoint_eigenvalues(faer::Side::Lower).map_err(|_| {
        AnalyticError::NoConvergence {
            what: "symmetric eigensolver on the dynamic stiffness",
            iterations: 0,
        }
    })?;
    Ok(ev.iter().filter(|&&v| v < 0.0).count())
}
