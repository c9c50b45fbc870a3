//! The assembled payload-link model: constant band operators whose combinations give the kinetic
//! energy, the forces and the Newton matrix (see the module doc of [`super`] for the equations).

use data::scene::{LinkField, PayloadLink, PrescribedMotion, TorqueLaw};

use crate::element::beam3d::{self, NodeLayout, PHI, Row, U, V, V_SLOPE, W, W_SLOPE};
use crate::element::quadrature::gauss01;
use crate::error::FemError;
use crate::linalg::dot;

/// Square band matrix of half-bandwidth b, rows stored contiguously (entry (i, j) at
/// i·(2b + 1) + j + b − i).
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    pub n: usize,
    pub b: usize,
    pub data: Vec<f64>,
}

impl Band {
    pub fn zeros(n: usize, b: usize) -> Self {
        Band {
            n,
            b,
            data: vec![0.0; n * (2 * b + 1)],
        }
    }

    /// Position of entry (i, j) in `data` (inside the band).
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        self.at(i, j)
    }

    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        debug_assert!(
            i.abs_diff(j) <= self.b,
            "({i}, {j}) outside the band {}",
            self.b
        );
        i * (2 * self.b + 1) + j + self.b - i
    }

    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.at(i, j);
        self.data[k] += v;
    }

    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i.abs_diff(j) > self.b {
            0.0
        } else {
            self.data[self.at(i, j)]
        }
    }

    /// Columns of row i inside the band.
    #[inline]
    pub fn cols(&self, i: usize) -> std::ops::Range<usize> {
        i.saturating_sub(self.b)..(i + self.b + 1).min(self.n)
    }

    /// self += c·aᵀb (the outer product of two rows).
    pub fn add_outer(&mut self, c: f64, a: &Row, b: &Row) {
        for (i, ai) in a.terms() {
            for (j, bj) in b.terms() {
                self.add(i, j, c * ai * bj);
            }
        }
    }

    /// self += c·other (same shape).
    pub fn add_scaled(&mut self, c: f64, other: &Band) {
        for (x, y) in self.data.iter_mut().zip(&other.data) {
            *x += c * y;
        }
    }

    /// y = A x.
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        for i in 0..self.n {
            let mut s = 0.0;
            for j in self.cols(i) {
                s += self.data[self.at(i, j)] * x[j];
            }
            y[i] = s;
        }
    }

    /// y = Aᵀ x.
    pub fn matvec_transpose(&self, x: &[f64], y: &mut [f64]) {
        y[..self.n].iter_mut().for_each(|v| *v = 0.0);
        for i in 0..self.n {
            for j in self.cols(i) {
                y[j] += self.data[self.at(i, j)] * x[i];
            }
        }
    }

    /// xᵀ A y.
    pub fn form(&self, x: &[f64], y: &[f64]) -> f64 {
        let mut s = 0.0;
        for i in 0..self.n {
            let mut r = 0.0;
            for j in self.cols(i) {
                r += self.data[self.at(i, j)] * y[j];
            }
            s += x[i] * r;
        }
        s
    }

    pub fn to_dense(&self) -> faer::Mat<f64> {
        faer::Mat::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }
}

/// How the base angle θ moves.
#[derive(Debug, Clone, PartialEq)]
pub enum Base {
    /// θ is a DOF: I_B θ̈ + … = T_mot(t) − b_m θ̇ − K(θ − θ₀).
    Free {
        torque: Option<TorqueLaw>,
        stiffness: f64,
        set_point: f64,
    },
    /// θ(t) = θ_init + law(t); the needed torque is reported.
    Prescribed(PrescribedMotion),
}

/// Rows of the tip node (and of the payload's centre of mass).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TipRows {
    pub u: Row,
    pub v: Row,
    pub v_slope: Row,
    pub w: Row,
    pub w_slope: Row,
    pub phi: Row,
    /// Payload centre: y_C = v_L + c v′_L, z_C = w_L + c w′_L.
    pub y_c: Row,
    pub z_c: Row,
}

