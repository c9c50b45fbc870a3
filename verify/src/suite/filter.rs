//! Zero-phase low-pass filtering of sampled histories (the `lowpassF:` quantity prefix).
//!
//! Undamped flexible arms carry high-frequency content that converges slowly with refinement,
//! while the slow motion converges fast. A low-passed history separates the two: it is compared
//! across backends beside the raw history.
//!
//! # Filter
//! Second-order Butterworth low-pass with cut-off f_c, designed by the bilinear transform with
//! pre-warping, K = tan(π f_c Δt):
//!
//! ```text
//! H(z) = K² (1 + 2z⁻¹ + z⁻²) / ((1 + √2K + K²) + 2(K² − 1) z⁻¹ + (1 − √2K + K²) z⁻²)
//! ```
//!
//! applied forward and then backward in time (filtfilt). The combined response is real and
//! non-negative, |H(f)|² = 1 / (1 + (tan(π f Δt) / tan(π f_c Δt))⁴): no phase shift (no lag),
//! unit gain at f = 0, one half (−6 dB) at f_c, and −80 dB one decade above f_c (f ≪ 1/Δt).
//!
//! # Edges
//! Each end is extended by `pad` samples of odd (point) reflection about the end sample,
//! x(−k) = 2x(0) − x(k), which continues the value and the slope; `pad` = ⌈6 / (f_c Δt)⌉
//! samples (about 27 decay times √2/(2π f_c) of the filter's poles), at most n − 1. Each pass
//! starts from the filter's steady state for a constant input equal to its first sample, so a
//! constant signal is returned unchanged at every sample, edges included, and the start-up
//! transient of the slope has decayed by ~e⁻²⁷ before the real samples are reached. The padding
//! is cut off afterwards. The filter runs on x − x(0) (x(0) added back after), which is the same
//! linear filter and returns a constant signal bit-exactly.
//!
//! # Sampling
//! The filter needs a uniform grid: [`resample_uniform`] interpolates a history linearly onto
//! n equal steps over its own time span.
//!
//! It sees only the samples. Content above their Nyquist frequency 1/(2Δt) has already
//! aliased into the band below it, where no low-pass can take it out. Undamped links keep
//! ringing in their high modes, and a joint angle on a massless hub carries that ringing at
//! the 1e-3 rad level: `two-link-free-undamped` sampled every 0.01 s low-passes to histories
//! that differ by ~1e-3 rad between discretizations within the first 0.1 s, sampled every
//! 2e-4 s to ones that agree to ~1e-5 (data/cases/two_link_rows.toml). Such a history must be
//! sampled finely (`--output-interval`, the `output_interval` setting of a case row) before
//! it is low-passed.
//!
//! The ends share that limit: the odd reflection about an end sample makes the filtered
//! history pass through that sample exactly, ringing included, and the error decays into the
//! history over the filter's decay time √2/(2π f_c). Comparisons of low-passed histories
//! therefore leave out one cut-off period 1/f_c at each end ([`interior`]); e^(−4.4) of the
//! end sample's ringing is left at that distance (measured on `two-link-free-undamped`, fem
//! 16 against 32 elements sampled every 2e-4 s: 7.7e-4 rad at the end sample, 1.4e-5 rad from
//! 0.05 s inside on, the interior's own difference).

/// Why a history cannot be low-passed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilterError {
    #[error("cut-off {cutoff_hz} Hz must be finite and > 0")]
    BadCutoff { cutoff_hz: f64 },
    #[error(
        "cut-off {cutoff_hz} Hz is at or above the Nyquist frequency {nyquist_hz:.6} Hz of the \
         history's sampling"
    )]
    AboveNyquist { cutoff_hz: f64, nyquist_hz: f64 },
    #[error("a history needs at least 3 samples over a positive time span to be filtered")]
    TooShort,
    #[error(
        "a low-passed history is compared without one cut-off period (1/{cutoff_hz} Hz) at each \
         end, and this one spans {span} s: give a longer run or a higher cut-off"
    )]
    NoInterior { cutoff_hz: f64, span: f64 },
}

/// Coefficients of the second-order section y = (b·x − a₁y₋₁ − a₂y₋₂), a₀ = 1.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Biquad {
    b: [f64; 3],
    a1: f64,
    a2: f64,
}

