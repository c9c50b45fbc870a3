//! The foreshortening completions of the body's kinetic energy (see the parent module): the
//! exact-inextensible terms ΔT and the stretch–foreshortening coupling ΔT_us, added to 𝕄 and h
//! of one body evaluation. The contraction of the fourth-order tensor with b here is the
//! dominant cost of a modal evaluation with foreshortening; both are `#[inline]` so that they
//! stay inlined into `body_terms` across the module boundary (as they were in one file).

use super::BodyScratch;
use crate::linalg::{dot, mat_vec};
use crate::model::integrals::LinkIntegrals;

/// Kinetic coupling of the axial stretch u = ψᵀa with the foreshortening s = ½bᵀS b (axial
/// field on: the axial displacement is u − s, so the strain u' + ½v'² of the von Kármán
/// model is the stretch u' alone and the axial basis carries no ½v'²). From
/// ½∫ρA |V + ωJp + ṗ|² with p = (x + u − s, v), the products of u and s give
///
///   ΔT_us = −ȧᵀP(b, ḃ) − ½ω² aᵀP(b, b),   P_k(x, y) = Σ_ij P_kij x_i y_j,  P_kij = ∫ρA ψ_k S_ij,
///
/// so 𝕄_{a_k b} −= P_k b, 𝕄_ωω −= aᵀP(b, b), and (h = 𝕄̇ν − ∂T/∂e)
///   h_a,k += −P_k(ḃ, ḃ) + ½ω² P_k(b, b),   h_b += ω² Σ_k a_k P_k b,
///   h_ω += −ω [ȧᵀP(b, b) + 2 aᵀP(b, ḃ)].
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn stretch_foreshortening_terms(
    it: &LinkIntegrals,
    a: &[f64],
    ad: &[f64],
    b: &[f64],
    bd: &[f64],
    om: f64,
    mb: &mut [f64],
    h: &mut [f64],
    s: &mut BodyScratch,
) {
    let (na, nb) = (it.na, it.nb);
    let nn = nb * nb;
    let d = h.len();
    let (ia, ib) = (3, 3 + na);
    let mut m_omega = 0.0;
    let mut h_omega = 0.0;
    for k in 0..na {
        let pk = &it.p3[k * nn..(k + 1) * nn];
        let pb = &mut s.pb[k * nb..(k + 1) * nb];
        let pbd = &mut s.pbd[k * nb..(k + 1) * nb];
        mat_vec(pk, nb, b, pb);
        mat_vec(pk, nb, bd, pbd);
        let pkbb = dot(pb, b);
        let pkbbd = dot(pb, bd);
        let pkbdbd = dot(pbd, bd);
        for j in 0..nb {
            mb[(ia + k) * d + ib + j] -= pb[j];
            mb[(ib + j) * d + ia + k] -= pb[j];
            h[ib + j] += om * om * a[k] * pb[j];
        }
        m_omega += a[k] * pkbb;
        h_omega += ad[k] * pkbb + 2.0 * a[k] * pkbbd;
        h[ia + k] += -pkbdbd + 0.5 * om * om * pkbb;
    }
    mb[2 * d + 2] -= m_omega;
    h[2] -= om * h_omega;
}