/// The discrete model. With d the field DOFs and θ the base angle,
/// T = ½J(d)θ̇² + θ̇ b(d)·ḋ + ½ḋᵀMḋ, J(d) = J₀ + 2j₁·d + dᵀK_c d, b(d) = b₀ + Gᵀd;
/// V = ½dᵀK_s d + f_g·d + ½K(θ − θ₀)²; Rayleigh ½b_m θ̇² + ½ḋᵀCḋ (C = Σ C_f).
#[derive(Debug, Clone)]
pub struct Model {
    pub layout: NodeLayout,
    pub fields: Vec<LinkField>,
    pub n_el: usize,
    pub h: f64,
    pub length: f64,
    pub offset: f64,
    /// Field DOFs.
    pub n: usize,
    pub m: Band,
    pub ks: Band,
    pub kc: Band,
    pub g: Band,
    pub c: Band,
    /// Kelvin–Voigt operator of each damped field.
    pub c_field: Vec<(LinkField, Band)>,
    /// S = ∫₀ᴸ (N_v′ᵀN_v′ + N_w′ᵀN_w′) dx: the tip's foreshortening s_L = ½dᵀSd.
    pub s: Band,
    pub j0: f64,
    pub j1: Vec<f64>,
    pub b0: Vec<f64>,
    pub fg: Vec<f64>,
    pub has_gravity: bool,
    pub tip: TipRows,
    pub base: Base,
    pub initial_angle: f64,
    pub initial_rate: f64,
    pub motor_friction: f64,
}

impl Model {
    pub fn assemble(link: &PayloadLink, n_el: usize) -> Result<Model, FemError> {
        if link.fields.is_empty() {
            return Err(FemError::unsupported(
                "fem payload link: the rod carries no elastic field",
            ));
        }
        let mut fields = link.fields.clone();
        fields.sort();
        fields.dedup();
        let layout = NodeLayout::new(&fields);
        let n = layout.per_node * n_el;
        let bw = layout.half_bandwidth();
        let len = link.length;
        let h = len / n_el as f64;
        let (rho, area, i2, jp) = (
            link.density,
            link.area(),
            link.second_moment(),
            link.polar_moment(),
        );
        let rho_a = rho * area;
        let g = link.gravity.unwrap_or(0.0);
        let base = match &link.base.prescribed {
            Some(p) => Base::Prescribed(p.clone()),
            None => Base::Free {
                torque: link.base.torque.clone(),
                stiffness: link.base.stiffness.unwrap_or(0.0),
                set_point: link.base.set_point.unwrap_or(link.base.initial_angle),
            },
        };
        let initial_rate = match &link.base.prescribed {
            Some(p) => p.kinematics(0.0).1,
            None => link.base.initial_rate,
        };
        let mut md = Model {
            layout,
            fields: fields.clone(),
            n_el,
            h,
            length: len,
            offset: link.payload.offset,
            n,
            m: Band::zeros(n, bw),
            ks: Band::zeros(n, bw),
            kc: Band::zeros(n, bw),
            g: Band::zeros(n, bw),
            c: Band::zeros(n, bw),
            c_field: Vec::new(),
            s: Band::zeros(n, bw),
            j0: 0.0,
            j1: vec![0.0; n],
            b0: vec![0.0; n],
            fg: vec![0.0; n],
            has_gravity: g != 0.0 && link.has(LinkField::Vertical),
            tip: TipRows::default(),
            base,
            initial_angle: link.base.initial_angle,
            initial_rate,
            motor_friction: link.motor_friction(),
        };
        let kv: Vec<(LinkField, f64)> = fields
            .iter()
            .filter_map(|&f| link.kelvin_voigt_on(f).map(|c| (f, c)))
            .collect();
        let mut c_field: Vec<(LinkField, Band)> =
            kv.iter().map(|&(f, _)| (f, Band::zeros(n, bw))).collect();
        let section_inertia = [
            [rho * jp, 0.0, 0.0],
            [0.0, rho * i2, 0.0],
            [0.0, 0.0, rho * i2],
        ];
        let (ea, ei, gj) = (
            link.axial_stiffness(),
            link.bending_stiffness(),
            link.torsional_stiffness(),
        );
        // 4-point Gauss: exact for every integrand (degree ≤ 6 in ξ).
        let (pts, wts) = gauss01(4);
        for e in 0..n_el {
            for (&xi, &wq) in pts.iter().zip(wts) {
                let x = (e as f64 + xi) * h;
                let wt = wq * h;
                let r = beam3d::rows_at(&md.layout, beam3d::bending_element(), e, h, xi);
                md.add_translation(rho_a * wt, x, &r.u, &r.v, &r.w);
                // Foreshortening: −2ρA∫x s dx = −ρA∫½(L² − x²)(v′² + w′²) dx.
                let cf = -0.5 * rho_a * (len * len - x * x) * wt;
                md.kc.add_outer(cf, &r.dv, &r.dv);
                md.kc.add_outer(cf, &r.dw, &r.dw);
                md.s.add_outer(wt, &r.dv, &r.dv);
                md.s.add_outer(wt, &r.dw, &r.dw);
                let si = section_inertia.map(|row| row.map(|v| v * wt));
                md.add_rotation(&si, &r.dv, &r.dw, &r.phi);
                md.ks.add_outer(ea * wt, &r.du, &r.du);
                md.ks.add_outer(ei * wt, &r.ddv, &r.ddv);
                md.ks.add_outer(ei * wt, &r.ddw, &r.ddw);
                md.ks.add_outer(gj * wt, &r.dphi, &r.dphi);
                for ((f, cv), (_, band)) in kv.iter().zip(c_field.iter_mut()) {
                    match f {
                        LinkField::Axial => band.add_outer(cv * area * wt, &r.du, &r.du),
                        LinkField::Horizontal => band.add_outer(cv * i2 * wt, &r.ddv, &r.ddv),
                        LinkField::Vertical => band.add_outer(cv * i2 * wt, &r.ddw, &r.ddw),
                        LinkField::Torsion => band.add_outer(cv * jp * wt, &r.dphi, &r.dphi),
                    }
                }
                for (i, v) in r.w.terms() {
                    md.fg[i] += g * rho_a * wt * v;
                }
            }
        }
        for (_, band) in &c_field {
            md.c.add_scaled(1.0, band);
        }
        md.c_field = c_field;
        // Payload at the tip node.
        let tip = n_el;
        let c = link.payload.offset;
        let unit = |slot| Row::unit(md.layout.dof(tip, slot));
        let mut t = TipRows {
            u: unit(U),
            v: unit(V),
            v_slope: unit(V_SLOPE),
            w: unit(W),
            w_slope: unit(W_SLOPE),
            phi: unit(PHI),
            ..Default::default()
        };
        t.y_c = t.v.plus(c, &t.v_slope);
        t.z_c = t.w.plus(c, &t.w_slope);
        md.tip = t;
        let mp = link.payload.mass;
        let a = len + c;
        md.add_translation(mp, a, &t.u, &t.y_c, &t.z_c);
        // −2a S_C, S_C = s_L + ½c(v′_L² + w′_L²).
        let s = md.s.clone();
        md.kc.add_scaled(-mp * a, &s);
        md.kc.add_outer(-mp * a * c, &t.v_slope, &t.v_slope);
        md.kc.add_outer(-mp * a * c, &t.w_slope, &t.w_slope);
        md.add_rotation(&link.payload.inertia, &t.v_slope, &t.w_slope, &t.phi);
        for (i, v) in t.z_c.terms() {
            md.fg[i] += g * mp * v;
        }
        Ok(md)
    }

