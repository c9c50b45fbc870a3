//! The energies and checks of a state: kinetic, gravity and strain energy, the material points,
//! the end effector and the residual of the wheels' rolling constraints.

use nalgebra::Vector3;

use super::{GAUSS, Mat3, Model, Vec3};

impl Model {
    /// Kinetic energy from the bodies' and beam points' velocities (any q̇).
    pub fn kinetic_energy(&self, q: &[f64], qd: &[f64]) -> f64 {
        let zeros = vec![0.0; self.layout.n];
        let f = self.frames(q, qd, &zeros);
        let mut t = 0.0;
        for b in &self.bodies {
            let r = &f.r[b.frame];
            let rc = r * b.com;
            let w = f.w[b.frame];
            let v = f.v[b.frame] + w.cross(&rc);
            let iw = r * b.inertia * r.transpose();
            t += 0.5 * b.mass * v.dot(&v) + 0.5 * w.dot(&(iw * w));
        }
        if let Some(fl) = &self.flex {
            let l = self.layout;
            let (e, ed) = (&q[l.q_el..l.n], &qd[l.q_el..l.n]);
            let fr = fl.frame;
            for el in 0..fl.elements {
                for g in 0..GAUSS {
                    let s = &fl.shapes[g];
                    let x = (el as f64 + fl.gauss_xi[g]) * fl.le;
                    let [vv, ww] = fl.field_at(e, el, &s.n);
                    let [vd, wd] = fl.field_at(ed, el, &s.n);
                    let d = f.r[fr] * Vector3::new(x, vv, ww);
                    let v = f.v[fr] + f.w[fr].cross(&d) + (f.r[fr] * Vector3::new(0.0, vd, wd));
                    t += 0.5 * fl.mu * fl.gauss_w[g] * v.dot(&v);
                }
            }
        }
        if let Some(p) = &self.platform {
            t += 0.5 * p.side_spin_inertia * (qd[3] * qd[3] + qd[4] * qd[4]);
        }
        t
    }

    /// Gravitational potential Σ m g z + ∫ μ g z dx.
    pub fn gravity_energy(&self, q: &[f64]) -> f64 {
        let zeros = vec![0.0; self.layout.n];
        let f = self.frames(q, &zeros, &zeros);
        let mut v = 0.0;
        for b in &self.bodies {
            v += b.mass * self.gravity * (f.o[b.frame] + (f.r[b.frame] * b.com))[2];
        }
        if let Some(fl) = &self.flex {
            let e = &q[self.layout.q_el..self.layout.n];
            for el in 0..fl.elements {
                for g in 0..GAUSS {
                    let s = &fl.shapes[g];
                    let x = (el as f64 + fl.gauss_xi[g]) * fl.le;
                    let [vv, ww] = fl.field_at(e, el, &s.n);
                    let z = f.o[fl.frame][2] + (f.r[fl.frame] * Vector3::new(x, vv, ww))[2];
                    v += fl.mu * fl.gauss_w[g] * self.gravity * z;
                }
            }
        }
        v
    }

    /// Strain energy ½ eᵀ K e.
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let Some(fl) = &self.flex else {
            return 0.0;
        };
        let e = &q[self.layout.q_el..self.layout.n];
        let mut u = 0.0;
        for i in 0..fl.ne {
            for j in 0..fl.ne {
                u += e[i] * fl.stiffness[i * fl.ne + j] * e[j];
            }
        }
        0.5 * u
    }

    /// Inertial positions of every mass element (bodies' mass centres, then the beam's Gauss
    /// points) by direct position kinematics, for the tests' velocity differences.
    pub fn material_points(&self, q: &[f64]) -> Vec<(f64, Vec3, Mat3, Mat3)> {
        let zeros = vec![0.0; self.layout.n];
        let f = self.frames(q, &zeros, &zeros);
        let mut out = Vec::new();
        for b in &self.bodies {
            out.push((
                b.mass,
                f.o[b.frame] + (f.r[b.frame] * b.com),
                f.r[b.frame],
                b.inertia,
            ));
        }
        if let Some(fl) = &self.flex {
            let e = &q[self.layout.q_el..self.layout.n];
            for el in 0..fl.elements {
                for g in 0..GAUSS {
                    let s = &fl.shapes[g];
                    let x = (el as f64 + fl.gauss_xi[g]) * fl.le;
                    let [vv, ww] = fl.field_at(e, el, &s.n);
                    let p = f.o[fl.frame] + (f.r[fl.frame] * Vector3::new(x, vv, ww));
                    out.push((fl.mu * fl.gauss_w[g], p, f.r[fl.frame], Mat3::zeros()));
                }
            }
        }
        out
    }

    /// Inertial position of the gripper frame origin (tip of link 3).
    pub fn end_effector(&self, q: &[f64]) -> Vec3 {
        let zeros = vec![0.0; self.layout.n];
        self.frames(q, &zeros, &zeros).o[5]
    }

    /// |A(q) q̇|∞ of the no-sideways-slip and rolling constraints (0 without platform).
    pub fn constraint_residual(&self, q: &[f64], qd: &[f64]) -> f64 {
        let Some(p) = &self.platform else {
            return 0.0;
        };
        let (s, c) = q[2].sin_cos();
        let (b, r) = (p.half_track, p.wheel_radius);
        let lateral = -s * qd[0] + c * qd[1];
        let fwd = c * qd[0] + s * qd[1];
        lateral
            .abs()
            .max((fwd + b * qd[2] - r * qd[3]).abs())
            .max((fwd - b * qd[2] - r * qd[4]).abs())
    }
}
