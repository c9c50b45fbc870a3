//! The FEM backend's reading of [`data::Settings`].

use crate::error::FemError;

/// Elements per link when `discretization.elements` is absent.
pub const DEFAULT_ELEMENTS: usize = 16;
/// Largest accepted element count per link (keeps dense modal analysis and memory bounded).
pub const MAX_ELEMENTS: usize = 20_000;

/// The [`data::Method`]s this backend implements.
pub const METHODS: [data::Method; 4] = [
    data::Method::EnergyMidpoint,
    data::Method::GeneralizedAlpha,
    data::Method::CentralDifference,
    data::Method::ImplicitMidpoint,
];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Energy-consistent implicit midpoint (discrete-gradient) scheme for free-joint chains:
    /// the ledger closes to the Newton tolerance (see [`crate::method::energy_midpoint`]).
    EnergyMidpoint,
    /// Implicit generalized-α (Chung–Hulbert, Arnold–Brüls form) with Newton iterations.
    GeneralizedAlpha,
    /// Explicit central difference (velocity-Verlet form) under its stability bound.
    CentralDifference,
    /// Implicit midpoint rule (one-stage Gauss) with Newton iterations.
    ImplicitMidpoint,
}

/// Elements per link of a planar chain or 3-D link: `discretization.elements`, [`DEFAULT_ELEMENTS`]
/// when unset.
pub fn elements(disc: &data::Discretization) -> Result<usize, FemError> {
    elements_or(disc, DEFAULT_ELEMENTS)
}

/// Elements per link: `discretization.elements`, `default` (a family's own default) when unset,
/// checked against 1..=[`MAX_ELEMENTS`].
pub fn elements_or(disc: &data::Discretization, default: usize) -> Result<usize, FemError> {
    let n = disc.elements.unwrap_or(default);
    if n == 0 || n > MAX_ELEMENTS {
        return Err(FemError::InvalidSettings {
            field: "discretization.elements".into(),
            message: format!("{n} elements per link; accepted 1..={MAX_ELEMENTS}"),
        });
    }
    Ok(n)
}

/// The method named in `time.method`, or `default` when none is given.
pub fn method(time: &data::TimeStepping, default: Method) -> Result<Method, FemError> {
    match time.method {
        None => Ok(default),
        Some(data::Method::EnergyMidpoint) => Ok(Method::EnergyMidpoint),
        Some(data::Method::GeneralizedAlpha) => Ok(Method::GeneralizedAlpha),
        Some(data::Method::CentralDifference) => Ok(Method::CentralDifference),
        Some(data::Method::ImplicitMidpoint) => Ok(Method::ImplicitMidpoint),
        Some(other) => Err(FemError::InvalidSettings {
            field: "time.method".into(),
            message: format!(
                "the fem backend does not implement `{other}`; it offers {}",
                METHODS.map(|m| m.name()).join(", ")
            ),
        }),
    }
}

/// Checks a user-given positive finite number.
pub fn positive(field: &str, v: Option<f64>) -> Result<Option<f64>, FemError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(FemError::InvalidSettings {
            field: field.into(),
            message: format!("must be positive and finite, got {x}"),
        }),
        other => Ok(other),
    }
}