    /// A point of mass `mass` at reference axial coordinate `a` whose displacements are
    /// (u, y, z) (its foreshortening term is added by the caller):
    /// ½m|ṙ + θ̇e_z×r|² → ½m[u̇² + ẏ² + ż² + 2θ̇(uẏ − u̇y) + 2θ̇aẏ + θ̇²(a² + 2au + u² + y²)].
    fn add_translation(&mut self, mass: f64, a: f64, u: &Row, y: &Row, z: &Row) {
        for r in [u, y, z] {
            self.m.add_outer(mass, r, r);
        }
        self.j0 += mass * a * a;
        for (i, v) in u.terms() {
            self.j1[i] += mass * a * v;
        }
        self.kc.add_outer(mass, u, u);
        self.kc.add_outer(mass, y, y);
        for (i, v) in y.terms() {
            self.b0[i] += mass * a * v;
        }
        self.g.add_outer(mass, u, y);
        self.g.add_outer(-mass, y, u);
    }

    /// A rigid section or body of inertia matrix I (section axes) whose orientation is
    /// R = R_t(0, −γ, α) R_x(φ) (α = v′, γ = w′): with ω̃ = RᵀΩ = θ̇a + r,
    /// a = (γ, φ − ½αγ, 1 − ½(γ² + φ²)), r = (φ̇ + ½(γα̇ − αγ̇), −γ̇ + φα̇, α̇ + φγ̇), adds ½ω̃ᵀIω̃
    /// truncated at second order in the fields.
    fn add_rotation(&mut self, inertia: &[[f64; 3]; 3], alpha: &Row, gamma: &Row, phi: &Row) {
        let r1 = [*phi, gamma.scaled(-1.0), *alpha];
        let a1 = [*gamma, *phi, Row::default()];
        let (i5, i6, i3) = (inertia[0][2], inertia[1][2], inertia[2][2]);
        for p in 0..3 {
            for q in 0..3 {
                let ipq = inertia[p][q];
                if ipq == 0.0 {
                    continue;
                }
                self.m.add_outer(ipq, &r1[p], &r1[q]);
                self.kc.add_outer(ipq, &a1[p], &a1[q]);
                self.g.add_outer(ipq, &a1[p], &r1[q]);
            }
        }
        // θ̇² terms: I₃ + 2(I₅γ + I₆φ) + 2c₃·a₂.
        self.j0 += i3;
        for (i, v) in gamma.terms() {
            self.j1[i] += i5 * v;
        }
        for (i, v) in phi.terms() {
            self.j1[i] += i6 * v;
        }
        self.kc.add_outer(-0.5 * i6, alpha, gamma);
        self.kc.add_outer(-0.5 * i6, gamma, alpha);
        self.kc.add_outer(-i3, gamma, gamma);
        self.kc.add_outer(-i3, phi, phi);
        // θ̇ terms: c₃·r₁ (constant) and c₃·r₂ + a₁ᵀI r₁ (bilinear).
        let c3 = [i5, i6, i3];
        for p in 0..3 {
            for (i, v) in r1[p].terms() {
                self.b0[i] += c3[p] * v;
            }
        }
        self.g.add_outer(0.5 * i5, gamma, alpha);
        self.g.add_outer(-0.5 * i5, alpha, gamma);
        self.g.add_outer(i6, phi, alpha);
        self.g.add_outer(i3, phi, gamma);
    }

