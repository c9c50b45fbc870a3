//! Element library: one-dimensional beam elements behind one [`Element`] trait, each testable
//! alone, and the element registry ([`for_link`]).
//!
//! * [`contract`] — the element contract: the [`Element`] trait, the padded local arrays, and one
//!   element kind on a mesh ([`MeshElement`]) with its shape functions tabulated at the
//!   quadrature points ([`Quadrature`]) and the averaged membrane strain;
//! * [`quadrature`] — Gauss–Legendre rules on an interval;
//! * [`hermite`] — Hermite-cubic transverse interpolation (v, v′ at each node);
//! * [`euler_bernoulli`] — [`euler_bernoulli::HermiteCubic`]: consistent mass, bending stiffness,
//!   geometric stiffness, von Kármán internal force and tangent for the extensible beam (linear
//!   axial interpolation);
//! * [`quintic`] — [`quintic::HermiteQuintic`]: hierarchical Hermite-quintic Euler–Bernoulli
//!   element (cubic + two C¹ bubbles, O(h⁸) frequencies);
//! * [`timoshenko`] — [`timoshenko::Timoshenko`]: cubic v and quadratic θ (interior DOFs kept
//!   global), free of shear locking, O(h⁴) frequencies;
//! * [`beam3d`] — the 3-D beam element (u, v, w, φ) of the payload link, its bending planes
//!   interpolated by a registry element through [`Element::shapes`].
//!
//! The elements use only [`contract`] (and the interpolation and quadrature modules); this file
//! is the registry, which names them.
//!
//! A new Euler–Bernoulli element is one new file implementing [`Element`] and its line in the
//! registry at the end of this file (which declares its module and maps the settings' choice to
//! it), with its row in `data`'s element table ([`data::FemElement`]).

pub mod beam3d;
pub mod contract;
pub mod hermite;
pub mod quadrature;
pub mod timoshenko;

use data::FemElement;
use data::scene::Link;

use crate::error::FemError;

pub use contract::{
    Element, ElementDofs, InteriorDof, InteriorField, Local, MAX_GAUSS, MAX_SUB_GAUSS, MAXE, Mat4,
    MeshElement, NONE, Quadrature, Row, Shapes, bar_shapes, linear_internal_force,
    linear_strain_energy, linear_tangent, pad,
};

// The local arrays are padded to the largest element of the registry.
const _: () = assert!(MAXE == timoshenko::NDOF && quintic::NDOF <= MAXE);

/// The element registry: the element a link uses under the `discretization.element` choice.
/// The choice names an Euler–Bernoulli element; a `shear` link always uses the Timoshenko
/// element, and asking for another element there is refused rather than silently ignored.
pub fn for_link(link: &Link, choice: Option<FemElement>) -> Result<&'static dyn Element, FemError> {
    match (link.shear, choice.unwrap_or_default()) {
        (false, choice) => Ok(euler_bernoulli_element(choice)),
        (true, FemElement::HermiteCubic) => Ok(&timoshenko::Timoshenko),
        (true, other) => Err(FemError::InvalidSettings {
            field: "discretization.element".into(),
            message: format!(
                "`{}` is an Euler–Bernoulli element; a `shear` link uses the Timoshenko \
                 (cubic v, quadratic θ) element: omit the field or use `hermite-cubic`",
                other.name()
            ),
        }),
    }
}

/// The Hermite-cubic element of the registry: the beams of the families built on cubics only
/// (the 3-D link, the mobile manipulator's flexible link, the rocket) take their shapes from it.
pub fn hermite_cubic() -> &'static dyn Element {
    euler_bernoulli_element(FemElement::HermiteCubic)
}

/// The registry of the Euler–Bernoulli elements: one line per element, `Choice =>
/// module::Type`, declaring the element's module and mapping the settings' `FemElement::Choice`
/// to its `Type`.
macro_rules! registry {
    ($($choice:ident => $module:ident :: $element:ident,)*) => {
        $(pub mod $module;)*

        /// The Euler–Bernoulli element of a `discretization.element` choice.
        pub(crate) fn euler_bernoulli_element(choice: FemElement) -> &'static dyn Element {
            match choice {
                $(FemElement::$choice => &$module::$element,)*
            }
        }
    };
}

registry! {
    HermiteCubic => euler_bernoulli::HermiteCubic,
    HermiteQuintic => quintic::HermiteQuintic,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::quadrature::gauss01;

    /// Every element of the registry and the Timoshenko element.
    fn every_element() -> Vec<&'static dyn Element> {
        FemElement::ALL
            .iter()
            .map(|&c| euler_bernoulli_element(c))
            .chain([&timoshenko::Timoshenko as &dyn Element])
            .collect()
    }

    /// ∫ s sᵀ dx over an element of length h by the highest Gauss rule, s = `shape` of the
    /// element's shapes.
    fn gauss_gram(element: &dyn Element, h: f64, shape: impl Fn(&Shapes) -> Row) -> Local {
        let (pts, wts) = gauss01(MAX_GAUSS);
        let ne = element.local_dofs();
        let mut integrated = [[0.0; MAXE]; MAXE];
        for (&xi, &w) in pts.iter().zip(wts) {
            let s = shape(&element.shapes(xi, h));
            for a in 0..ne {
                for b in 0..ne {
                    integrated[a][b] += w * h * s[a] * s[b];
                }
            }
        }
        integrated
    }

    /// Asserts `got` = `want` entry by entry on the element's DOFs, to 1e-12 of `want`'s largest
    /// entry.
    fn assert_local_eq(element: &dyn Element, what: &str, got: &Local, want: &Local) {
        let ne = element.local_dofs();
        let scale = want.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for a in 0..ne {
            for b in 0..ne {
                assert!(
                    (got[a][b] - want[a][b]).abs() <= 1e-12 * scale,
                    "{} {what}[{a}][{b}]: {:.6e} against {:.6e}",
                    element.name(),
                    got[a][b],
                    want[a][b]
                );
            }
        }
    }

    #[test]
    fn elem_slope_gram_is_the_integral_of_the_slope_shapes() {
        // Quadrature::slope_gram (the foreshortening's ∫v′² = dᵀG d over an element, summed
        // over the sub-interval points) against ∫N′N′ᵀ by the highest Gauss rule and, where the
        // element has one, its geometric stiffness at unit axial force.
        let h = 0.37;
        for element in every_element() {
            let gram = Quadrature::new(element, h).slope_gram;
            assert_local_eq(element, "G", &gram, &gauss_gram(element, h, |s| s.dn));
            if let Some(kg) = element.geometric_stiffness(h, &|_| 1.0) {
                assert_local_eq(element, "G (K_g)", &gram, &kg);
            }
        }
    }

    #[test]
    fn elem_curvature_shapes_integrate_to_every_elements_bending_stiffness() {
        // K_bending = ∫EI B′B′ dx: the curvature shapes of `Element::shapes` (which the 3-D
        // element's bending planes use) against each element's own stiffness at κGA = 0.
        let (ei, h) = (2.5e3, 0.37);
        for element in every_element() {
            let k = element.stiffness(ei, 0.0, h);
            let mut integrated = gauss_gram(element, h, |s| s.db);
            integrated.iter_mut().flatten().for_each(|x| *x *= ei);
            assert_local_eq(element, "∫EI B′B′ (K)", &integrated, &k);
        }
    }
}