impl Biquad {
    /// Butterworth low-pass, cut-off `cutoff_hz`, sample step `dt`.
    fn butterworth_lowpass(cutoff_hz: f64, dt: f64) -> Result<Biquad, FilterError> {
        if !(cutoff_hz.is_finite() && cutoff_hz > 0.0) {
            return Err(FilterError::BadCutoff { cutoff_hz });
        }
        let nyquist_hz = 0.5 / dt;
        if cutoff_hz >= nyquist_hz {
            return Err(FilterError::AboveNyquist {
                cutoff_hz,
                nyquist_hz,
            });
        }
        let k = (std::f64::consts::PI * cutoff_hz * dt).tan();
        let s2 = std::f64::consts::SQRT_2;
        let norm = 1.0 / (1.0 + s2 * k + k * k);
        let b0 = k * k * norm;
        Ok(Biquad {
            b: [b0, 2.0 * b0, b0],
            a1: 2.0 * (k * k - 1.0) * norm,
            a2: (1.0 - s2 * k + k * k) * norm,
        })
    }

    /// One pass in transposed direct form II, started from the steady state of a constant
    /// input equal to `x[0]` (the gain at f = 0 is 1, so the state is z₁ = (1 − b₀)x₀,
    /// z₂ = (b₂ − a₂)x₀).
    fn run(&self, x: &mut [f64]) {
        let Some(&x0) = x.first() else { return };
        let [b0, b1, b2] = self.b;
        let (mut z1, mut z2) = ((1.0 - b0) * x0, (b2 - self.a2) * x0);
        for v in x.iter_mut() {
            let xin = *v;
            let y = b0 * xin + z1;
            z1 = b1 * xin - self.a1 * y + z2;
            z2 = b2 * xin - self.a2 * y;
            *v = y;
        }
    }
}

/// Zero-phase low-pass (forward–backward second-order Butterworth) of samples on a uniform
/// grid of step `dt`; see the module docs for the design and the edge handling.
pub fn lowpass_zero_phase(x: &[f64], dt: f64, cutoff_hz: f64) -> Result<Vec<f64>, FilterError> {
    let n = x.len();
    if n < 3 || !(dt.is_finite() && dt > 0.0) {
        return Err(FilterError::TooShort);
    }
    let section = Biquad::butterworth_lowpass(cutoff_hz, dt)?;
    let pad = ((6.0 / (cutoff_hz * dt)).ceil() as usize).clamp(1, n - 1);
    // The filter is linear with unit gain at f = 0: filtering x − x₀ and adding x₀ back is the
    // same filter, and it keeps a constant signal bit-exact (the deviation is exactly zero).
    let offset = x[0];
    let dev = |v: f64| v - offset;
    let mut ext = Vec::with_capacity(n + 2 * pad);
    ext.extend((1..=pad).rev().map(|k| 2.0 * dev(x[0]) - dev(x[k])));
    ext.extend(x.iter().map(|v| dev(*v)));
    ext.extend((1..=pad).map(|k| 2.0 * dev(x[n - 1]) - dev(x[n - 1 - k])));
    section.run(&mut ext);
    ext.reverse();
    section.run(&mut ext);
    ext.reverse();
    Ok(ext[pad..pad + n].iter().map(|v| v + offset).collect())
}

/// The samples of a history low-passed on a grid of `n` steps `dt` that comparisons use: all
/// but one cut-off period 1/f_c at each end, where the filtered history still carries the end
/// samples' unfiltered values (module docs, "Sampling").
pub fn interior(n: usize, dt: f64, cutoff_hz: f64) -> Result<std::ops::Range<usize>, FilterError> {
    let edge = (1.0 / (cutoff_hz * dt)).ceil() as usize;
    if n < 3 || n.saturating_sub(2 * edge) < 3 {
        return Err(FilterError::NoInterior {
            cutoff_hz,
            span: n.saturating_sub(1) as f64 * dt,
        });
    }
    Ok(edge..n - edge)
}

