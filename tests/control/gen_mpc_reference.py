#!/usr/bin/python3
"""Independent reference values for tests/control/mpc_test.cpp and dare_test.cpp.

Computed with numpy/scipy only, from the definitions in
include/pneumid/control/mpc.hpp and dare.hpp, without the C++ code's
formulas for the prediction matrices:
  * the DARE by scipy.linalg.solve_discrete_are (QZ on the symplectic pencil);
  * the prediction y^ = Phi z + Gamma (1 u_prev + S du) built from the stacked
    Markov parameters (block-Toeplitz Gamma, P x P) and the input-hold matrix S
    (P x M), and the unconstrained first-move gain by solving the normal
    equations of the cost;
  * one constrained step by scipy.optimize.minimize (SLSQP), polished by
    solving the KKT system of the active set it finds (multipliers checked).

Cases
  fopdt: the paper's FOPDT 1.6 exp(-0.001 s)/(0.245 s + 1) at Ts = 0.01 s,
         sampled exactly (modified z-transform) with the states
         [y, u(k-1)]; output disturbance; P = 126, M = 5, lambda = 2.25
         (the paper's DMC settings), q = 1, R = 1, state noise 0.01,
         disturbance noise 1.
  second_order: x+ = [1.6 -0.64; 1 0] x + [1; 0] u(k-2), y = [0.1 0.08] x
         (double pole at 0.8, static gain 4.5, two samples of input delay as
         two shift-register states); input disturbance; P = 30, M = 4,
         lambda = 0.5, q = 2, input weight 0.1, R = 0.1, state noise 0.01 on
         the two plant states, disturbance noise 0.5.

Run: /usr/bin/python3 tests/control/gen_mpc_reference.py
"""
import numpy as np
import scipy.linalg
import scipy.optimize

np.set_printoptions(precision=17)


def fmt(v):
    return ", ".join(f"{x:.17g}" for x in np.ravel(v))


def fopdt_case():
    K, tau, theta, Ts = 1.6, 0.245, 0.001, 0.01
    a = np.exp(-Ts / tau)
    b0 = K * (1.0 - np.exp(-(Ts - theta) / tau))
    b1 = K * np.exp(-(Ts - theta) / tau) * (1.0 - np.exp(-theta / tau))
    A = np.array([[a, b1], [0.0, 0.0]])
    B = np.array([1.0 * b0, 1.0])
    C = np.array([1.0, 0.0])
    return dict(name="fopdt", A=A, B=B, C=C, n_plant=2, dist="output", P=126, M=5, lam=2.25,
                q=1.0, wu=0.0, R=1.0, qx=0.01, qd=1.0)


def second_order_case():
    A0 = np.array([[1.6, -0.64], [1.0, 0.0]])
    B0 = np.array([1.0, 0.0])
    C0 = np.array([0.1, 0.08])
    # two samples of input delay as states v1, v2: v1+ = u, v2+ = v1, x+ = A0 x + B0 v2
    A = np.zeros((4, 4))
    A[:2, :2] = A0
    A[:2, 3] = B0
    A[3, 2] = 1.0
    B = np.array([0.0, 0.0, 1.0, 0.0])
    C = np.concatenate([C0, [0.0, 0.0]])
    return dict(name="second_order", A=A, B=B, C=C, n_plant=2, dist="input", P=30, M=4, lam=0.5,
                q=2.0, wu=0.1, R=0.1, qx=0.01, qd=0.5)


def augment(c):
    A, B, C = c["A"], c["B"], c["C"]
    n = A.shape[0]
    if c["dist"] == "none":
        return A, B, C
    Az = np.zeros((n + 1, n + 1))
    Az[:n, :n] = A
    Az[n, n] = 1.0
    Bz = np.concatenate([B, [0.0]])
    if c["dist"] == "output":
        Cz = np.concatenate([C, [1.0]])
    else:
        Az[:n, n] = B
        Cz = np.concatenate([C, [0.0]])
    return Az, Bz, Cz


