//! Checks of the methods' payloads, one function per payload field (named as the field), called
//! by [`super::Method::from_data`]: `data`'s `Option<T>` (None: the default) to a checked `T`.

use crate::error::FdmError;

/// Default Robert–Asselin filter coefficient ν (Asselin 1972 used 0.01–0.25; 0.01 keeps the
/// accuracy cost small while damping the computational mode by ≈ 4ν per step).
pub const DEFAULT_ASSELIN_NU: f64 = 0.01;

/// Robert–Asselin ν ([`DEFAULT_ASSELIN_NU`] when not given), in (0, 0.5).
pub(crate) fn nu(nu: Option<f64>) -> Result<f64, FdmError> {
    let nu = nu.unwrap_or(DEFAULT_ASSELIN_NU);
    if !(nu > 0.0 && nu < 0.5) {
        return Err(FdmError::invalid(
            "time.method",
            format!("Robert–Asselin ν = {nu} must lie in (0, 0.5)"),
        ));
    }
    Ok(nu)
}
