//! Exact natural frequencies of a straight planar chain of uniform Euler–Bernoulli links with
//! torsional joint springs, linearized about its set points (the configuration the backends'
//! `modes` use for chain scenes: joints at their spring set points, links straight, at rest).
//!
//! ## Model
//! Link i (length Lᵢ, EIᵢ, ρAᵢ) carries the transverse displacement wᵢ(x) off the straight
//! reference line, EIᵢ wᵢ'''' = ρAᵢ ω² wᵢ. The root is pinned (w₁(0) = 0) with a joint spring
//! K₁ and a hub inertia J_h1 on the root slope (a `fixed` joint clamps it); at the joint between
//! links i and i + 1 the displacement W is common, the two slopes a⁻ = wᵢ'(Lᵢ),
//! a⁺ = wᵢ₊₁'(0) are tied by the spring Kᵢ₊₁ (equal for a rigid joint), link i's tip mass moves
//! with W, its tip inertia turns with a⁻ and link i + 1's hub inertia with a⁺; the last link's
//! tip carries its tip mass and tip inertia and is otherwise free. The Lagrangian
//!   Σ ½∫(EI w''² − ω²ρA w²) + Σ ½K(a⁺ − a⁻)² − ½ω²(Σ m W² + Σ J a²)
//! gives, per link, the exact dynamic stiffness Dᵢ(ω) relating the end displacements and slopes
//! (w(0), w'(0), w(L), w'(L)) to the end forces (EI w'''(0), −EI w''(0), −EI w'''(L), EI w''(L));
//! assembled with the springs and the lumped inertias into the global D(ω) over the joint DOFs.
//! The frequencies are the ω where D(ω) is singular.
//!
//! Dᵢ = F A⁻¹ with A, F the end values of the basis (cos βx, sin βx, e^{−βx}, e^{−β(L−x)}),
//! β⁴ = ω²ρA/EI, every entry bounded by 1 on the link, so no cosh βL overflows or cancels.
//!
//! ## Root search without missed roots (Wittrick–Williams)
//! The number of natural frequencies below ω is
//!   J(ω) = Σᵢ J₀ᵢ(ω) + s{D(ω)},
//! s the number of negative eigenvalues of D (Jacobi rotations) and J₀ᵢ the number of
//! clamped–clamped frequencies of link i below ω (Williams & Wittrick 1970):
//!   J₀ = j − ½(1 − (−1)ʲ sgn(1 − cos βL cosh βL)),  j = ⌊βL/π⌋.
//! The n-th frequency is located by bisection on J (bracketed by doubling from the slowest
//! link's √(EI/ρAL⁴)) to a relative width of 4ε: every root is counted, double roots included,
//! and none is missed between scan points. A joint with K = 0 (not fixed) adds a rigid mode,
//! ω = 0; their number is known from the joints and they are returned first.
//!
//! ## Limits
//! K → ∞ on every joint: one clamped–free beam of length ΣLᵢ (equal sections);
//! K₁ → 0, the others → ∞: the pinned–free beam (rigid mode, then tan βL = tanh βL).
//! Both are tested against [`crate::analytic::beam`] below and are offered as references of
//! their own (`chain-clamped-limit`, `chain-pinned-limit`).

// Matrix kernels index several arrays with the same subscripts, as the formulas do.
#![allow(clippy::needless_range_loop)]

use std::f64::consts::PI;

use data::scene::{PlanarChain, PrescribedMotion};

use super::beam::{BeamSupport, bending_frequencies_hz};
use super::error::{AnalyticError, Result};
use super::error::{non_negative, positive};

/// One uniform link of the chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainLink {
    pub length: f64,
    pub ei: f64,
    pub rho_a: f64,
    pub tip_mass: f64,
    pub tip_inertia: f64,
}

/// The joint at a link's root: a torsional spring (`stiffness` None: rigid, i.e. clamped at the
/// root) and the hub inertia that turns with the link's root slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainJoint {
    pub stiffness: Option<f64>,
    pub hub_inertia: f64,
}

