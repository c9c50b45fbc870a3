//! Gauss–Legendre quadrature on [0, 1].

/// Points and weights of the n-point Gauss–Legendre rule on [0, 1] (n = 1..=5); exact for
/// polynomials of degree 2n − 1.
pub fn gauss01(n: usize) -> (&'static [f64], &'static [f64]) {
    // Nodes/weights on [−1, 1] mapped to [0, 1]: ξ = (1 + t)/2, w = w_t / 2.
    const P1: [f64; 1] = [0.5];
    const W1: [f64; 1] = [1.0];
    const P2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];
    const W2: [f64; 2] = [0.5, 0.5];
    const P3: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
    const W3: [f64; 3] = [
        0.277_777_777_777_777_8,
        0.444_444_444_444_444_4,
        0.277_777_777_777_777_8,
    ];
    const P4: [f64; 4] = [
        0.069_431_844_202_973_71,
        0.330_009_478_207_571_9,
        0.669_990_521_792_428_1,
        0.930_568_155_797_026_3,
    ];
    const W4: [f64; 4] = [
        0.173_927_422_568_726_9,
        0.326_072_577_431_273_1,
        0.326_072_577_431_273_1,
        0.173_927_422_568_726_9,
    ];
    const P5: [f64; 5] = [
        0.046_910_077_030_668,
        0.230_765_344_947_158_5,
        0.5,
        0.769_234_655_052_841_5,
        0.953_089_922_969_332,
    ];
    const W5: [f64; 5] = [
        0.118_463_442_528_094_5,
        0.239_314_335_249_683_2,
        0.284_444_444_444_444_4,
        0.239_314_335_249_683_2,
        0.118_463_442_528_094_5,
    ];
    match n {
        1 => (&P1, &W1),
        2 => (&P2, &W2),
        3 => (&P3, &W3),
        4 => (&P4, &W4),
        _ => (&P5, &W5),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_gauss_rules_integrate_monomials_exactly() {
        for n in 1..=5 {
            let (p, w) = gauss01(n);
            for deg in 0..(2 * n) {
                let q: f64 = p.iter().zip(w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = 1.0 / (deg as f64 + 1.0);
                // Nodes are given to 16–17 significant digits: error at round-off level.
                assert!((q - exact).abs() < 1e-15, "n={n} deg={deg}: {q} vs {exact}");
            }
        }
    }
}
