//! Forward-mode dual numbers a + b ε (ε² = 0): the exact directional derivative (∂p/∂q)·q̇ of the
//! generalized momenta in one O(n) pass, so that d/dt ∂T/∂q̇ needs no hand-derived Ṁ.

use std::ops::{Add, Mul, Neg, Sub};

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