/// A straight spring-jointed chain (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringJointedChain {
    pub links: Vec<ChainLink>,
    /// `joints[i]` at the root of `links[i]`.
    pub joints: Vec<ChainJoint>,
}

/// Global DOFs of the chain's joints: per link its end DOFs (w(0), w'(0), w(L), w'(L)), `None`
/// where held at zero.
struct DofMap {
    ends: Vec<[Option<usize>; 4]>,
    n: usize,
}

impl SpringJointedChain {
    /// A scene's planar chain, linearized about its set points. Refuses what the model does not
    /// contain: gravity, extensible, Timoshenko or rotary-inertia links, prescribed joint
    /// motion other than `fixed`, and a reference configuration that is not straight.
    pub fn from_chain(chain: &PlanarChain) -> Result<Self> {
        if chain
            .gravity
            .as_ref()
            .is_some_and(|g| g.vector.iter().any(|&x| x != 0.0))
        {
            return Err(AnalyticError::Unsupported(
                "the spring-jointed chain has no gravity (its straight reference is no \
                 equilibrium under gravity)"
                    .into(),
            ));
        }
        let mut links = Vec::with_capacity(chain.links.len());
        let mut joints = Vec::with_capacity(chain.links.len());
        for (i, l) in chain.links.iter().enumerate() {
            if l.axial || l.shear || l.rotary_inertia {
                return Err(AnalyticError::Unsupported(format!(
                    "link {}: the spring-jointed chain is of inextensible Euler–Bernoulli links \
                     without rotary inertia",
                    i + 1
                )));
            }
            let j = &l.joint;
            let (stiffness, reference_angle) = match j.prescribed {
                Some(PrescribedMotion::Fixed) => (None, j.initial_angle),
                Some(_) => {
                    return Err(AnalyticError::Unsupported(format!(
                        "joint {}: prescribed motion has no rest configuration",
                        i + 1
                    )));
                }
                None => {
                    let k = j.stiffness.unwrap_or(0.0);
                    let angle = if k != 0.0 {
                        j.set_point.unwrap_or(0.0)
                    } else {
                        j.initial_angle
                    };
                    (Some(k), angle)
                }
            };
            if i > 0 && reference_angle != 0.0 {
                return Err(AnalyticError::Unsupported(format!(
                    "joint {} is at {reference_angle} rad in the reference configuration: the \
                     spring-jointed chain reference is the straight chain",
                    i + 1
                )));
            }
            links.push(ChainLink {
                length: l.length,
                ei: l.bending_stiffness,
                rho_a: l.mass_per_length,
                tip_mass: l.tip_mass.unwrap_or(0.0),
                tip_inertia: l.tip_inertia.unwrap_or(0.0),
            });
            joints.push(ChainJoint {
                stiffness,
                hub_inertia: j.hub_inertia.unwrap_or(0.0),
            });
        }
        let chain = SpringJointedChain { links, joints };
        chain.validate()?;
        Ok(chain)
    }

    fn validate(&self) -> Result<()> {
        if self.links.is_empty() || self.links.len() != self.joints.len() {
            return Err(AnalyticError::Unsupported(
                "a chain needs one joint per link and at least one link".into(),
            ));
        }
        for l in &self.links {
            positive("L", l.length)?;
            positive("EI", l.ei)?;
            positive("rho A", l.rho_a)?;
            non_negative("tip mass", l.tip_mass)?;
            non_negative("tip inertia", l.tip_inertia)?;
        }
        for j in &self.joints {
            if let Some(k) = j.stiffness {
                non_negative("joint stiffness", k)?;
            }
            non_negative("hub inertia", j.hub_inertia)?;
        }
        Ok(())
    }

    /// min over links of √(EI/ρAL⁴) [rad/s]: the scale the root search starts from.
    fn bending_scale(&self) -> f64 {
        self.links
            .iter()
            .map(|l| (l.ei / l.rho_a).sqrt() / (l.length * l.length))
            .fold(f64::INFINITY, f64::min)
    }

