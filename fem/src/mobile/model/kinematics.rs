//! The recursive kinematics of the mobile manipulator: frames F0…F5 at (q, q̇, q̈), the
//! full coordinate rates q̇ = S(q)ν and Ṡν, and the partial velocities (J_v, J_ω) of a point
//! carried by a frame or by the flexible link (parent module docs).

use nalgebra::Vector3;

use super::{EY, EZ, FlexLink, Frames, MINUS_EY, Model, Partials, Vec3, revolute, rot_z};
use crate::element::Shapes;

impl Model {
    /// Recursive kinematics of F0…F5 at (q, q̇, q̈) (full coordinate rates, any q̇).
    pub fn frames(&self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Frames {
        let mut f = Frames::default();
        let l = self.layout;
        if l.platform {
            f.o[0] = Vector3::new(q[0], q[1], 0.0);
            f.r[0] = rot_z(q[2]);
            f.w[0] = Vector3::new(0.0, 0.0, qd[2]);
            f.al[0] = Vector3::new(0.0, 0.0, qdd[2]);
            f.v[0] = Vector3::new(qd[0], qd[1], 0.0);
            f.a[0] = Vector3::new(qdd[0], qdd[1], 0.0);
        } else {
            let [x, y, psi] = self.ground_pose;
            f.o[0] = Vector3::new(x, y, 0.0);
            f.r[0] = rot_z(psi);
        }
        let a0 = l.q_arm;
        for k in 1..6 {
            // Offset of frame k's origin in frame k − 1 (with its rates when it is a flexible tip).
            let mut d = [Vec3::zeros(); 3];
            let mut tip = None;
            match k {
                1 => d[0] = self.mount,
                2 => d[0] = Vector3::new(0.0, 0.0, self.base_height),
                _ => {
                    d[0] = Vector3::new(self.lengths[k - 3], 0.0, 0.0);
                    if let Some(fl) = &self.flex
                        && fl.frame == k - 1
                    {
                        let b = l.q_el + fl.ne - 4;
                        d[0][1] = q[b];
                        d[0][2] = q[b + 2];
                        d[1] = Vector3::new(0.0, qd[b], qd[b + 2]);
                        d[2] = Vector3::new(0.0, qdd[b], qdd[b + 2]);
                        tip = Some(b);
                    }
                }
            }
            let (r, w, al) = (f.r[k - 1], f.w[k - 1], f.al[k - 1]);
            [f.o[k], f.v[k], f.a[k]] = f.carry(k - 1, d);
            let (mut r, mut w, mut al) = (r, w, al);
            if let Some(b) = tip {
                f.tip_o = f.o[k];
                f.tip_axes[0] = r * EY;
                f.tip_axes[1] = r * EZ;
                f.tip_axes[2] = revolute(
                    &mut r,
                    &mut w,
                    &mut al,
                    EZ,
                    [q[b + 1], qd[b + 1], qdd[b + 1]],
                );
                f.tip_axes[3] = revolute(
                    &mut r,
                    &mut w,
                    &mut al,
                    MINUS_EY,
                    [q[b + 3], qd[b + 3], qdd[b + 3]],
                );
            }
            if k < 5 {
                let u = if k == 1 { EZ } else { MINUS_EY };
                let j = a0 + k - 1;
                f.axis[k] = revolute(&mut r, &mut w, &mut al, u, [q[j], qd[j], qdd[j]]);
            }
            f.r[k] = r;
            f.w[k] = w;
            f.al[k] = al;
        }
        f
    }

    /// q̇ = S(q) ν into `qd` and Ṡ ν into `sdot_nu`.
    pub fn velocities(&self, q: &[f64], nu: &[f64], qd: &mut [f64], sdot_nu: &mut [f64]) {
        let l = self.layout;
        sdot_nu[..l.n].fill(0.0);
        if let Some(p) = &self.platform {
            let (s, c) = q[2].sin_cos();
            let u = 0.5 * p.wheel_radius * (nu[0] + nu[1]);
            let psid = 0.5 * p.wheel_radius / p.half_track * (nu[0] - nu[1]);
            qd[0] = u * c;
            qd[1] = u * s;
            qd[2] = psid;
            qd[3] = nu[0];
            qd[4] = nu[1];
            sdot_nu[0] = -u * s * psid;
            sdot_nu[1] = u * c * psid;
        }
        qd[l.q_arm..l.n].copy_from_slice(&nu[l.nu_arm..l.m]);
    }

    /// Partial velocities ∂(v, ω)/∂ν of a point `p` fixed to frame `k` (k ≤ 5).
    pub(super) fn frame_partials(
        &self,
        f: &Frames,
        q: &[f64],
        k: usize,
        p: Vec3,
        out: &mut Partials,
    ) {
        out.len = 0;
        let l = self.layout;
        if let Some(pl) = &self.platform {
            let (s, c) = q[2].sin_cos();
            let half = 0.5 * pl.wheel_radius;
            let v = Vector3::new(half * c, half * s, 0.0);
            let yaw = half / pl.half_track;
            let turn = EZ.cross(&(p - f.o[0]));
            out.push(0, v + (yaw * turn), Vector3::new(0.0, 0.0, yaw));
            out.push(1, v - (yaw * turn), Vector3::new(0.0, 0.0, -yaw));
        }
        for j in 1..5.min(k + 1) {
            let axis = f.axis[j];
            out.push(l.nu_arm + j - 1, axis.cross(&(p - f.o[j])), axis);
        }
        if let Some(fl) = &self.flex
            && k > fl.frame
        {
            let b = l.nu_el + fl.ne - 4;
            let zero = Vec3::zeros();
            out.push(b, f.tip_axes[0], zero);
            out.push(b + 2, f.tip_axes[1], zero);
            let arm = p - f.tip_o;
            out.push(b + 1, f.tip_axes[2].cross(&arm), f.tip_axes[2]);
            out.push(b + 3, f.tip_axes[3].cross(&arm), f.tip_axes[3]);
        }
    }

    /// Partial velocities of the beam point of element `el` with shapes `s` at inertial
    /// position `p`: the frame's (rigid) columns plus R_F N e_y, R_F N e_z.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn beam_partials(
        &self,
        f: &Frames,
        q: &[f64],
        fl: &FlexLink,
        el: usize,
        s: &Shapes,
        p: Vec3,
        out: &mut Partials,
    ) {
        self.frame_partials(f, q, fl.frame, p, out);
        let (ey, ez) = (f.r[fl.frame] * EY, f.r[fl.frame] * EZ);
        let zero = Vec3::zeros();
        for (field, axis) in [(0, ey), (1, ez)] {
            for a in 0..4 {
                if let Some(g) = FlexLink::dof(el, a, field) {
                    out.push(self.layout.nu_el + g, s.n[a] * axis, zero);
                }
            }
        }
    }
}