def design(c):
    Az, Bz, Cz = augment(c)
    nz = Az.shape[0]
    n = c["A"].shape[0]
    Qz = np.zeros((nz, nz))
    Qz[: c["n_plant"], : c["n_plant"]] = c["qx"] * np.eye(c["n_plant"])
    if nz > n:
        Qz[n, n] = c["qd"]
    X = scipy.linalg.solve_discrete_are(Az.T, Cz[:, None], Qz, np.array([[c["R"]]]))
    L = X @ Cz / (Cz @ X @ Cz + c["R"])
    P, M = c["P"], c["M"]
    Phi = np.array([Cz @ np.linalg.matrix_power(Az, i) for i in range(1, P + 1)])
    markov = np.array([Cz @ np.linalg.matrix_power(Az, i) @ Bz for i in range(P)])
    Gamma = np.zeros((P, P))  # y(k+i) from u(k+j), j < i
    for i in range(P):
        for j in range(i + 1):
            Gamma[i, j] = markov[i - j]
    S = np.zeros((P, M))  # u(k+j) - u(k-1) = sum_{l <= min(j, M-1)} du_l
    for j in range(P):
        S[j, : min(j, M - 1) + 1] = 1.0
    Theta = Gamma @ S
    T = S[:M, :]
    G = c["C"] @ np.linalg.solve(np.eye(n) - c["A"], c["B"])
    q, lam, wu = c["q"], c["lam"], c["wu"]
    H = q * Theta.T @ Theta + lam * np.eye(M) + wu * T.T @ T

    def g_of(z, u_prev, r, us):
        e = r - Phi @ z - Gamma @ np.ones(P) * u_prev
        return -q * Theta.T @ e + wu * T.T @ (np.ones(M) * (u_prev - us))

    # gain by linearity: du0 = -e1' H^-1 g
    def du0(z, u_prev, r, us):
        return -np.linalg.solve(H, g_of(z, u_prev, r, us))[0]

    K_r = du0(np.zeros(nz), 0.0, 1.0, 0.0)
    K_s = du0(np.zeros(nz), 0.0, 0.0, 1.0)
    K_u = -du0(np.zeros(nz), 1.0, 0.0, 0.0)
    K_z = np.array([-du0(np.eye(nz)[i], 0.0, 0.0, 0.0) for i in range(nz)])
    return dict(Az=Az, Bz=Bz, Cz=Cz, X=X, L=L, H=H, Theta=Theta, Phi=Phi, Gamma=Gamma, T=T,
                G=G, g_of=g_of, K_r=K_r, K_s=K_s, K_u=K_u, K_z=K_z)


def solve_qp(H, g, A_in, b_in):
    """min 1/2 x'Hx + g'x s.t. A_in x >= b_in: SLSQP, then its active set refined until
    the KKT system gives nonnegative multipliers and a feasible point."""
    n = H.shape[0]
    res = scipy.optimize.minimize(
        lambda x: 0.5 * x @ H @ x + g @ x, np.zeros(n), jac=lambda x: H @ x + g,
        constraints=[{"type": "ineq", "fun": lambda x: A_in @ x - b_in, "jac": lambda x: A_in}],
        method="SLSQP", options={"ftol": 1e-15, "maxiter": 1000})
    x = res.x
    slack = A_in @ x - b_in
    act = list(np.nonzero(np.abs(slack) < 1e-6 * max(1.0, np.abs(b_in).max()))[0])
    # Refine the active set: drop a negative multiplier or add the most violated row.
    for _ in range(100):
        Aa = A_in[act]
        na = len(act)
        KKT = np.block([[H, -Aa.T], [Aa, np.zeros((na, na))]])
        sol = np.linalg.solve(KKT, np.concatenate([-g, b_in[act]]))
        x, mu = sol[:n], sol[n:]
        viol = A_in @ x - b_in
        if na and mu.min() < -1e-12:
            act.pop(int(np.argmin(mu)))
        elif viol.min() < -1e-12:
            act.append(int(np.argmin(viol)))
        else:
            break
    assert (mu >= -1e-12).all() and (A_in @ x - b_in >= -1e-12).all()
    # x satisfies the KKT conditions of a strictly convex QP: it is the minimizer,
    # and no worse than the SLSQP point (which may stop early on badly scaled costs).
    obj = lambda v: 0.5 * v @ H @ v + g @ v
    assert obj(x) <= obj(res.x) + 1e-9 * max(1.0, abs(obj(x)))
    return x, act, res