/// Terms that make the inextensible (foreshortening) kinetic energy exact:
/// ΔT = ½∫ρA [ω² s² + 2ω(v ṡ − s v̇) + ṡ²], with s = ½bᵀS b, ṡ = bᵀS ḃ. Without them the
/// truncated T loses positive definiteness in the stiff direction "turn the frame, counter-bend
/// the link" (its inertia there is ∫ρA(ωx + v̇)², while the kept −ω²∫ρA·2xs is negative).
///
/// With Q_ijkl = ∫ρA S_ij S_kl, R_mij = ∫ρA φ_m S_ij, Bq = Q:(b⊗b) (= 2∫ρA s S),
/// Eq = Q:(ḃ⊗ḃ), A_jl = ∫ρA (Sb)_j (Sb)_l, Rv = R·b (= ∫ρA v S), Rvd = R·ḃ,
/// z_p = R_p:(b⊗ḃ), w_j = R_j:(b⊗b):
///   𝕄_ωω += ¼ bᵀBq b,   𝕄_ωb += Rv b − ½w,   𝕄_bb += A,
///   h_ω += ω ḃᵀBq b + ḃ·(Rvd b + Rv ḃ − z),
///   h_b += 2ω (Rvd b − z) + Eq b − ½ω² Bq b.
///
/// Evaluation (O(n⁴)/2 once, O(n³) after): one contraction of Q with b,
/// C_ij,l = Σ_k Q_ij,kl b_k (symmetric in ij: n²(n+1)/2 rows of n² products), gives
/// A_jl = Σ_i b_i C_ij,l and Eq b = Σ_ij ḃ_iḃ_j C_ij; by the symmetries of Q
/// (Q_ij,kl = Q_ji,kl = Q_kl,ij) Bq b = A b, so bᵀBq b = bᵀA b and ḃᵀBq b = ḃᵀA b, and
/// neither Bq nor Eq is formed. R enters through D_mj = Σ_l R_mjl b_l and E_mj = Σ_l R_mjl ḃ_l:
/// Rv b = Dᵀb, w = D b, Rvd b = Dᵀḃ, Rv ḃ = Eᵀb, z = E b.
#[inline]
pub(super) fn exact_inextensible_terms(
    it: &LinkIntegrals,
    b: &[f64],
    bd: &[f64],
    om: f64,
    mb: &mut [f64],
    h: &mut [f64],
    s: &mut BodyScratch,
) {
    let n = it.nb;
    let nn = n * n;
    let na = it.na;
    let d = h.len();
    let ib = 3 + na;
    // C_ij = Σ_k b_k Q_ij,k· for i ≤ j (C_ji = C_ij), then A_j· = Σ_i b_i C_ij· and
    // Eq b = Σ_{i≤j} (2 − δ_ij) ḃ_iḃ_j C_ij.
    match n {
        4 => quartic_contractions::<4>(&it.q4, b, bd, s),
        5 => quartic_contractions::<5>(&it.q4, b, bd, s),
        6 => quartic_contractions::<6>(&it.q4, b, bd, s),
        7 => quartic_contractions::<7>(&it.q4, b, bd, s),
        8 => quartic_contractions::<8>(&it.q4, b, bd, s),
        10 => quartic_contractions::<10>(&it.q4, b, bd, s),
        12 => quartic_contractions::<12>(&it.q4, b, bd, s),
        _ => quartic_contractions_any(&it.q4, n, b, bd, s),
    }
    mat_vec(&s.amat, n, b, &mut s.ab);
    // D_m· = R_m b, E_m· = R_m ḃ (R_m symmetric n × n).
    for m in 0..n {
        let r = &it.r3[m * nn..(m + 1) * nn];
        mat_vec(r, n, b, &mut s.dr[m * n..(m + 1) * n]);
        mat_vec(r, n, bd, &mut s.er[m * n..(m + 1) * n]);
    }
    // w = D b, z = E b, Rvd b = Dᵀḃ (t1), Rv b = Dᵀb, Rv ḃ = Eᵀb.
    for p in 0..n {
        s.t2[p] = dot(&s.dr[p * n..(p + 1) * n], b);
        s.zv[p] = dot(&s.er[p * n..(p + 1) * n], b);
    }
    let bqbb = dot(b, &s.ab);
    let bqbdb = dot(bd, &s.ab);
    mb[2 * d + 2] += 0.25 * bqbb;
    let mut h_om = om * bqbdb;
    for j in 0..n {
        let (mut rvb, mut rvdb, mut rvbd) = (0.0, 0.0, 0.0);
        for m in 0..n {
            rvb += b[m] * s.dr[m * n + j];
            rvdb += bd[m] * s.dr[m * n + j];
            rvbd += b[m] * s.er[m * n + j];
        }
        let c = rvb - 0.5 * s.t2[j];
        mb[2 * d + ib + j] += c;
        mb[(ib + j) * d + 2] += c;
        for l in 0..n {
            mb[(ib + j) * d + ib + l] += s.amat[j * n + l];
        }
        h_om += bd[j] * (rvdb + rvbd - s.zv[j]);
        s.t1[j] = rvdb;
    }
    h[2] += h_om;
    for p in 0..n {
        h[ib + p] += 2.0 * om * (s.t1[p] - s.zv[p]) + s.eqb[p] - 0.5 * om * om * s.ab[p];
    }
}

/// The contractions of Q with b of [`exact_inextensible_terms`] for any order n: C_ij for
/// i ≤ j mirrored to C_ji (`s.cq`), A (`s.amat`) and Eq b (`s.eqb`).
fn quartic_contractions_any(q4: &[f64], n: usize, b: &[f64], bd: &[f64], s: &mut BodyScratch) {
    let nn = n * n;
    for i in 0..n {
        for j in i..n {
            let row = &q4[(i * n + j) * nn..(i * n + j + 1) * nn];
            let cij = &mut s.cq[(i * n + j) * n..(i * n + j + 1) * n];
            cij.iter_mut().for_each(|v| *v = 0.0);
            for (bk, qk) in b.iter().zip(row.chunks_exact(n)) {
                for (c, q) in cij.iter_mut().zip(qk) {
                    *c += bk * q;
                }
            }
        }
        for j in 0..i {
            let (lo, hi) = s.cq.split_at_mut((i * n + j) * n);
            hi[..n].copy_from_slice(&lo[(j * n + i) * n..(j * n + i + 1) * n]);
        }
    }
    s.amat.iter_mut().for_each(|v| *v = 0.0);
    s.eqb.iter_mut().for_each(|v| *v = 0.0);
    for i in 0..n {
        let bi = b[i];
        for j in 0..n {
            let cij = &s.cq[(i * n + j) * n..(i * n + j + 1) * n];
            for (a, c) in s.amat[j * n..(j + 1) * n].iter_mut().zip(cij) {
                *a += bi * c;
            }
            if j >= i {
                let wgt = if i == j { 1.0 } else { 2.0 };
                let e = wgt * bd[i] * bd[j];
                for (v, c) in s.eqb.iter_mut().zip(cij) {
                    *v += e * c;
                }
            }
        }
    }
}

