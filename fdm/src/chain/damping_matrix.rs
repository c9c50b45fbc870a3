//! The data of the implicit damping kick ([`super::implicit`]): the constant damping matrix C
//! on the band (diagonal and two sub-diagonals) and on the full columns of M, the banded
//! saddle system of the deflection block and the scratch of a kick.

// Index loops over band positions read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::schur::{MAX_FULL, MAX_SMALL, SmallLu};
use crate::band_ldl::BandLdl;

/// C and the banded factorization of the implicit kick (module docs).
#[derive(Debug, Clone)]
pub struct ImplicitDamping {
    /// q-index of each band position (the coordinates outside the full columns, in q order)
    pub(super) band: Vec<usize>,
    /// C on the band: diagonal, first and second sub-diagonals (by band position)
    pub(super) c0: Vec<f64>,
    pub(super) c1: Vec<f64>,
    pub(super) c2: Vec<f64>,
    /// C's full columns over q
    pub(super) cf: [Vec<f64>; MAX_FULL],
    /// the saddle system [[D_B + ½τC_BB + ..., Gᵀ], [G, −N⁻¹]] interleaved by station
    pub(super) saddle: BandLdl,
    /// position in the saddle system of each band position's unknown, and of each link's
    /// segment multipliers
    pub(super) at_band: Vec<usize>,
    pub(super) at_segment: [Vec<usize>; 2],
    /// saddle-system scratch: the right-hand sides of a solve by rows
    pub(super) y: Vec<f64>,
    /// Z = A⁻¹ of the full columns of M + ½τC and of U, and A⁻¹r_B (q indexing, zero on F)
    pub(super) z: [Vec<f64>; MAX_SMALL],
    pub(super) zb: Vec<f64>,
    /// the small system of the Schur solve, factored
    pub(super) small: SmallLu,
    /// the τ of the factors above, while they are those of the current state (`None` after
    /// a new state's `build_columns`)
    pub(super) factored_for: Option<f64>,
    /// whether the saddle system of those factors did not factor
    pub(super) failed: bool,
    /// v_{j+1}
    pub(super) vnew: Vec<f64>,
    /// (M + ½τC)⁻¹Gᵀ of a held tip's constraint row
    pub(super) damped_g: Vec<f64>,
}
