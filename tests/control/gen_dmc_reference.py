#!/usr/bin/python3
"""Independent reference for tests/control/dmc_test.cpp (docs/paper.md, reference value 6).

DMC (Cutler & Ramaker 1980) on the paper's FOPDT 1.6 exp(-0.001 s)/(0.245 s + 1)
sampled with a zero-order hold at Ts = 0.01 s. The plant is simulated exactly
by superposition of the closed-form sampled step response
    s(t) = K (1 - exp(-(t - theta)/tau)),  t >= theta,
so that no discretization routine is shared with the C++ code. Unit set-point
step at t = 0, P = 126. Prints first move, rise time 10-90 %, overshoot (%),
settling time 2 % (MATLAB stepinfo definitions, linear interpolation) and the
lambda_max(A'A)/500 tuning value.
Run: /usr/bin/python3 tests/control/gen_dmc_reference.py
"""
import numpy as np

K, tau, theta, Ts = 1.6, 0.245, 0.001, 0.01


def step(i):
    t = np.asarray(i, dtype=float) * Ts
    return np.where(t >= theta, K * (1.0 - np.exp(-(t - theta) / tau)), 0.0)


def dmc(P, M, lam, n_steps=300):
    A = np.zeros((P, M))
    for j in range(M):
        A[j:, j] = step(np.arange(1, P - j + 1))
    Kmat = np.linalg.solve(A.T @ A + lam * np.eye(M), A.T)
    k_row = Kmat[0]
    du = np.zeros(n_steps)
    y = np.zeros(n_steps + 1)
    u = np.zeros(n_steps)
    for k in range(n_steps):
        # exact plant output at k from past moves
        y[k] = sum(du[j] * step(k - j) for j in range(k))
        # free response over the horizon: past moves only, plus bias (zero here)
        i = np.arange(1, P + 1)
        f = np.array([sum(du[j] * step(k + ii - j) for j in range(k)) for ii in i], dtype=float)
        f += y[k] - sum(du[j] * step(k - j) for j in range(k))
        du[k] = k_row @ (np.ones(P) - f)
        u[k] = du[: k + 1].sum()
    y[n_steps] = sum(du[j] * step(n_steps - j) for j in range(n_steps))
    return A, u, y[:n_steps]


def stepinfo(t, y, y0=0.0, yf=1.0):
    d = yf - y0

    def cross(level):
        idx = np.nonzero((y - y0) / d >= level)[0][0]
        if idx == 0:
            return t[0]
        y1, y2 = (y[idx - 1] - y0) / d, (y[idx] - y0) / d
        return t[idx - 1] + (level - y1) / (y2 - y1) * (t[idx] - t[idx - 1])

    rise = cross(0.9) - cross(0.1)
    over = max(0.0, (y.max() - yf) / abs(d) * 100.0)
    # settling: last exit of the 2 % band, interpolated between samples
    outside = np.nonzero(np.abs(y - yf) > 0.02 * abs(d))[0]
    i = outside[-1]
    e1, e2 = abs(y[i] - yf), abs(y[i + 1] - yf)
    band = 0.02 * abs(d)
    settle = t[i] + (e1 - band) / (e1 - e2) * (t[i + 1] - t[i])
    return rise, over, settle


for M, lam in ((5, 2.25), (10, 1.92)):
    A, u, y = dmc(126, M, lam)
    t = np.arange(len(y)) * Ts
    r, o, s = stepinfo(t, y)
    lmax = np.linalg.eigvalsh(A.T @ A).max()
    print(f"M={M} lambda={lam}: first_move={u[0]:.6f} rise={r:.6f} overshoot={o:.6f} "
          f"settling={s:.6f} y_end={y[-1]:.9f} lambda_max/500={lmax / 500:.6f}")
