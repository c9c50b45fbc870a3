//! Double-double arithmetic (an unevaluated sum `hi + lo` of two f64, ≈ 106-bit significand):
//! Dekker 1971, Knuth TAOCP vol. 2 (TwoSum), with the fused multiply-add TwoProd.
//!
//! Only what the Frobenius power series of the rotating beam needs: the sums there reach
//! e^{β} while the frequency determinant is O(e^{β}) *after* a cancellation of O(e^{2β}) terms,
//! so plain f64 would lose ~β/ln 10 digits for mode shapes with large βL.

use std::ops::{Add, Mul, Neg, Sub};

/// `hi + lo` with |lo| ≤ ulp(hi)/2.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DD {
    pub hi: f64,
    pub lo: f64,
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let err = (a - (s - bb)) + (b - bb);
    (s, err)
}

#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl DD {
    pub const ZERO: DD = DD { hi: 0.0, lo: 0.0 };

    pub fn from_f64(x: f64) -> DD {
        DD { hi: x, lo: 0.0 }
    }

    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    pub fn abs(self) -> DD {
        if self.hi < 0.0 { -self } else { self }
    }

    /// Product with an f64.
    pub fn mul_f64(self, b: f64) -> DD {
        let (p, e) = two_prod(self.hi, b);
        let e = self.lo.mul_add(b, e);
        let (hi, lo) = quick_two_sum(p, e);
        DD { hi, lo }
    }

    /// Quotient by an f64.
    pub fn div_f64(self, b: f64) -> DD {
        let q1 = self.hi / b;
        // remainder r = self − q1 b, computed exactly enough with TwoProd
        let (p, e) = two_prod(q1, b);
        let (s, t) = two_sum(self.hi, -p);
        let t = t - e + self.lo;
        let q2 = (s + t) / b;
        let (hi, lo) = quick_two_sum(q1, q2);
        DD { hi, lo }
    }
}

impl Add for DD {
    type Output = DD;
    fn add(self, b: DD) -> DD {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        DD { hi, lo }
    }
}

impl Neg for DD {
    type Output = DD;
    fn neg(self) -> DD {
        DD {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for DD {
    type Output = DD;
    fn sub(self, b: DD) -> DD {
        self + (-b)
    }
}

impl Mul for DD {
    type Output = DD;
    fn mul(self, b: DD) -> DD {
        let (p, e) = two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = quick_two_sum(p, e);
        DD { hi, lo }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ana_dd_resolves_cancellation_below_f64() {
        // (1 + 2^-60) − 1 is invisible in f64 but exact in double-double.
        let tiny = 2f64.powi(-60);
        let a = DD::from_f64(1.0) + DD::from_f64(tiny);
        let d = a - DD::from_f64(1.0);
        assert_eq!(d.to_f64(), tiny);
        // (1/3)·3 − 1 to ~1e-32.
        let third = DD::from_f64(1.0).div_f64(3.0);
        let r = third.mul_f64(3.0) - DD::from_f64(1.0);
        assert!(r.to_f64().abs() < 1e-31, "{r:?}");
        let sq = third * third - DD::from_f64(1.0).div_f64(9.0);
        assert!(sq.to_f64().abs() < 1e-31, "{sq:?}");
    }
}