/// [`quartic_contractions_any`] with the order N known: every sum accumulates in registers
/// (the general loop loads and stores C_ij for every k), each from zero and in the general
/// loop's order, so with its bits; C is read by its upper triangle instead of being
/// mirrored. This contraction is the largest single cost of a modal evaluation with
/// foreshortening (docs/performance.md).
#[inline]
fn quartic_contractions<const N: usize>(q4: &[f64], b: &[f64], bd: &[f64], s: &mut BodyScratch) {
    let b: &[f64; N] = b.try_into().expect("b of order N");
    let bd: &[f64; N] = bd.try_into().expect("ḃ of order N");
    let cq = &mut s.cq[..N * N * N];
    for i in 0..N {
        for j in i..N {
            let row = &q4[(i * N + j) * N * N..(i * N + j + 1) * N * N];
            let mut c = [0.0; N];
            for (bk, qk) in b.iter().zip(row.chunks_exact(N)) {
                let qk: &[f64; N] = qk.try_into().expect("rows of N");
                for l in 0..N {
                    c[l] += bk * qk[l];
                }
            }
            cq[(i * N + j) * N..(i * N + j + 1) * N].copy_from_slice(&c);
        }
    }
    let cq = &s.cq[..N * N * N];
    let upper = |i: usize, j: usize| -> &[f64; N] {
        let (p, q) = if i <= j { (i, j) } else { (j, i) };
        cq[(p * N + q) * N..(p * N + q + 1) * N]
            .try_into()
            .expect("rows of N")
    };
    for j in 0..N {
        let mut a = [0.0; N];
        for i in 0..N {
            let c = upper(i, j);
            for l in 0..N {
                a[l] += b[i] * c[l];
            }
        }
        s.amat[j * N..(j + 1) * N].copy_from_slice(&a);
    }
    let mut e = [0.0; N];
    for i in 0..N {
        for j in i..N {
            let wgt = if i == j { 1.0 } else { 2.0 };
            let x = wgt * bd[i] * bd[j];
            let c = upper(i, j);
            for l in 0..N {
                e[l] += x * c[l];
            }
        }
    }
    s.eqb[..N].copy_from_slice(&e);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_quartic_contractions_of_known_order_keep_the_general_bits() {
        // Any Q (the functions rely on no symmetry of it) and state: the registers' version
        // must give C's upper triangle, A and Eq b bit for bit.
        for n in [4, 5, 6, 7, 8, 10, 12] {
            let mut x = 0.377_f64;
            let mut next = || {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-3, 1.0 - 1e-3);
                x - 0.5
            };
            let q4: Vec<f64> = (0..n * n * n * n).map(|_| next()).collect();
            let b: Vec<f64> = (0..n).map(|_| next()).collect();
            let bd: Vec<f64> = (0..n).map(|_| 10.0 * next()).collect();
            let mut general = BodyScratch::new(2, n, 0);
            let mut known = BodyScratch::new(2, n, 0);
            quartic_contractions_any(&q4, n, &b, &bd, &mut general);
            match n {
                4 => quartic_contractions::<4>(&q4, &b, &bd, &mut known),
                5 => quartic_contractions::<5>(&q4, &b, &bd, &mut known),
                6 => quartic_contractions::<6>(&q4, &b, &bd, &mut known),
                7 => quartic_contractions::<7>(&q4, &b, &bd, &mut known),
                8 => quartic_contractions::<8>(&q4, &b, &bd, &mut known),
                10 => quartic_contractions::<10>(&q4, &b, &bd, &mut known),
                _ => quartic_contractions::<12>(&q4, &b, &bd, &mut known),
            }
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&general.amat), bits(&known.amat), "A, n = {n}");
            assert_eq!(bits(&general.eqb), bits(&known.eqb), "Eq b, n = {n}");
            for i in 0..n {
                for j in i..n {
                    let r = (i * n + j) * n..(i * n + j + 1) * n;
                    assert_eq!(
                        bits(&general.cq[r.clone()]),
                        bits(&known.cq[r]),
                        "C_{i}{j}, n = {n}"
                    );
                }
            }
        }
    }
}
