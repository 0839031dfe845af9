#!/usr/bin/python3
"""Recorded synthetic step tests for the step-response identification tests.

Each plant is driven by one input step at t = 1 s, held between samples (the
continuous response to a step is exact on the sample grid), with white
Gaussian measurement noise of standard deviation 1 % of the output change
(seeded). The noise-free response is the plant's analytic step response
computed with scipy.signal.step, independent of pneumid's own simulation.

Run from the repository root:
    /usr/bin/python3 tests/identify/gen_synthetic_steps.py
writes tests/identify/data/{fopdt,sopdt,high_order}.csv (columns t,u,y,y_true)
and tests/identify/data/sopdt_steps.csv: the SOPDT plant under ten alternating
steps of 15 s each at Ts = 0.01 s, same noise level, for the process-model fit
(a single step carries too little information to pin tau2 down to 2 %: the
Cramer-Rao bound printed below is 3.4 % for the single-step record).
"""
import os

import numpy as np
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))

PLANTS = {
    # name: (numerator, denominator, delay s, Ts s, duration s, u0, u1, seed)
    "fopdt": ([2.5], [1.5, 1.0], 0.413, 0.02, 12.0, 10.0, 30.0, 1),
    "sopdt": ([1.2], np.polymul([2.0, 1.0], [0.7, 1.0]), 0.537, 0.02, 20.0, 0.0, 50.0, 2),
    "high_order": ([0.8], np.polymul(np.polymul([1.0, 1.0], [0.5, 1.0]), [0.25, 1.0]), 0.3,
                   0.02, 15.0, 20.0, 70.0, 3),
}
T_STEP = 1.0


def make(name, num, den, delay, Ts, duration, u0, u1, seed):
    n = int(round(duration / Ts)) + 1
    t = np.arange(n) * Ts
    u = np.where(t >= T_STEP - 1e-9, u1, u0)
    tau = t - T_STEP - delay
    y_true = np.zeros(n)
    after = tau > 0
    _, h = signal.step(signal.lti(num, den), T=np.concatenate(([0.0], tau[after])))
    y_true[after] = (u1 - u0) * h[1:]
    gain = num[-1] / den[-1]
    dy = gain * (u1 - u0)
    rng = np.random.default_rng(seed)
    y = y_true + rng.normal(0.0, 0.01 * abs(dy), n)
    path = os.path.join(HERE, "data", name + ".csv")
    with open(path, "w") as f:
        f.write("# %s: num=%s den=%s delay=%g Ts=%g step %g->%g at t=%g, noise std %g\n" %
                (name, list(num), list(np.asarray(den, float)), delay, Ts, u0, u1, T_STEP,
                 0.01 * abs(dy)))
        f.write("t,u,y,y_true\n")
        for row in zip(t, u, y, y_true):
            f.write("%.6f,%.10g,%.10g,%.10g\n" % row)


def step_response(num, den, delay, t):
    """Unit step response at times t (0 for t <= delay)."""
    tau = t - delay
    y = np.zeros(len(t))
    after = tau > 0
    if np.any(after):
        _, h = signal.step(signal.lti(num, den), T=np.concatenate(([0.0], tau[after])))
        y[after] = h[1:]
    return y


def make_steps(name, num, den, delay, Ts, segment, count, u0, u1, seed):
    n = int(round(segment * count / Ts))
    t = np.arange(n) * Ts
    u = np.full(n, u0)
    y_true = np.zeros(n)
    level = u0
    for i in range(count):
        t_i = 1.0 + i * segment
        new = u1 if i % 2 == 0 else u0
        u[t >= t_i - 1e-9] = new
        y_true += (new - level) * step_response(num, den, delay, t - t_i)
        level = new
    dy = num[-1] / den[-1] * (u1 - u0)
    rng = np.random.default_rng(seed)
    y = y_true + rng.normal(0.0, 0.01 * abs(dy), n)
    path = os.path.join(HERE, "data", name + ".csv")
    with open(path, "w") as f:
        f.write("# %s: num=%s den=%s delay=%g Ts=%g, %d alternating steps %g<->%g every %g s "
                "from t=1, noise std %g\n" % (name, list(num), list(np.asarray(den, float)),
                                               delay, Ts, count, u0, u1, segment, 0.01 * abs(dy)))
        f.write("t,u,y,y_true\n")
        for row in zip(t, u, y, y_true):
            f.write("%.6f,%.10g,%.10g,%.10g\n" % row)


def cramer_rao_sopdt(K, T1, T2, theta, Ts, duration, du, rel_noise):
    """Relative standard deviations (%) of K, T1, T2 and of theta in samples
    for a least-squares fit of one step (offset estimated too)."""
    t = np.arange(0.0, duration + 1e-9, Ts)

    def resp(p):
        k, a, b, d = p
        x = t - 1.0 - d
        y = np.zeros(len(t))
        m = x > 0
        y[m] = k * du * (1 - (a * np.exp(-x[m] / a) - b * np.exp(-x[m] / b)) / (a - b))
        return y

    p = np.array([K, T1, T2, theta])
    cols = []
    for i in range(4):
        h = 1e-6 * max(abs(p[i]), 1.0)
        pp, pm = p.copy(), p.copy()
        pp[i] += h
        pm[i] -= h
        cols.append((resp(pp) - resp(pm)) / (2 * h))
    J = np.column_stack(cols + [np.ones(len(t))])
    sd = np.sqrt(np.diag((rel_noise * abs(K * du)) ** 2 * np.linalg.inv(J.T @ J)))[:4]
    return 100 * sd[:3] / p[:3], sd[3] / Ts


if __name__ == "__main__":
    for name, args in PLANTS.items():
        make(name, *args)
    make_steps("sopdt_steps", [1.2], np.polymul([2.0, 1.0], [0.7, 1.0]), 0.537, 0.01, 15.0, 10,
               0.0, 50.0, 4)
    rel, th = cramer_rao_sopdt(1.2, 2.0, 0.7, 0.537, 0.02, 20.0, 50.0, 0.01)
    print("sopdt single step: Cramer-Rao std K %.2f %%, tau1 %.2f %%, tau2 %.2f %%, "
          "theta %.2f samples" % (rel[0], rel[1], rel[2], th))
