//! The data of the implicit damping kick ([`super::implicit`]): the constant damping matrix C
//! on the band (diagonal and two sub-diagonals) and on the full columns of M, the banded
//! saddle system of the deflection block and the scratch of a kick.

// Index loops over band positions read like the formulas.
#![allow(clippy::needless_range_loop)]

use std::ops::Range;

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
    /// the factors of the saddle system [[D_B + ½τC_BB + ..., Gᵀ], [G, −N⁻¹]] interleaved
    /// by station
    pub(super) saddle: BandLdl,
    /// the saddle system as assembled: its entries that do not follow the state (all but
    /// G's) at the step `constant_for`, and G's of the last assembly (the factor reads it in
    /// place of a copy)
    pub(super) assembled: BandLdl,
    pub(super) constant_for: Option<f64>,
    /// per link, the storage positions in `assembled` of G's entries g_seg (segments
    /// 0…r − 2) and −g_seg (segments 1…r − 1)
    pub(super) g_plus: [Vec<usize>; 2],
    pub(super) g_minus: [Vec<usize>; 2],
    /// position in the saddle system of each band position's unknown, and of each link's
    /// segment multipliers
    pub(super) at_band: Vec<usize>,
    pub(super) at_segment: [Vec<usize>; 2],
    /// each link's block of the saddle system and of the kick's solves
    pub(super) blocks: [KickBlock; 2],
    /// the small system of the Schur solve as formed (the kernel's bench reads it) and
    /// factored
    pub(super) system: [[f64; MAX_SMALL]; MAX_SMALL],
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

/// Largest number of right-hand sides of a block's solve: the small system's columns and the
/// kick's right-hand side.
pub const MAX_SOLVED: usize = MAX_SMALL + 1;

/// One link's diagonal block of the saddle system (the links' blocks do not couple) and its
/// part of the kick's solves: the columns of [A_BF U] that are not zero on the link (the other
/// link's U column, and a constant full column without entries there, are left out: their
/// A⁻¹ is zero on it) and the right-hand side, solved together.
#[derive(Debug, Clone)]
pub struct KickBlock {
    /// the block's rows of the saddle system
    pub(super) rows: Range<usize>,
    /// the link's band positions
    pub(super) band: Range<usize>,
    /// the small system's columns solved on the block, ascending, then the right-hand side:
    /// `m` in all
    pub(super) cols: [usize; MAX_SOLVED],
    pub(super) m: usize,
    /// the right-hand sides of the block's band rows (band row × m) and the solution of the
    /// last factoring solve by saddle rows (saddle row × m)
    pub(super) rhs: Vec<f64>,
    pub(super) sol: Vec<f64>,
    /// a later right-hand side's solution (one per saddle row)
    pub(super) one: Vec<f64>,
}