    /// Rigid modes: one per joint with a zero spring.
    pub fn rigid_modes(&self) -> usize {
        self.joints
            .iter()
            .filter(|j| j.stiffness == Some(0.0))
            .count()
    }

    fn dof_map(&self) -> DofMap {
        let mut n = 0;
        let mut next = || {
            n += 1;
            Some(n - 1)
        };
        let mut ends: Vec<[Option<usize>; 4]> = Vec::with_capacity(self.links.len());
        for (i, j) in self.joints.iter().enumerate() {
            let (w0, a0) = if i == 0 {
                (None, j.stiffness.and_then(|_| next()))
            } else {
                let prev = ends[i - 1];
                match j.stiffness {
                    Some(_) => (prev[2], next()),
                    None => (prev[2], prev[3]),
                }
            };
            ends.push([w0, a0, next(), next()]);
        }
        DofMap { ends, n }
    }

    /// The global dynamic stiffness D(ω) (module docs), row-major n × n.
    fn dynamic_stiffness(&self, map: &DofMap, omega: f64) -> Vec<f64> {
        let n = map.n;
        let mut d = vec![0.0; n * n];
        let mut add = |i: Option<usize>, j: Option<usize>, v: f64| {
            if let (Some(i), Some(j)) = (i, j) {
                d[i * n + j] += v;
            }
        };
        let w2 = omega * omega;
        for (i, (l, jt)) in self.links.iter().zip(&self.joints).enumerate() {
            let e = map.ends[i];
            let m = member_stiffness(l, omega);
            for a in 0..4 {
                for b in 0..4 {
                    add(e[a], e[b], m[a][b]);
                }
            }
            // The joint spring between the parent's tip slope and this root slope (or ground).
            if let Some(k) = jt.stiffness {
                let parent = if i == 0 { None } else { map.ends[i - 1][3] };
                add(e[1], e[1], k);
                add(parent, parent, k);
                add(e[1], parent, -k);
                add(parent, e[1], -k);
            }
            add(e[1], e[1], -w2 * jt.hub_inertia);
            add(e[2], e[2], -w2 * l.tip_mass);
            add(e[3], e[3], -w2 * l.tip_inertia);
        }
        d
    }

    /// J(ω): the number of natural frequencies below ω > 0 (Wittrick–Williams, module docs).
    pub fn count_below(&self, omega: f64) -> usize {
        let map = self.dof_map();
        let members: usize = self
            .links
            .iter()
            .map(|l| clamped_clamped_below(beta(l, omega) * l.length))
            .sum();
        let mut d = self.dynamic_stiffness(&map, omega);
        members + negative_eigenvalues(&mut d, map.n)
    }

    /// The first `count` natural frequencies ω [rad/s], ascending, rigid modes (0) first.
    pub fn frequencies(&self, count: usize) -> Result<Vec<f64>> {
        self.validate()?;
        let rigid = self.rigid_modes();
        let scale = self.bending_scale();
        let mut out = Vec::with_capacity(count);
        let mut hi = scale;
        for n in 1..=count {
            if n <= rigid {
                out.push(0.0);
                continue;
            }
            let mut lo = out.last().copied().unwrap_or(0.0);
            let mut doublings = 0;
            while self.count_below(hi) < n {
                lo = hi;
                hi *= 2.0;
                doublings += 1;
                if doublings > 200 || !hi.is_finite() {
                    return Err(AnalyticError::TooFewRoots {
                        what: "spring-jointed chain",
                        found: n - 1,
                        wanted: count,
                        limit: hi,
                    });
                }
            }
            let mut iterations = 0;
            while hi - lo > 4.0 * f64::EPSILON * hi {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if self.count_below(mid) >= n {
                    hi = mid;
                } else {
                    lo = mid;
                }
                iterations += 1;
                if iterations > 400 {
                    return Err(AnalyticError::NoConvergence {
                        what: "spring-jointed chain bisection",
                        iterations,
                    });
                }
            }
            out.push(0.5 * (lo + hi));
        }
        Ok(out)
    }