/// The history `(time, values)` linearly interpolated onto `n` equal steps over its own span:
/// (grid step, grid times, values).
pub fn resample_uniform(
    time: &[f64],
    values: &[f64],
    n: usize,
) -> Result<(f64, Vec<f64>, Vec<f64>), FilterError> {
    let (Some(&t0), Some(&t1)) = (time.first(), time.last()) else {
        return Err(FilterError::TooShort);
    };
    if n < 3 || t1 <= t0 || time.len() != values.len() {
        return Err(FilterError::TooShort);
    }
    let dt = (t1 - t0) / (n - 1) as f64;
    let grid: Vec<f64> = (0..n)
        .map(|k| if k == n - 1 { t1 } else { t0 + k as f64 * dt })
        .collect();
    let vals = grid
        .iter()
        .map(|&t| data::results::interpolate(time, values, t).ok_or(FilterError::TooShort))
        .collect::<Result<Vec<f64>, _>>()?;
    Ok((dt, grid, vals))
}

/// Combined magnitude |H(f)|² of the forward–backward filter at frequency `f_hz` (the design
/// formula, for tests and documentation of the attenuation).
pub fn designed_gain(f_hz: f64, cutoff_hz: f64, dt: f64) -> f64 {
    let r =
        (std::f64::consts::PI * f_hz * dt).tan() / (std::f64::consts::PI * cutoff_hz * dt).tan();
    1.0 / (1.0 + r.powi(4))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn sine(f: f64, dt: f64, n: usize, phase: f64) -> Vec<f64> {
        (0..n)
            .map(|k| (2.0 * PI * f * k as f64 * dt + phase).sin())
            .collect()
    }

    fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
    }

    #[test]
    fn elem_lowpass_passes_a_slow_sinusoid_everywhere() {
        // 1 Hz through a 20 Hz cut-off over 10 s sampled at 1 kHz: the designed gain at 1 Hz is
        // 1 − 6e-6, and the odd-reflection padding keeps the edges within that too.
        let (dt, n) = (1e-3, 10_001);
        for phase in [0.0, 0.7, PI / 2.0] {
            let x = sine(1.0, dt, n, phase);
            let y = lowpass_zero_phase(&x, dt, 20.0).unwrap();
            let err = max_abs_diff(&x, &y);
            assert!(err < 1e-3, "phase {phase}: max error {err:.3e}");
            let interior = max_abs_diff(&x[1000..9000], &y[1000..9000]);
            let expected = 1.0 - designed_gain(1.0, 20.0, dt);
            assert!(
                (interior - expected).abs() < 1e-6,
                "interior error {interior:.3e} vs designed {expected:.3e}"
            );
        }
    }

    #[test]
    fn elem_lowpass_attenuates_a_fast_sinusoid_by_the_designed_amount() {
        let (dt, n, fc) = (1e-3, 10_001, 20.0);
        for f in [100.0, 200.0] {
            let x = sine(f, dt, n, 0.3);
            let y = lowpass_zero_phase(&x, dt, fc).unwrap();
            let amplitude = y[2000..8000].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let designed = designed_gain(f, fc, dt);
            assert!(designed < 3e-3, "design gain at {f} Hz: {designed:.3e}");
            assert!(
                (amplitude - designed).abs() < 0.02 * designed,
                "{f} Hz: amplitude {amplitude:.4e} vs designed {designed:.4e}"
            );
        }
        // At the cut-off the forward–backward gain is exactly one half.
        let x = sine(fc, dt, n, 0.0);
        let y = lowpass_zero_phase(&x, dt, fc).unwrap();
        let amplitude = y[2000..8000].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            (amplitude - 0.5).abs() < 2e-3,
            "gain at cut-off {amplitude}"
        );
    }

    #[test]
    fn elem_lowpass_has_zero_phase() {
        // A sinusoid at half the cut-off keeps its zero crossings (no lag), although a
        // single forward pass would delay it by ~7 ms.
        let (dt, n, fc, f) = (1e-3, 4001, 20.0, 10.0);
        let x = sine(f, dt, n, 0.0);
        let y = lowpass_zero_phase(&x, dt, fc).unwrap();
        let gain = designed_gain(f, fc, dt);
        let scaled: Vec<f64> = x.iter().map(|v| gain * v).collect();
        // y = gain · x exactly when the phase is zero; a lag τ would leave 2π f τ · gain.
        let err = max_abs_diff(&scaled[500..3500], &y[500..3500]);
        assert!(err < 1e-6, "deviation from a zero-phase response {err:.3e}");
        // And a pulse stays centred on its peak.
        let pulse: Vec<f64> = (0..n)
            .map(|k| (-((k as f64 - 2000.0) * dt / 0.05).powi(2)).exp())
            .collect();
        let yp = lowpass_zero_phase(&pulse, dt, fc).unwrap();
        let argmax = yp
            .iter()
            .enumerate()
            .fold(
                (0, f64::MIN),
                |m, (k, v)| if *v > m.1 { (k, *v) } else { m },
            )
            .0;
        assert_eq!(argmax, 2000);
    }

    #[test]
    fn elem_lowpass_keeps_a_constant_exactly_at_the_edges() {
        let x = vec![0.7312; 500];
        let y = lowpass_zero_phase(&x, 1e-3, 20.0).unwrap();
        let err = max_abs_diff(&x, &y);
        assert_eq!(err, 0.0, "constant changed by {err:.3e}");
        // A ramp is a straight line after filtering as well (odd reflection continues it).
        let ramp: Vec<f64> = (0..500).map(|k| 0.1 + 2e-3 * k as f64).collect();
        let yr = lowpass_zero_phase(&ramp, 1e-3, 20.0).unwrap();
        assert!(max_abs_diff(&ramp, &yr) < 1e-9);
    }

    #[test]
    fn elem_lowpass_refuses_bad_cutoffs() {
        let x = vec![0.0; 10];
        assert!(matches!(
            lowpass_zero_phase(&x, 1e-3, 600.0),
            Err(FilterError::AboveNyquist { .. })
        ));
        assert!(matches!(
            lowpass_zero_phase(&x, 1e-3, -1.0),
            Err(FilterError::BadCutoff { .. })
        ));
        assert!(matches!(
            lowpass_zero_phase(&x[..2], 1e-3, 1.0),
            Err(FilterError::TooShort)
        ));
    }

    #[test]
    fn elem_resample_uniform_interpolates_linearly() {
        let t = [0.0, 0.1, 0.3, 1.0];
        let v = [0.0, 1.0, 3.0, 10.0];
        let (dt, grid, vals) = resample_uniform(&t, &v, 11).unwrap();
        assert!((dt - 0.1).abs() < 1e-15);
        assert_eq!(grid.len(), 11);
        assert_eq!(*grid.last().unwrap(), 1.0);
        for (g, y) in grid.iter().zip(&vals) {
            assert!((10.0 * g - y).abs() < 1e-12);
        }
    }

    #[test]
    fn elem_ringing_reaches_the_filtered_ends_and_the_interior_leaves_it_out() {
        // A slow motion with a fast ringing on top, sampled finely enough to resolve it.
        let (dt, n, fc) = (1e-4, 10_001, 20.0);
        let slow = sine(1.0, dt, n, 0.2);
        let ringing: Vec<f64> = sine(400.0, dt, n, 0.7).iter().map(|r| 1e-2 * r).collect();
        let signal: Vec<f64> = slow.iter().zip(&ringing).map(|(s, r)| s + r).collect();
        let filtered = lowpass_zero_phase(&signal, dt, fc).unwrap();
        // The odd reflection pins the filtered end to the raw end sample, ringing included.
        assert!((filtered[n - 1] - signal[n - 1]).abs() < 1e-12);
        assert!((filtered[n - 1] - slow[n - 1]).abs() > 0.5 * ringing[n - 1].abs());
        let keep = interior(n, dt, fc).unwrap();
        assert_eq!(
            keep,
            500..n - 500,
            "one cut-off period, 0.05 s, at each end"
        );
        let inside = max_abs_diff(&filtered[keep.clone()], &slow[keep]);
        // 400 Hz is attenuated to 1/(1 + 20⁴) of 1e-2 and the 1 Hz motion by 6e-6; what the
        // ends leave at one cut-off period inside has decayed by e^(−2π/√2) = 1.2e-2.
        let decay = (-2.0 * PI / 2f64.sqrt()).exp();
        assert!(inside < decay * 1e-2 + 1e-5, "{inside:e}");
        let whole = max_abs_diff(&filtered, &slow);
        assert!(whole > 100.0 * inside, "{whole:e} against {inside:e}");

        // Shorter than two cut-off periods: nothing is left to compare.
        let short = interior(801, dt, fc).unwrap_err();
        assert!(matches!(short, FilterError::NoInterior { .. }), "{short:?}");
        assert!(short.to_string().contains("0.08 s"), "{short}");
    }
}
