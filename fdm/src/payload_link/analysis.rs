//! `modes` and `statics` of the payload link.
//!
//! **Modes**: (K − Ω²H) x = ω² M x with M the mass of ż = (θ̇, q̇) at the undeformed state —
//! M_ff, and with a free base the θ row (M_θθ(0), c) — and K the strain stiffness (plus the
//! joint spring on θ), linearized about the straight rod at the base's reference rate Ω (the
//! rate of a constant-rate base, else 0). −Ω²H is the centrifugal softening and the
//! foreshortening's tension stiffening of the θ̇²M_θθ(q)/2 term. The gyroscopic coupling
//! Ω(B − Bᵀ) is left out (undamped, symmetric problem), densely.
//! Each mode is named by the field (or θ) carrying most of its kinetic energy. Solved in the
//! flexibility form (K + σM)⁻¹M (see [`PayloadLinkModel::spectrum`]).
//!
//! **Statics**: K q = f_g, the discrete static equations under gravity at rest (the static-sag
//! start of the dynamics).

use data::scene::{LinkField, PayloadLink, PrescribedMotion};
use data::{BackendKind, Cost, ModalResult, ModeShape, Scene, StaticResult};
use faer::{Mat, Side};

use super::{BaseDrive, PayloadLinkModel, apply};
use crate::error::FdmError;
use crate::settings::ValidatedSettings;

/// Frequencies (rad/s, ascending), mode vectors (columns, over ż) and kinds.
pub struct Spectrum {
    pub omega: Vec<f64>,
    pub vectors: Mat<f64>,
    pub kinds: Vec<String>,
}

impl PayloadLinkModel {
    /// The base rate the modes are linearized at.
    pub fn reference_rate(&self) -> f64 {
        match &self.drive {
            BaseDrive::Prescribed(PrescribedMotion::ConstantRate { rate }) => self.rate0 + rate,
            _ => 0.0,
        }
    }

    /// Dense (M, K) over ż = (θ̇ if free, q̇).
    pub fn linearized(&self) -> (Mat<f64>, Mat<f64>) {
        let off = usize::from(self.free_base());
        let nt = self.n + off;
        let mut m = Mat::<f64>::zeros(nt, nt);
        let mut k = Mat::<f64>::zeros(nt, nt);
        for &(i, j, c) in &self.mff.entries {
            m[(i + off, j + off)] += c;
        }
        let w2 = self.reference_rate().powi(2);
        for (_, kf) in &self.stiffness {
            for &(i, j, c) in &kf.entries {
                k[(i + off, j + off)] += c;
            }
        }
        for &(i, j, c) in &self.h_theta.entries {
            k[(i + off, j + off)] -= w2 * c;
        }
        if let BaseDrive::Free { stiffness, .. } = &self.drive {
            m[(0, 0)] = self.m0;
            for i in 0..self.n {
                m[(0, i + 1)] = self.c_theta[i];
                m[(i + 1, 0)] = self.c_theta[i];
            }
            k[(0, 0)] = *stiffness;
        }
        (m, k)
    }

    /// The linearized spectrum (module docs).
    pub fn spectrum(&self) -> Result<Spectrum, FdmError> {
        let (m, k) = self.linearized();
        let n = m.nrows();
        let numerical = |message: String| FdmError::Numerical { t: 0.0, message };
        // Flexibility form: the lowest ω² are the largest μ = 1/(ω² + σ) of
        // (K + σM)⁻¹M, which a backward-stable solver resolves to ε relative to μ_max; in the
        // stiffness form they would sit ~10 decades below ‖M⁻¹K‖ (axial and torsional
        // sawtooth) and lose digits at fine grids. σ > 0 makes a free base's θ definite.
        let sigma = 1e-9
            * (0..n)
                .map(|i| k[(i, i)] / m[(i, i)])
                .fold(0.0f64, f64::max)
                .max(f64::MIN_POSITIVE);
        let shifted = Mat::<f64>::from_fn(n, n, |i, j| k[(i, j)] + sigma * m[(i, j)]);
        let llt = shifted.llt(Side::Lower).map_err(|e| {
            numerical(format!(
                "stiffness not positive definite at the reference rate (the rod buckles): {e:?}"
            ))
        })?;
        let l = llt.L();
        let mut t = m.clone();
        l.solve_lower_triangular_in_place(&mut t);
        let mut c = t.transpose().to_owned();
        l.solve_lower_triangular_in_place(&mut c);
        let c = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
        let ev = c
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| numerical(format!("eigen decomposition failed: {e:?}")))?;
        let s = ev.S().column_vector();
        // descending μ ↔ ascending ω
        let mut omega = Vec::with_capacity(n);
        let mut x = Mat::<f64>::zeros(n, n);
        let u = ev.U();
        for (jj, j) in (0..n).rev().enumerate() {
            let mu = s[j];
            if mu.is_nan() || mu <= 0.0 {
                return Err(numerical(format!(
                    "non-positive flexibility eigenvalue {mu:e}"
                )));
            }
            omega.push((1.0 / mu - sigma).max(0.0).sqrt());
            for i in 0..n {
                x[(i, jj)] = u[(i, j)];
            }
        }
        l.transpose().solve_upper_triangular_in_place(&mut x);
        let off = usize::from(self.free_base());
        let kinds = (0..n)
            .map(|j| {
                // kinetic-energy share per coordinate group: x_i (M x)_i
                let mx: Vec<f64> = (0..n)
                    .map(|i| (0..n).map(|l| m[(i, l)] * x[(l, j)]).sum::<f64>())
                    .collect();
                let mut best = (
                    "rigid",
                    if off == 1 {
                        x[(0, j)] * mx[0]
                    } else {
                        f64::MIN
                    },
                );
                for &f in &self.fields {
                    let e: f64 = (1..=self.r)
                        .filter_map(|i| self.index(f, i))
                        .map(|ix| x[(ix + off, j)] * mx[ix + off])
                        .sum();
                    if e > best.1 {
                        best = (kind_name(f), e);
                    }
                }
                best.0.to_string()
            })
            .collect();
        Ok(Spectrum {
            omega,
            vectors: x,
            kinds,
        })
    }
}