    /// Whether the base angle is a DOF.
    pub fn free_base(&self) -> bool {
        matches!(self.base, Base::Free { .. })
    }

    /// (θ, θ̇, θ̈) of a prescribed base at time t.
    pub fn prescribed(&self, t: f64) -> Option<(f64, f64, f64)> {
        match &self.base {
            Base::Prescribed(p) => {
                let (th, rate, acc) = p.kinematics(t);
                Some((self.initial_angle + th, rate, acc))
            }
            Base::Free { .. } => None,
        }
    }

    /// Motor torque law T_mot(t) of a free base.
    pub fn motor_torque(&self, t: f64) -> f64 {
        match &self.base {
            Base::Free {
                torque: Some(law), ..
            } => law.torque(t),
            _ => 0.0,
        }
    }

    pub fn spring(&self) -> (f64, f64) {
        match self.base {
            Base::Free {
                stiffness,
                set_point,
                ..
            } => (stiffness, set_point),
            Base::Prescribed(_) => (0.0, 0.0),
        }
    }

    /// J(d) = J₀ + 2j₁·d + dᵀK_c d.
    pub fn polar(&self, d: &[f64]) -> f64 {
        self.j0 + 2.0 * dot(&self.j1, d) + self.kc.form(d, d)
    }

    /// T = ½J(d)θ̇² + θ̇ b(d)·ḋ + ½ḋᵀMḋ.
    pub fn kinetic(&self, d: &[f64], rate: f64, dd: &[f64]) -> f64 {
        0.5 * self.polar(d) * rate * rate
            + rate * (dot(&self.b0, dd) + self.g.form(d, dd))
            + 0.5 * self.m.form(dd, dd)
    }

    pub fn strain(&self, d: &[f64]) -> f64 {
        0.5 * self.ks.form(d, d)
    }

    pub fn gravity(&self, d: &[f64]) -> f64 {
        dot(&self.fg, d)
    }

    pub fn joint_spring(&self, theta: f64) -> f64 {
        let (k, th0) = self.spring();
        0.5 * k * (theta - th0) * (theta - th0)
    }

    /// Payload centre of mass in the turning frame: (L + c + u_L − s_L − ½c(v′_L² + w′_L²),
    /// v_L + c v′_L, w_L + c w′_L).
    pub fn payload_position(&self, d: &[f64]) -> [f64; 3] {
        let t = &self.tip;
        let (a, b) = (t.v_slope.dot(d), t.w_slope.dot(d));
        let x = self.length + self.offset + t.u.dot(d)
            - 0.5 * self.s.form(d, d)
            - 0.5 * self.offset * (a * a + b * b);
        [x, t.y_c.dot(d), t.z_c.dot(d)]
    }

    /// Value of a field at x (slot U, V, W or PHI).
    pub fn field_at(&self, d: &[f64], slot: usize, x: f64) -> f64 {
        let e = ((x / self.h) as usize).min(self.n_el - 1);
        let xi = (x / self.h - e as f64).clamp(0.0, 1.0);
        let r = beam3d::rows_at(&self.layout, beam3d::bending_element(), e, self.h, xi);
        match slot {
            U => r.u.dot(d),
            V => r.v.dot(d),
            W => r.w.dot(d),
            _ => r.phi.dot(d),
        }
    }
}
