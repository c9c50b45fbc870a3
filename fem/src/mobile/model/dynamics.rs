//! The reduced equations of motion in the speeds ν (Kane's form, parent module docs): the mass
//! matrix M̄(q) and the force M̄ν̇ + b summed over the mass elements, and the applied inputs.

use nalgebra::Vector3;

use super::{GAUSS, Mat3, Model, Partials, Vec3};

impl Model {
    /// Reduced mass matrix M̄(q) (m × m, row-major into `mass`) and the reduced generalized
    /// inertial, gravity and elastic forces at (q, ν, ν̇) into `force` (M̄ ν̇ + b).
    pub fn evaluate(
        &self,
        q: &[f64],
        nu: &[f64],
        nudot: &[f64],
        ws: &mut Workspace,
        mass: Option<&mut [f64]>,
        force: &mut [f64],
    ) {
        let l = self.layout;
        let (n, m) = (l.n, l.m);
        self.velocities(q, nu, &mut ws.qd, &mut ws.sdn);
        // q̈ = S ν̇ + Ṡ ν.
        self.velocities(q, nudot, &mut ws.qdd, &mut ws.scratch);
        for i in 0..n {
            ws.qdd[i] += ws.sdn[i];
        }
        let f = self.frames(q, &ws.qd, &ws.qdd);
        force[..m].fill(0.0);
        let mut mass = mass;
        if let Some(mm) = mass.as_deref_mut() {
            mm[..m * m].fill(0.0);
        }
        let gvec = Vector3::new(0.0, 0.0, self.gravity);
        let mut jp = Partials::default();
        for b in &self.bodies {
            let r = &f.r[b.frame];
            let rc = r * b.com;
            let p = f.o[b.frame] + rc;
            let (w, al) = (f.w[b.frame], f.al[b.frame]);
            let acc = f.a[b.frame] + al.cross(&rc) + w.cross(&w.cross(&rc));
            let iw = r * b.inertia * r.transpose();
            let lin = b.mass * (acc + gvec);
            let ang = iw * al + w.cross(&(iw * w));
            self.frame_partials(&f, q, b.frame, p, &mut jp);
            accumulate(&jp, b.mass, &iw, lin, ang, m, force, mass.as_deref_mut());
        }
        if let Some(fl) = &self.flex {
            let fr = fl.frame;
            let e = &q[l.q_el..l.q_el + fl.ne];
            let ed = &ws.qd[l.q_el..l.q_el + fl.ne];
            let edd = &ws.qdd[l.q_el..l.q_el + fl.ne];
            let zero3 = Mat3::zeros();
            for el in 0..fl.elements {
                for g in 0..GAUSS {
                    let s = &fl.shapes[g];
                    let x = (el as f64 + fl.gauss_xi[g]) * fl.le;
                    let [vv, ww] = fl.field_at(e, el, &s.n);
                    let [vd, wd] = fl.field_at(ed, el, &s.n);
                    let [vdd, wdd] = fl.field_at(edd, el, &s.n);
                    let [p, _, acc] = f.carry(
                        fr,
                        [
                            Vector3::new(x, vv, ww),
                            Vector3::new(0.0, vd, wd),
                            Vector3::new(0.0, vdd, wdd),
                        ],
                    );
                    let dm = fl.mu * fl.gauss_w[g];
                    let lin = dm * (acc + gvec);
                    self.beam_partials(&f, q, fl, el, s, p, &mut jp);
                    accumulate(
                        &jp,
                        dm,
                        &zero3,
                        lin,
                        Vec3::zeros(),
                        m,
                        force,
                        mass.as_deref_mut(),
                    );
                }
            }
            for i in 0..fl.ne {
                let row = &fl.stiffness[i * fl.ne..(i + 1) * fl.ne];
                force[l.nu_el + i] += crate::linalg::dot(row, e);
            }
        }
        if let Some(p) = &self.platform {
            for s in 0..2 {
                force[s] += p.side_spin_inertia * nudot[s];
                if let Some(mm) = mass.as_deref_mut() {
                    mm[s * m + s] += p.side_spin_inertia;
                }
            }
        }
    }

    /// Applied generalized forces in ν: inputs τ (wheels then joints) minus viscous friction.
    pub fn applied(&self, nu: &[f64], tau: &[f64], out: &mut [f64]) {
        let l = self.layout;
        out[..l.m].fill(0.0);
        if let Some(p) = &self.platform {
            for s in 0..2 {
                out[s] = tau[s] - p.side_friction * nu[s];
            }
        }
        for i in 0..4 {
            let j = l.nu_arm + i;
            out[j] = tau[j] - self.joint_friction[i] * nu[j];
        }
    }
}

/// Adds one mass element's contribution: force += Jᵀ(lin, ang), M̄ += m J_vᵀJ_v + J_ωᵀ I J_ω.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn accumulate(
    jp: &Partials,
    mass_el: f64,
    iw: &Mat3,
    lin: Vec3,
    ang: Vec3,
    m: usize,
    force: &mut [f64],
    mass: Option<&mut [f64]>,
) {
    for a in 0..jp.len {
        force[jp.idx[a]] += jp.jv[a].dot(&lin) + jp.jw[a].dot(&ang);
    }
    if let Some(mm) = mass {
        let rotating = iw.iter().any(|&x| x != 0.0);
        for a in 0..jp.len {
            let iwa = if rotating {
                iw * jp.jw[a]
            } else {
                Vec3::zeros()
            };
            let ia = jp.idx[a];
            for b in 0..jp.len {
                let ib = jp.idx[b];
                mm[ia * m + ib] += mass_el * jp.jv[a].dot(&jp.jv[b]) + jp.jw[b].dot(&iwa);
            }
        }
    }
}

/// Scratch vectors of one evaluation (allocated once per run).
#[derive(Debug, Clone)]
pub struct Workspace {
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub sdn: Vec<f64>,
    pub scratch: Vec<f64>,
}

impl Workspace {
    pub fn new(n: usize) -> Self {
        Workspace {
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            sdn: vec![0.0; n],
            scratch: vec![0.0; n],
        }
    }
}
