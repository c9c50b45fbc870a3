//! Gauss–Legendre quadrature (nodes by Newton iteration on Pₙ) and composite rules on [0, L].

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1].
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Tricomi's initial guess, then Newton on Pₙ.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre_and_derivative(n, z);
            dp = d;
            let dz = p / d;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_and_derivative(n, z);
        dp = if d.is_finite() { d } else { dp };
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// Nodes and weights of the n-point Gauss–Legendre rule on [0, 1] (ascending nodes).
pub fn gauss_legendre_unit(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut w) = gauss_legendre(n);
    for (xi, wi) in x.iter_mut().zip(&mut w) {
        *xi = 0.5 * (1.0 + *xi);
        *wi *= 0.5;
    }
    (x, w)
}

fn legendre_and_derivative(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (z * p1 - p0) / (z * z - 1.0);
    (p1, d)
}

/// A composite Gauss rule on [0, length]: `panels` equal panels of `points` nodes each.
#[derive(Debug, Clone)]
pub struct Quadrature {
    pub x: Vec<f64>,
    pub w: Vec<f64>,
}

impl Quadrature {
    pub fn composite(length: f64, panels: usize, points: usize) -> Self {
        let (gx, gw) = gauss_legendre(points);
        let h = length / panels as f64;
        let mut x = Vec::with_capacity(panels * points);
        let mut w = Vec::with_capacity(panels * points);
        for p in 0..panels {
            let a = p as f64 * h;
            for (xi, wi) in gx.iter().zip(&gw) {
                x.push(a + 0.5 * h * (xi + 1.0));
                w.push(0.5 * h * wi);
            }
        }
        Quadrature { x, w }
    }

    /// A rule fine enough for products of two shape functions of wavenumber up to `beta_max`/L
    /// (and their derivatives): at least ~4 panels of 10 points per wavelength, and at least 16
    /// panels, so that the quadrature error stays below ~1e-13 relative.
    pub fn for_wavenumber(length: f64, beta_max: f64) -> Self {
        let wavelengths = beta_max / (2.0 * std::f64::consts::PI);
        let panels = ((4.0 * wavelengths).ceil() as usize).max(16);
        Self::composite(length, panels, 10)
    }

    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> f64 {
        self.x.iter().zip(&self.w).map(|(x, w)| w * f(*x)).sum()
    }
}