/// The kind of a mode dominated by field f.
pub fn kind_name(f: LinkField) -> &'static str {
    match f {
        LinkField::Axial => "axial",
        LinkField::Horizontal => "bending-horizontal",
        LinkField::Vertical => "bending-vertical",
        LinkField::Torsion => "torsion",
    }
}

/// `modes` of a payload-link scene: the lowest `count` frequencies with their kinds; each
/// shape is the dominant field at the stations (root included), unit peak.
pub fn modes(
    scene: &Scene,
    p: &PayloadLink,
    s: &ValidatedSettings,
    count: usize,
) -> Result<ModalResult, FdmError> {
    let clock = std::time::Instant::now();
    let model = PayloadLinkModel::from_payload_link(scene, p, s.stations)?;
    let sp = model.spectrum()?;
    let off = usize::from(model.free_base());
    let count = count.min(sp.omega.len());
    let xs: Vec<f64> = (0..=model.r).map(|i| i as f64 * model.h).collect();
    let mut shapes = Vec::with_capacity(count);
    for j in 0..count {
        let field = model
            .fields
            .iter()
            .copied()
            .find(|f| kind_name(*f) == sp.kinds[j])
            .unwrap_or(model.fields[0]);
        let mut w: Vec<f64> = (0..=model.r)
            .map(|i| {
                model
                    .index(field, i)
                    .map_or(0.0, |ix| sp.vectors[(ix + off, j)])
            })
            .collect();
        let peak = w
            .iter()
            .fold(0.0f64, |a, v| if v.abs() > a.abs() { *v } else { a });
        if peak != 0.0 {
            w.iter_mut().for_each(|v| *v /= peak);
        }
        shapes.push(ModeShape {
            link: 1,
            x: xs.clone(),
            transverse: w,
        });
    }
    Ok(ModalResult {
        backend: BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        frequencies_hz: sp.omega[..count]
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect(),
        kinds: sp.kinds[..count].to_vec(),
        shapes,
        cost: Cost {
            wall_time_s: clock.elapsed().as_secs_f64(),
            dofs: sp.omega.len(),
            factorizations: 1,
            ..Cost::default()
        },
    })
}

/// `statics`: the gravity sag, w_L and w′_L.
pub fn statics(
    scene: &Scene,
    p: &PayloadLink,
    s: &ValidatedSettings,
) -> Result<StaticResult, FdmError> {
    let clock = std::time::Instant::now();
    let model = PayloadLinkModel::from_payload_link(scene, p, s.stations)?;
    if model.f_gravity.is_none() {
        return Err(FdmError::Unsupported(format!(
            "fdm statics of `{}`: the payload link's static load is gravity, and the scene has \
             none (or no vertical field)",
            scene.name
        )));
    }
    let q = model.static_sag()?;
    Ok(StaticResult {
        backend: BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        tip_deflection: apply(&model.tip[2], &q),
        tip_rotation: apply(&model.slope_w, &q),
        cost: Cost {
            wall_time_s: clock.elapsed().as_secs_f64(),
            dofs: model.n,
            factorizations: 1,
            ..Cost::default()
        },
    })
}
