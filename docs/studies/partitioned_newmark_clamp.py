# Stability of a partitioned Newmark step for fdm's clamp ghost (docs/performance.md, "What
# bounds the step"). Linear model of one clamped link of the two-link arm (link 2: L = 2 ft,
# rhoA = 1.764 slug/ft, EI = 5029.5312 lbf ft^2), the clamp ghost as the section rotation psi
# with fdm's rotary inertia J_c = rhoA h^3/24: the amplification matrix of the velocity form
# (every DOF explicit, beta = 0) and of the partition with psi at beta = 1/4, at steps relative
# to the bending waves' own limit 2/omega (psi held). Run: python3 docs/studies/partitioned_newmark_clamp.py
# (needs numpy).
# Clamped link with the clamp ghost turned into the section rotation psi (z coordinates):
# stations v_1..v_N (v_0 = 0 at the clamp), psi with rotary inertia J = rhoA h^3/24,
# V = sum_i c_i h EI kappa_i^2 / 2, kappa_0 = (2 v_1 - 2 h psi)/h^2 (c_0 = 1/2),
# kappa_i = (v_{i+1} - 2 v_i + v_{i-1})/h^2, free end via kappa_N = 0 (ghost eliminated).
import numpy as np
EI, rA, L = 5029.5312, 1.764, 2.0
def model(N, jscale=1.0):
    h = L / N
    n = N + 1  # psi, v1..vN
    # curvature rows as linear forms of x = (psi, v1..vN)
    rows, w = [], []
    r = np.zeros(n); r[1] = 2/h**2; r[0] = -2*h/h**2; rows.append(r); w.append(0.5)
    for i in range(1, N):  # kappa_i for i=1..N-1
        r = np.zeros(n); r[i+1 if i+1<=N else 0] += 1/h**2; r[i] += -2/h**2
        if i-1 >= 1: r[i-1] += 1/h**2
        rows.append(r); w.append(1.0)
    R = np.array(rows); W = np.diag(w)
    K = h*EI * R.T @ W @ R
    M = np.diag([jscale*rA*h**3/24] + [rA*h]*(N-1) + [rA*h/2])
    return h, M, K
def omega_max(M, K):
    ev = np.linalg.eigvals(np.linalg.solve(M, K))
    return np.sqrt(np.max(ev.real))
def amplification(M, K, tau, beta):
    # partitioned Newmark: q~ = q + tau v + (1/2 - beta_i) tau^2 a; v~ = v + tau/2 a;
    # (M + tau^2 K B) a1 = -K q~; q1 = q~ + tau^2 B a1; v1 = v~ + tau/2 a1
    n = M.shape[0]; B = np.diag(beta)
    A = M + tau**2 * K @ B
    Ainv = np.linalg.inv(A)
    I = np.eye(n)
    # state (q, v, a)
    Qq = I; Qv = tau*I; Qa = tau**2*(0.5*I - B)
    a1_q = -Ainv@K@Qq; a1_v = -Ainv@K@Qv; a1_a = -Ainv@K@Qa
    q1 = np.hstack([Qq + tau**2*B@a1_q, Qv + tau**2*B@a1_v, Qa + tau**2*B@a1_a])
    v1 = np.hstack([0.5*tau*a1_q, I + 0.5*tau*a1_v, 0.5*tau*I + 0.5*tau*a1_a])
    a1 = np.hstack([a1_q, a1_v, a1_a])
    G = np.vstack([q1, v1, a1])
    return np.max(np.abs(np.linalg.eigvals(G)))
for N in [10, 20, 40]:
    h, M, K = model(N)
    wmax = omega_max(M, K)
    wint = 4/h**2*np.sqrt(EI/rA)
    # top mode without the ghost (psi held): interior bending only
    wv = omega_max(M[1:,1:], K[1:,1:])
    print(f"N={N}: omega_max/omega_int = {wmax/wint:.3f}, without psi {wv/wint:.3f}")
    beta = np.zeros(M.shape[0]); beta[0] = 0.25
    for f in [0.5, 0.9, 1.0, 1.05]:
        tau = f*2/wv
        rho_ex = amplification(M, K, tau, np.zeros(M.shape[0]))
        rho_im = amplification(M, K, tau, beta)
        print(f"   tau = {f} x 2/omega(v only): spectral radius explicit {rho_ex:.4f}, psi implicit {rho_im:.4f}")
