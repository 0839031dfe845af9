#!/usr/bin/python3
"""Recorded synthetic step tests for the step-response identification tests.

Each plant is driven by one input step at t = 1 s, held between samples (the
continuous response to a step is exact on the sample grid), with white
Gaussian measurement noise of standard deviation 1 % of the output change
(seeded). The noise-free response is the plant's analytic step response
computed with scipy.signal.step, independent of pneumid's own simulation.

Run from the repository root:
    /usr/bin/python3 tests/identify/gen_synthetic_steps.py
writes tests/identify/data/{fopdt,sopdt,high_order}.csv (columns t,u,y,y_true).
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


if __name__ == "__main__":
    for name, args in PLANTS.items():
        make(name, *args)