def constrained_step(c, d, u0, y0, r, y, u_min, u_max, du_max, y_max, rho1=1e4, rho2=1e2):
    """Reset(u0, y0), then one Update(r, y) with bounds on u, du and a soft y_max."""
    n = c["A"].shape[0]
    M, P = c["M"], c["P"]
    xs_unit = np.linalg.solve(np.eye(n) - c["A"], c["B"])
    z = np.zeros(d["Az"].shape[0])
    if c["dist"] == "output":
        z[:n] = xs_unit * u0
        z[n] = y0 - c["C"] @ z[:n]
    elif c["dist"] == "input":
        dd = y0 / d["G"] - u0
        z[:n] = xs_unit * (u0 + dd)
        z[n] = dd
    else:
        z = xs_unit * u0
    z = z + d["L"] * (y - d["Cz"] @ z)
    if c["dist"] == "output":
        us = (r - z[n]) / d["G"]
    elif c["dist"] == "input":
        us = r / d["G"] - z[n]
    else:
        us = r / d["G"]
    g = d["g_of"](z, u0, r, us)
    soft = np.isfinite(y_max)
    nv = M + (1 if soft else 0)
    Hq = np.zeros((nv, nv))
    Hq[:M, :M] = d["H"]
    gq = np.zeros(nv)
    gq[:M] = g
    rows, rhs = [], []
    T = d["T"]
    for j in range(M):  # u_min <= u0 + T du <= u_max
        rows.append(np.concatenate([T[j], [0.0] * (nv - M)]))
        rhs.append(u_min - u0)
        rows.append(np.concatenate([-T[j], [0.0] * (nv - M)]))
        rhs.append(u0 - u_max)
    for j in range(M):  # |du_j| <= du_max
        e = np.zeros(nv)
        e[j] = 1.0
        rows.append(e)
        rhs.append(-du_max)
        rows.append(-e)
        rhs.append(-du_max)
    if soft:
        Hq[M, M] = rho2
        gq[M] = rho1
        f = d["Phi"] @ z + d["Gamma"] @ np.ones(P) * u0
        for i in range(P):  # Theta du - e <= y_max - f
            rows.append(np.concatenate([-d["Theta"][i], [1.0]]))
            rhs.append(f[i] - y_max)
        e = np.zeros(nv)
        e[M] = 1.0
        rows.append(e)
        rhs.append(0.0)
    x, act, res = solve_qp(Hq, gq, np.array(rows), np.array(rhs))
    return x, act, res, z, us


def main():
    # DARE cases (dare_test.cpp)
    A = np.array([[1.1, 0.2, 0.0, 0.0], [0.0, 0.9, 0.3, 0.0], [0.1, 0.0, 0.8, 0.2],
                  [0.0, 0.0, -0.3, 1.05]])
    B = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [0.5, 0.2]])
    Q = np.diag([1.0, 2.0, 0.5, 1.0])
    R = np.array([[1.0, 0.2], [0.2, 0.5]])
    X = scipy.linalg.solve_discrete_are(A, B, Q, R)
    print("// dare 4x4 (unstable A, 2 inputs): X row-major")
    print("X = {" + fmt(X) + "}")

    for c in (fopdt_case(), second_order_case()):
        d = design(c)
        print(f"// case {c['name']}: A = {{{fmt(c['A'])}}}, B = {{{fmt(c['B'])}}}")
        print(f"G = {d['G']:.17g}")
        print("X = {" + fmt(d["X"]) + "}")
        print("L = {" + fmt(d["L"]) + "}")
        print(f"K_r = {d['K_r']:.17g}; K_s = {d['K_s']:.17g}; K_u = {d['K_u']:.17g}")
        print("K_z = {" + fmt(d["K_z"]) + "}")
        if c["name"] == "fopdt":
            for label, y_max in (("u/du bounds", np.inf), ("u/du bounds + soft y_max 0.8", 0.8)):
                x, act, res, z, us = constrained_step(c, d, u0=0.1, y0=0.2, r=1.0, y=0.25,
                                                      u_min=0.0, u_max=0.9, du_max=0.25,
                                                      y_max=y_max)
                print(f"// constrained step ({label}): Reset(0.1, 0.2); Update(1.0, 0.25); "
                      f"u in [0, 0.9], |du| <= 0.25; active rows {list(act)}; SLSQP: "
                      f"{res.message}")
                print("moves = {" + fmt(x) + "}")
                print(f"u = {0.1 + x[0]:.17g}")


if __name__ == "__main__":
    main()
