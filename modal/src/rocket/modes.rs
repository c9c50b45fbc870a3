//! Free-free natural frequencies of the reduced rocket at ignition mass.
//!
//! Linearization about the undeformed body at rest, no loads: K x = ω² M x with M the reduced
//! mass matrix at t = 0 (case + discrete masses) and K the modal stiffness plus the discrete
//! springs. The three rigid modes (X, Y, θ) have ω = 0 and are dropped. At the reference state
//! the axial (V_x, a, u_j) and transverse (V_y, ω, b, w_j) coordinates decouple exactly, so
//! each mode is classified by where its kinetic energy lives. Being a Rayleigh–Ritz reduction,
//! the frequencies converge from above as `discretization.modes` grows.

use data::scene::Rocket;
use data::{BackendKind, Cost, ModalResult, ModalSettings, ModeShape};

use super::basis::Basis;
use super::body::Body;
use super::config;
use super::dynamics::{Layout, Model, StationModes, fill_mass_matrix};
use super::eig::lowest_eigenpairs;
use super::error::RocketError;

/// Linear stiffness of the reduced model (row-major).
pub fn stiffness_matrix(model: &Model) -> Vec<f64> {
    let l = model.layout;
    let (n, nd) = (l.n, l.dofs());
    let mut k = vec![0.0; nd * nd];
    for i in 0..n {
        for j in 0..n {
            k[(l.a() + i) * nd + l.a() + j] = model.ka[i * n + j];
            k[(l.b() + i) * nd + l.b() + j] = model.kb[i * n + j];
        }
    }
    // ½ k (q_i − Σ c_p q_p)² for a spring between a mass coordinate and the case
    let mut add_case_spring = |mass_dof: usize, field0: usize, shape: &[f64], stiff: f64| {
        k[mass_dof * nd + mass_dof] += stiff;
        for p in 0..n {
            k[mass_dof * nd + field0 + p] -= stiff * shape[p];
            k[(field0 + p) * nd + mass_dof] -= stiff * shape[p];
            for r in 0..n {
                k[(field0 + p) * nd + field0 + r] += stiff * shape[p] * shape[r];
            }
        }
    };
    for (j, pm) in model.body.masses.iter().enumerate() {
        let st = &model.at_mass[j];
        add_case_spring(l.mu() + j, l.a(), &st.u, pm.ku);
        add_case_spring(l.mw() + j, l.b(), &st.w, pm.kw);
    }
    for c in &model.body.couplings {
        let (i, j) = (l.mu() + c.i, l.mu() + c.j);
        k[i * nd + i] += c.ku;
        k[j * nd + j] += c.ku;
        k[i * nd + j] -= c.ku;
        k[j * nd + i] -= c.ku;
        // ½k_w s², s the stretch across the whole body's mean axis: k_w g gᵀ
        for p in 0..l.nm {
            for r in 0..l.nm {
                k[(l.mw() + p) * nd + l.mw() + r] +=
                    c.kw * model.coupling_gradient_w(c, p) * model.coupling_gradient_w(c, r);
            }
        }
    }
    k
}

/// Is generalized coordinate i an axial one (V_x, a_k, u_j)?
fn is_axial(l: Layout, i: usize) -> bool {
    i == 0 || (l.a()..l.b()).contains(&i) || (l.mu()..l.mw()).contains(&i)
}

pub fn modes(
    scene: &data::Scene,
    r: &Rocket,
    settings: &ModalSettings,
    count: usize,
) -> Result<ModalResult, RocketError> {
    let wall = std::time::Instant::now();
    let body = Body::from_rocket(r)?;
    let n = config::modes(settings)?;
    let basis = Basis::new(&body, n)?;
    let model = Model::new(body, &basis);
    let l = model.layout;
    let nd = l.dofs();
    let available = nd - 3;
    if count > available {
        return Err(RocketError::invalid(
            "discretization.modes",
            format!(
                "{count} frequencies requested but {n} modes per field with {} discrete masses \
                 give only {available}; raise discretization.modes",
                l.nm
            ),
        ));
    }
    let mut m = vec![0.0; nd * nd];
    fill_mass_matrix(l, &model.body, &model.m0, &vec![0.0; nd], true, &mut m);
    let k = stiffness_matrix(&model);
    // shift of the order of the first elastic eigenvalue: the smallest K_ii/M_ii of the
    // elastic coordinates (the basis nearly diagonalizes the case)
    let sigma = (3..nd)
        .filter(|&i| k[i * nd + i] > 0.0)
        .map(|i| k[i * nd + i] / m[i * nd + i])
        .fold(f64::INFINITY, f64::min);
    let (lam, x) = lowest_eigenpairs(&k, &m, nd, sigma, (3 + count).max(4)).map_err(|message| {
        RocketError::Basis {
            field: "reduced",
            message,
        }
    })?;
    // three rigid modes: zero up to round-off relative to the first elastic eigenvalue
    if lam[3].is_nan() || lam[3] <= 0.0 || (0..3).any(|i| lam[i].abs() > 1e-6 * lam[3]) {
        return Err(RocketError::Basis {
            field: "reduced",
            message: format!(
                "expected exactly three rigid modes, eigenvalues start {:.3e} {:.3e} {:.3e} {:.3e}",
                lam[0], lam[1], lam[2], lam[3]
            ),
        });
    }
    let ns = scene.simulation.field_stations.max(2);
    let len = model.body.length;
    let xs: Vec<f64> = (0..ns).map(|i| len * i as f64 / (ns - 1) as f64).collect();
    let stations: Vec<StationModes> = xs.iter().map(|x| StationModes::new(&basis, *x)).collect();
    let mut freqs = Vec::with_capacity(count);
    let mut kinds = Vec::with_capacity(count);
    let mut shapes = Vec::with_capacity(count);
    for j in 3..3 + count {
        freqs.push(lam[j].sqrt() / (2.0 * std::f64::consts::PI));
        // kinetic-energy share of the axial coordinates: xᵢ (M x)ᵢ summed
        let (mut ax, mut tot) = (0.0, 0.0);
        for i in 0..nd {
            let mx: f64 = (0..nd).map(|p| m[i * nd + p] * x[(p, j)]).sum();
            let e = x[(i, j)] * mx;
            tot += e;
            if is_axial(l, i) {
                ax += e;
            }
        }
        let axial = ax > 0.5 * tot;
        kinds.push(if axial { "axial" } else { "bending" }.to_string());
        // transverse displacement of the case: frame translation + rotation + elastic part
        let mut w: Vec<f64> = stations
            .iter()
            .map(|st| {
                if axial {
                    0.0
                } else {
                    x[(1, j)]
                        + x[(2, j)] * st.x
                        + (0..n).map(|p| st.w[p] * x[(l.b() + p, j)]).sum::<f64>()
                }
            })
            .collect();
        let peak = w.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if peak > 0.0 {
            let sign = if w.last().copied().unwrap_or(0.0) < 0.0 {
                -1.0
            } else {
                1.0
            };
            w.iter_mut().for_each(|v| *v *= sign / peak);
        }
        shapes.push(ModeShape {
            link: 1,
            x: xs.clone(),
            transverse: w,
        });
    }
    Ok(ModalResult {
        backend: BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        frequencies_hz: freqs,
        kinds,
        shapes,
        cost: Cost {
            wall_time_s: wall.elapsed().as_secs_f64(),
            dofs: nd,
            factorizations: 2,
            ..Default::default()
        },
    })
}
