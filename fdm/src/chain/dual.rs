//! Forward-mode dual numbers a + b ε (ε² = 0): the exact directional derivative (∂(Bq̇)/∂q)·q̇
//! of the lumped points' velocities in one O(n) pass ([`super::kinetic`]), so that the inertia
//! forces need no hand-derived Ṁ.
//!
//! [`Number`] lets one formula run on either `Dual` (value and directional derivative) or `f64`
//! (value only: T, the momenta and the columns of M). The real part of every `Dual` operation is the `f64`
//! operation, so both give the same value bits.

use std::ops::{Add, Mul, Neg, Sub};

/// The arithmetic the velocity formula needs: `f64` (values) or [`Dual`] (values and one
/// directional derivative).
pub trait Number:
    Copy
    + Default
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<f64, Output = Self>
    + Add<f64, Output = Self>
    + Neg<Output = Self>
{
    /// The value `re` with derivative `du` along the seeded direction (`f64` drops `du`).
    fn seed(re: f64, du: f64) -> Self;
    /// A value with zero derivative.
    fn constant(re: f64) -> Self;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    /// The value part.
    fn value(self) -> f64;
}

impl Number for f64 {
    fn seed(re: f64, _du: f64) -> Self {
        re
    }
    fn constant(re: f64) -> Self {
        re
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn value(self) -> f64 {
        self
    }
}

impl Number for Dual {
    fn seed(re: f64, du: f64) -> Self {
        Dual::new(re, du)
    }
    fn constant(re: f64) -> Self {
        Dual::constant(re)
    }
    fn sin(self) -> Self {
        Dual::sin(self)
    }
    fn cos(self) -> Self {
        Dual::cos(self)
    }
    fn value(self) -> f64 {
        self.re
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dual {
    pub re: f64,
    pub du: f64,
}

impl Dual {
    pub const fn new(re: f64, du: f64) -> Self {
        Dual { re, du }
    }
    pub const fn constant(re: f64) -> Self {
        Dual { re, du: 0.0 }
    }
    pub fn sin(self) -> Self {
        Dual::new(self.re.sin(), self.du * self.re.cos())
    }
    pub fn cos(self) -> Self {
        Dual::new(self.re.cos(), -self.du * self.re.sin())
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual::new(self.re + o.re, self.du + o.du)
    }
}
impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual::new(self.re - o.re, self.du - o.du)
    }
}
impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual::new(self.re * o.re, self.re * o.du + self.du * o.re)
    }
}
impl Mul<f64> for Dual {
    type Output = Dual;
    fn mul(self, o: f64) -> Dual {
        Dual::new(self.re * o, self.du * o)
    }
}
impl Mul<Dual> for f64 {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        o * self
    }
}
impl Add<f64> for Dual {
    type Output = Dual;
    fn add(self, o: f64) -> Dual {
        Dual::new(self.re + o, self.du)
    }
}
impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        Dual::new(-self.re, -self.du)
    }
}