    /// The first `count` natural frequencies (Hz).
    pub fn frequencies_hz(&self, count: usize) -> Result<Vec<f64>> {
        Ok(self
            .frequencies(count)?
            .into_iter()
            .map(|w| w / (2.0 * PI))
            .collect())
    }

    /// Equal sections and no lumped bodies: what the single-beam limits need.
    fn uniform_section(&self) -> Result<(f64, f64, f64)> {
        let first = self.links[0];
        let plain = self.links.iter().all(|l| {
            l.ei == first.ei && l.rho_a == first.rho_a && l.tip_mass == 0.0 && l.tip_inertia == 0.0
        }) && self.joints.iter().all(|j| j.hub_inertia == 0.0);
        if !plain {
            return Err(AnalyticError::Unsupported(
                "the single-beam limits of the chain need equal sections and no hub or tip bodies"
                    .into(),
            ));
        }
        let length = self.links.iter().map(|l| l.length).sum();
        Ok((first.ei, first.rho_a, length))
    }

    /// K → ∞ on every joint: the clamped–free beam of length ΣLᵢ (Hz).
    pub fn clamped_limit_hz(&self, count: usize) -> Result<Vec<f64>> {
        let (ei, rho_a, length) = self.uniform_section()?;
        bending_frequencies_hz(BeamSupport::ClampedFree, ei, rho_a, length, count)
    }

    /// K₁ → 0, every other K → ∞: the pinned–free beam of length ΣLᵢ, its rigid rotation (0)
    /// first (Hz).
    pub fn pinned_limit_hz(&self, count: usize) -> Result<Vec<f64>> {
        let (ei, rho_a, length) = self.uniform_section()?;
        let mut out = vec![0.0];
        if count > 1 {
            out.extend(bending_frequencies_hz(
                BeamSupport::PinnedFree,
                ei,
                rho_a,
                length,
                count - 1,
            )?);
        }
        out.truncate(count);
        Ok(out)
    }
}

fn beta(l: &ChainLink, omega: f64) -> f64 {
    (omega * omega * l.rho_a / l.ei).powf(0.25)
}

/// sech x without overflow.
fn sech(x: f64) -> f64 {
    let e = (-x.abs()).exp();
    2.0 * e / (1.0 + e * e)
}

/// Clamped–clamped frequencies of one link below βL (Wittrick–Williams J₀; module docs).
/// sgn(1 − cos x cosh x) = sgn(sech x − cos x).
fn clamped_clamped_below(x: f64) -> usize {
    let j = (x / PI).floor() as usize;
    let s = (sech(x) - x.cos()).signum();
    let parity = if j.is_multiple_of(2) { 1.0 } else { -1.0 };
    let correction = 0.5 * (1.0 - parity * s);
    (j as f64 - correction).round().max(0.0) as usize
}

/// Dynamic stiffness of one link, DOFs (w(0), w'(0), w(L), w'(L)) → end forces
/// (EI w'''(0), −EI w''(0), −EI w'''(L), EI w''(L)): D = F A⁻¹ in the bounded basis
/// (cos βx, sin βx, e^{−βx}, e^{−β(L−x)}).
fn member_stiffness(l: &ChainLink, omega: f64) -> [[f64; 4]; 4] {
    let b = beta(l, omega);
    let len = l.length;
    // derivative k (0..=3) of the four basis functions at x
    let basis = |x: f64, k: usize| -> [f64; 4] {
        let (c, s) = ((b * x).cos(), (b * x).sin());
        let (e0, e1) = ((-b * x).exp(), (-b * (len - x)).exp());
        let bk = b.powi(k as i32);
        let v = match k {
            0 => [c, s, e0, e1],
            1 => [-s, c, -e0, e1],
            2 => [-c, -s, e0, e1],
            _ => [s, -c, -e0, e1],
        };
        v.map(|y| bk * y)
    };
    let a = [basis(0.0, 0), basis(0.0, 1), basis(len, 0), basis(len, 1)];
    let f = [
        basis(0.0, 3).map(|y| l.ei * y),
        basis(0.0, 2).map(|y| -l.ei * y),
        basis(len, 3).map(|y| -l.ei * y),
        basis(len, 2).map(|y| l.ei * y),
    ];
    // D = F A⁻¹ ⇔ Aᵀ Dᵀ = Fᵀ: solve with Aᵀ for each row of D.
    let at = transpose(a);
    let mut d = [[0.0; 4]; 4];
    for r in 0..4 {
        d[r] = solve4(at, f[r]);
    }
    for r in 0..4 {
        for c in 0..r {
            let m = 0.5 * (d[r][c] + d[c][r]);
            d[r][c] = m;
            d[c][r] = m;
        }
    }
    d
}

