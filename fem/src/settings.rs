//! The FEM backend's reading of its settings ([`data::FemSettings`]).

use crate::error::FemError;

/// Elements per link when `discretization.elements` is absent.
pub const DEFAULT_ELEMENTS: usize = 16;
/// Largest accepted element count per link (keeps dense modal analysis and memory bounded).
pub const MAX_ELEMENTS: usize = 20_000;

/// The FEM backend's time-integration methods ([`data::FemMethod`]).
pub use data::FemMethod as Method;

/// The spellings of `methods` for a message: `` `a`, `b` or `c` `` with `conjunction` "or".
pub fn spelled_list(methods: impl IntoIterator<Item = Method>, conjunction: &str) -> String {
    let names: Vec<String> = methods.into_iter().map(|m| format!("`{m}`")).collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} {conjunction} {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// Elements per link of a planar chain or 3-D link: `elements`, [`DEFAULT_ELEMENTS`] when unset.
pub fn elements(settings: &data::FemSettings) -> Result<usize, FemError> {
    elements_or(settings, DEFAULT_ELEMENTS)
}

/// Elements per link of a family whose beams are Hermite cubics only (`family` and `beam` name
/// them in the message): as [`elements_or`], but `discretization.element = "hermite-quintic"` is
/// refused rather than run as cubics under that name.
pub fn cubic_elements_or(
    settings: &data::FemSettings,
    default: usize,
    family: &str,
    beam: &str,
) -> Result<usize, FemError> {
    if settings.element == Some(data::FemElement::HermiteQuintic) {
        return Err(FemError::unsupported(format!(
            "fem {family}: the hermite-quintic element ({beam} uses Hermite cubics)"
        )));
    }
    elements_or(settings, default)
}

/// Elements per link: `elements`, `default` (a family's own default) when unset, checked
/// against 1..=[`MAX_ELEMENTS`].
pub fn elements_or(settings: &data::FemSettings, default: usize) -> Result<usize, FemError> {
    let n = settings.elements.unwrap_or(default);
    if n == 0 || n > MAX_ELEMENTS {
        return Err(FemError::InvalidSettings {
            field: "discretization.elements".into(),
            message: format!("{n} elements per link; accepted 1..={MAX_ELEMENTS}"),
        });
    }
    Ok(n)
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
