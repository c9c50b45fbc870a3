//! The default step of the implicit methods (module docs of [`super`], "Dynamics").

use super::model::Model;
use super::modes::{linearized, link_modes};
use crate::error::FemError;

/// Default step: the largest h whose estimated phase error of the modes the loads excite stays
/// below this fraction of each observable's scale ([`default_step`]).
pub const PHASE_ERROR_TOLERANCE: f64 = 1e-4;

/// Largest step ≤ h that divides the output interval evenly.
pub(super) fn fit(h: f64, out: f64) -> f64 {
    if h >= out {
        out
    } else {
        out / (out / h).ceil()
    }
}

/// Default step from the linearized modes and the scene's loads.
///
/// The implicit midpoint rule turns a mode ω into ω_h = (2/h)·atan(ωh/2) ≈ ω(1 − (ωh)²/12), so
/// after t_end a mode of amplitude A is off by A·min(2, ω³h²t_end/12). Each mode's amplitude is
/// estimated from the loads that start it ringing: the imbalance at t = 0 (gravity against the
/// initial shape, centrifugal load θ̇²(j₁ + K_c d₀), the motor torque or −b₀θ̈ of a prescribed base)
/// plus the largest jump of those loads between samples a quarter output interval apart (a
/// bang-bang switch): A_k = |φ_k·F|/(φ_kᵀMφ_k ω_k²) times the mode's share of three observables:
/// the payload's height z_C, its turning-plane position y_C + (L + c)θ, and θ. The error sums of
/// the payload's position (height and turning plane together) and of θ are held below
/// [`PHASE_ERROR_TOLERANCE`] times their scales: the payload's initial height plus, for a free
/// base, (L + c)·min(Θ, 1), plus Σ A_k; Θ plus Σ A_k (base), with Θ the rigid base excursion
/// over the run (prescribed law, or a rigid-body integration of
/// J₀θ̈ = T(t) − b_mθ̇ − K(θ − θ₀) for a free base). A mode's phase error grows over
/// min(t_end, 1/(eσ)), σ = φᵀCφ/(2φᵀMφ) its Kelvin–Voigt (and motor-friction) decay rate.
/// Torsion and axial modes hardly move these observables and so do not bound the step.
pub fn default_step(md: &Model, d0: &[f64], t_end: f64, out: f64) -> Result<f64, FemError> {
    let n = md.n;
    let free = md.free_base();
    let nn = n + usize::from(free);
    let (_, m) = linearized(md);
    let modes = link_modes(md, nn)?;
    // Load samples F(t) on (d, θ): imbalance and base-driven loads.
    let samples = (4.0 * t_end / out).ceil().max(1.0) as usize;
    let dt_s = t_end / samples as f64;
    let mut ksd0 = vec![0.0; n];
    md.ks.matvec(d0, &mut ksd0);
    let mut kcd0 = vec![0.0; n];
    md.kc.matvec(d0, &mut kcd0);
    // Rigid base: (θ, θ̇, θ̈) at the samples.
    let mut base = Vec::with_capacity(samples + 1);
    match md.prescribed(0.0) {
        Some(_) => {
            for i in 0..=samples {
                base.push(md.prescribed(i as f64 * dt_s).unwrap_or_default());
            }
        }
        None => {
            let (k_spring, set_point) = md.spring();
            let (mut th, mut w) = (md.initial_angle, md.initial_rate);
            let sub = 16;
            let hs = dt_s / sub as f64;
            let acc = |t: f64, th: f64, w: f64| {
                (md.motor_torque(t) - md.motor_friction * w - k_spring * (th - set_point)) / md.j0
            };
            base.push((th, w, acc(0.0, th, w)));
            for i in 0..samples {
                for j in 0..sub {
                    let t = i as f64 * dt_s + j as f64 * hs;
                    w += hs * acc(t, th, w);
                    th += hs * w;
                }
                let t = (i + 1) as f64 * dt_s;
                base.push((th, w, acc(t, th, w)));
            }
        }
    }
    let load = |i: usize, f: &mut [f64]| {
        let t = i as f64 * dt_s;
        let (_, w, a) = base[i];
        for j in 0..n {
            f[j] = -md.fg[j] - ksd0[j] + w * w * (md.j1[j] + kcd0[j]);
            if !free {
                f[j] -= md.b0[j] * a;
            }
        }
        if free {
            f[n] = md.motor_torque(t);
        }
    };
    let theta0 = base[0].0;
    let excursion = base
        .iter()
        .fold(0.0f64, |e, &(th, _, _)| e.max((th - theta0).abs()));
    let arm = md.length + md.offset;
    let mut f0 = vec![0.0; nn];
    let mut fa = vec![0.0; nn];
    let mut fb = vec![0.0; nn];
    load(0, &mut f0);
    // Per mode: excitation e_k = |φ·F(0)| + max_i |φ·(F(t_i) − F(t_{i−1}))|.
    let mut exc: Vec<f64> = modes
        .iter()
        .map(|md_k| crate::linalg::dot(&md_k.vector, &f0).abs())
        .collect();
    let mut jump = vec![0.0f64; modes.len()];
    fa.copy_from_slice(&f0);
    for i in 1..=samples {
        load(i, &mut fb);
        for (k, mk) in modes.iter().enumerate() {
            let dj: f64 = mk
                .vector
                .iter()
                .zip(fb.iter().zip(&fa))
                .map(|(p, (b, a))| p * (b - a))
                .sum();
            jump[k] = jump[k].max(dj.abs());
        }
        std::mem::swap(&mut fa, &mut fb);
    }
    // Amplitudes of (vertical, turning plane, base) per mode.
    let mut amp = Vec::with_capacity(modes.len());
    let mut horizon = Vec::with_capacity(modes.len());
    for (k, mk) in modes.iter().enumerate() {
        exc[k] += jump[k];
        let v = &mk.vector;
        let mut mv = 0.0;
        for a in 0..nn {
            for b in 0..nn {
                mv += v[a] * m[(a, b)] * v[b];
            }
        }
        let q = exc[k] / (mv * mk.omega * mk.omega);
        // Decay rate σ = φᵀCφ/(2φᵀMφ) (Kelvin–Voigt and motor friction): the phase error of a
        // damped mode, A e^(−σt)·ω³h²t/12, peaks at t = 1/σ.
        let mut cv = md.c.form(&v[..n], &v[..n]);
        if free {
            cv += md.motor_friction * v[n] * v[n];
        }
        let sigma = cv / (2.0 * mv);
        horizon.push(if sigma * t_end > 1.0 {
            1.0 / (std::f64::consts::E * sigma)
        } else {
            t_end
        });
        let th = if free { v[n] } else { 0.0 };
        amp.push([
            q * md.tip.z_c.dot(&v[..n]).abs(),
            q * (md.tip.y_c.dot(&v[..n]) + arm * th).abs(),
            q * th.abs(),
        ]);
    }
    // The payload's position (height and turning plane: one vector, so a barely moving
    // component is not held to its own tiny scale) and the base angle. A prescribed rotation
    // is exact and adds nothing to the position's scale.
    let sum = |c: usize| amp.iter().map(|a| a[c]).sum::<f64>();
    let rigid_arc = if free { arm * excursion.min(1.0) } else { 0.0 };
    let scale = [
        md.tip.z_c.dot(d0).abs() + rigid_arc + sum(0) + sum(1),
        if free { excursion + sum(2) } else { 0.0 },
    ];
    let within = |h: f64| {
        (0..2).all(|c| {
            if scale[c] <= 0.0 {
                return true;
            }
            let e: f64 = modes
                .iter()
                .zip(amp.iter().zip(&horizon))
                .map(|(mk, (a, t))| {
                    let a = if c == 0 { a[0] + a[1] } else { a[2] };
                    a * (mk.omega.powi(3) * h * h * t / 12.0).min(2.0)
                })
                .sum();
            e <= PHASE_ERROR_TOLERANCE * scale[c]
        })
    };
    if within(out) {
        return Ok(out);
    }
    // Bisection in log h between a step that resolves the fastest mode to 1e-9 and `out`.
    let fastest = modes.iter().fold(0.0f64, |w, mk| w.max(mk.omega));
    let (mut lo, mut hi) = ((1e-9f64).sqrt() / fastest.max(1.0 / out), out);
    if !within(lo) {
        return Ok(lo);
    }
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if within(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}