fn transpose(a: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut t = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// Gaussian elimination with partial pivoting on a 4 × 4 system.
fn solve4(mut a: [[f64; 4]; 4], mut y: [f64; 4]) -> [f64; 4] {
    for k in 0..4 {
        let p = (k..4)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap_or(k);
        a.swap(k, p);
        y.swap(k, p);
        for i in k + 1..4 {
            let f = a[i][k] / a[k][k];
            for j in k..4 {
                a[i][j] -= f * a[k][j];
            }
            y[i] -= f * y[k];
        }
    }
    let mut x = [0.0; 4];
    for k in (0..4).rev() {
        let s: f64 = (k + 1..4).map(|j| a[k][j] * x[j]).sum();
        x[k] = (y[k] - s) / a[k][k];
    }
    x
}

/// Number of negative eigenvalues of the symmetric n × n matrix `a` (row-major, overwritten),
/// by cyclic Jacobi rotations to an off-diagonal norm below ε² of the matrix norm.
fn negative_eigenvalues(a: &mut [f64], n: usize) -> usize {
    let norm2: f64 = a.iter().map(|x| x * x).sum();
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j] * a[i * n + j])
            .sum();
        if off <= f64::EPSILON * f64::EPSILON * norm2 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let (app, aqq) = (a[p * n + p], a[q * n + q]);
                let theta = (aqq - app) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (akp, akq) = (a[k * n + p], a[k * n + q]);
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[p * n + k], a[q * n + k]);
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
            }
        }
    }
    (0..n).filter(|&i| a[i * n + i] < 0.0).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two links of the `two-link-free` scene's section (ft, slug, s).
    fn chain(k1: Option<f64>, k2: Option<f64>) -> SpringJointedChain {
        let link = |length| ChainLink {
            length,
            ei: 5029.5312,
            rho_a: 1.764,
            tip_mass: 0.0,
            tip_inertia: 0.0,
        };
        let joint = |stiffness| ChainJoint {
            stiffness,
            hub_inertia: 0.0,
        };
        SpringJointedChain {
            links: vec![link(3.0), link(2.0)],
            joints: vec![joint(k1), joint(k2)],
        }
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn static_limit_of_the_member_stiffness_is_the_beam_stiffness_matrix() {
        let l = ChainLink {
            length: 2.0,
            ei: 3.0,
            rho_a: 1.0,
            tip_mass: 0.0,
            tip_inertia: 0.0,
        };
        // ω small: D → the static Hermite stiffness EI/L³ [12 6L −12 6L; …] (sign convention
        // of the end forces above).
        let d = member_stiffness(&l, 1e-3);
        let (ei, len) = (l.ei, l.length);
        let k = [
            [12.0, 6.0 * len, -12.0, 6.0 * len],
            [6.0 * len, 4.0 * len * len, -6.0 * len, 2.0 * len * len],
            [-12.0, -6.0 * len, 12.0, -6.0 * len],
            [6.0 * len, 2.0 * len * len, -6.0 * len, 4.0 * len * len],
        ];
        for i in 0..4 {
            for j in 0..4 {
                let want = ei / len.powi(3) * k[i][j];
                assert!(
                    (d[i][j] - want).abs() < 1e-5 * 12.0 * ei / len,
                    "D[{i}][{j}] = {} vs {want}",
                    d[i][j]
                );
            }
        }
    }

    #[test]
    fn rigid_joints_give_the_clamped_free_beam() {
        let c = chain(None, None);
        let got = c.frequencies_hz(5).unwrap();
        let want = c.clamped_limit_hz(5).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert!(rel(*g, *w) < 1e-12, "{g} vs {w}");
        }
    }

    #[test]
    fn free_root_and_rigid_elbow_give_the_pinned_free_beam() {
        let c = chain(Some(0.0), None);
        let got = c.frequencies_hz(5).unwrap();
        let want = c.pinned_limit_hz(5).unwrap();
        assert_eq!(got[0], 0.0);
        for (g, w) in got.iter().zip(&want).skip(1) {
            assert!(rel(*g, *w) < 1e-12, "{g} vs {w}");
        }
    }

    #[test]
    fn stiff_springs_tend_to_the_clamped_limit_and_soft_root_to_the_pinned_limit() {
        // The spring's compliance shifts a frequency by O(EI/(K L)): each decade of K removes
        // a decade of the difference.
        let clamped = chain(None, None).frequencies_hz(4).unwrap();
        let pinned = chain(Some(0.0), None).frequencies_hz(4).unwrap();
        let mut last_clamped = f64::INFINITY;
        let mut last_pinned = f64::INFINITY;
        for k in [1e5, 1e6, 1e7, 1e8] {
            let f = chain(Some(k), Some(k)).frequencies_hz(4).unwrap();
            let e = (0..4).map(|i| rel(f[i], clamped[i])).fold(0.0, f64::max);
            assert!(e < 0.2 * last_clamped, "K = {k}: {e} after {last_clamped}");
            last_clamped = e;
            let soft = chain(Some(1e3 / k), Some(k)).frequencies_hz(4).unwrap();
            let e = (1..4).map(|i| rel(soft[i], pinned[i])).fold(0.0, f64::max);
            assert!(e < 0.2 * last_pinned, "K = {k}: {e} after {last_pinned}");
            last_pinned = e;
        }
        assert!(last_clamped < 1e-4 && last_pinned < 1e-4);
    }

    #[test]
    fn frequencies_are_continuous_and_increasing_in_the_joint_stiffness() {
        // Scene springs K₁ = 120, K₂ = 20 lbf·ft/rad; a relative change δ in K moves every
        // frequency by at most δ (ω² is at most linear in K) and never down (Rayleigh).
        let base = chain(Some(120.0), Some(20.0)).frequencies_hz(5).unwrap();
        for delta in [1e-2, 1e-4, 1e-6] {
            let up = chain(Some(120.0 * (1.0 + delta)), Some(20.0 * (1.0 + delta)))
                .frequencies_hz(5)
                .unwrap();
            for (u, b) in up.iter().zip(&base) {
                assert!(*u >= *b * (1.0 - 1e-14), "δ = {delta}: {u} < {b}");
                assert!(rel(*u, *b) <= delta, "δ = {delta}: {u} vs {b}");
            }
        }
        // ascending, distinct, positive
        assert!(base[0] > 0.0 && base.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn count_matches_the_roots_found() {
        let c = chain(Some(120.0), Some(20.0));
        let f = c.frequencies(6).unwrap();
        for (n, w) in f.iter().enumerate() {
            assert_eq!(c.count_below(w * (1.0 - 1e-9)), n);
            assert_eq!(c.count_below(w * (1.0 + 1e-9)), n + 1);
        }
    }

    #[test]
    fn hinged_elbow_adds_a_rigid_mode() {
        let c = chain(Some(0.0), Some(0.0));
        let f = c.frequencies(3).unwrap();
        assert_eq!(&f[..2], &[0.0, 0.0]);
        assert!(f[2] > 0.0);
        assert_eq!(c.count_below(0.5 * f[2]), 2);
    }
}
