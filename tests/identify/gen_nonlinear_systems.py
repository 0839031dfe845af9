#!/usr/bin/python3
"""Recorded data of known nonlinear systems for the Hammerstein, Wiener and
NARX tests (hammerstein_test.cpp, narx_test.cpp).

The systems are simulated here with numpy / scipy.signal.lfilter,
independently of pneumid's own simulation. Inputs are random levels (uniform
in [0, 100], or on the grid 0, 5, .., 100 for the NARX system, each held 5..40
samples, seeded), outputs get white Gaussian
noise (seeded); y_true is the noise-free output.

Run from the repository root:
    /usr/bin/python3 tests/identify/gen_nonlinear_systems.py
writes tests/identify/data/{hammerstein,wiener,hw,narx}.csv (columns t,u,y,y_true).

Hammerstein and Wiener: the static map f through the knots U_KNOTS with values
F_VALUES (linear between knots, held beyond them) and the unit-gain linear part
    G(q) = (B1 q^-1 + B2 q^-2) / (1 + A1 q^-1 + A2 q^-2),  Ts = 0.01 s,
started in steady state at the first input sample:
    Hammerstein y = f(u0) + G (f(u) - f(u0));  Wiener y = f(u0 + G (u - u0)).
Hammerstein-Wiener (hw.csv): y = g(x), x = f_in(u0) + G (f_in(u) - f_in(u0)) with
the same G, the input map f_in through U_KNOTS with values HW_IN_VALUES (end
values equal to the end knots: pneumid's normalisation) and the output map g
through HW_OUT_KNOTS with values HW_OUT_VALUES; the input starts with 0 and 100
held 150 samples each, so that x covers [0, 100]; noise std 0.2.
NARX (Billings 2013, sec. 3.7 style polynomial model, u scaled to [-1, 1]
as u/50 - 1):
    y(t) = -0.605 y(t-1) - 0.163 y(t-2)^2 + 0.588 v(t-1) - 0.240 v(t-2) + e(t),
with v = u/50 - 1 and the measured u given in its raw units; noise std 0.01
added to the output equation (NARX noise model) and y_true the noise-free run.
"""
import os

import numpy as np
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))

TS = 0.01
U_KNOTS = np.array([0.0, 20.0, 40.0, 60.0, 80.0, 100.0])
F_VALUES = np.array([10.0, 14.0, 40.0, 80.0, 120.0, 128.0])
A1, A2 = -1.7, 0.72  # poles 0.9 and 0.8
B1 = 0.012
B2 = (1.0 + A1 + A2) - B1  # unit static gain: B(1) = A(1) = 0.02
N = 4000
HW_IN_VALUES = np.array([0.0, 6.0, 24.0, 55.0, 85.0, 100.0])
HW_OUT_KNOTS = np.array([0.0, 20.0, 40.0, 60.0, 80.0, 100.0])
HW_OUT_VALUES = np.array([5.0, 40.0, 68.0, 88.0, 101.0, 108.0])


def levels(seed, n, grid=False):
    """Random levels; rounded to the 6 decimals written to the file (so that
    y_true is the response to the recorded input), or on the grid 0, 5, ..,
    100 starting with 0 and 100 (the input range is then exactly [0, 100])."""
    rng = np.random.default_rng(seed)
    u = np.empty(n)
    k = 0
    first = [0.0, 100.0] if grid else []
    while k < n:
        hold = rng.integers(5, 41)
        if first:
            u[k:k + hold] = first.pop(0)
        elif grid:
            u[k:k + hold] = 5.0 * rng.integers(0, 21)
        else:
            u[k:k + hold] = rng.uniform(0.0, 100.0)
        k += hold
    return np.round(u, 6)


def f(x):
    return np.interp(x, U_KNOTS, F_VALUES)


def unit_gain_from_rest(x):
    """x0 + G (x - x0), G started at rest."""
    x0 = x[0]
    return x0 + signal.lfilter([0.0, B1, B2], [1.0, A1, A2], x - x0)


def write(name, u, y_true, noise, seed, header):
    rng = np.random.default_rng(seed)
    y = y_true + rng.normal(0.0, noise, len(u))
    t = TS * np.arange(len(u))
    path = os.path.join(HERE, "data", name + ".csv")
    with open(path, "w") as fh:
        fh.write("# " + header + "\n")
        fh.write("t,u,y,y_true\n")
        for row in zip(t, u, y, y_true):
            fh.write("{:.2f},{:.6f},{:.9g},{:.12g}\n".format(*row))
    print("wrote", path)


def main():
    u = levels(11, N)
    write("hammerstein", u, unit_gain_from_rest(f(u)), 0.2, 12,
          "Hammerstein: f knots {} values {}; G = ({} q^-1 + {:.6g} q^-2) / (1 {} q^-1 + {} q^-2);"
          " noise std 0.2 (gen_nonlinear_systems.py)".format(
              list(U_KNOTS), list(F_VALUES), B1, B2, A1, A2))
    u = levels(21, N)
    write("wiener", u, f(unit_gain_from_rest(u)), 0.2, 22,
          "Wiener: same f and G as hammerstein.csv; noise std 0.2 (gen_nonlinear_systems.py)")

    u = np.concatenate([np.zeros(150), np.full(150, 100.0), levels(41, N - 300)])
    x = unit_gain_from_rest(np.interp(u, U_KNOTS, HW_IN_VALUES))
    write("hw", u, np.interp(x, HW_OUT_KNOTS, HW_OUT_VALUES), 0.2, 42,
          "Hammerstein-Wiener: f_in knots {} values {}, g knots {} values {}; G as hammerstein.csv;"
          " noise std 0.2 (gen_nonlinear_systems.py)".format(
              list(U_KNOTS), list(HW_IN_VALUES), list(HW_OUT_KNOTS), list(HW_OUT_VALUES)))

    u = levels(31, 2000, grid=True)
    v = u / 50.0 - 1.0
    rng = np.random.default_rng(32)
    e = rng.normal(0.0, 0.01, len(u))
    y = np.zeros(len(u))
    y_true = np.zeros(len(u))
    for t in range(2, len(u)):
        y[t] = -0.605 * y[t - 1] - 0.163 * y[t - 2] ** 2 + 0.588 * v[t - 1] - 0.240 * v[t - 2] + e[t]
        y_true[t] = (-0.605 * y_true[t - 1] - 0.163 * y_true[t - 2] ** 2 + 0.588 * v[t - 1]
                     - 0.240 * v[t - 2])
    path = os.path.join(HERE, "data", "narx.csv")
    with open(path, "w") as fh:
        fh.write("# NARX y(t) = -0.605 y(t-1) - 0.163 y(t-2)^2 + 0.588 v(t-1) - 0.240 v(t-2) + e(t),"
                 " v = u/50 - 1, e std 0.01 (gen_nonlinear_systems.py)\n")
        fh.write("t,u,y,y_true\n")
        for row in zip(TS * np.arange(len(u)), u, y, y_true):
            fh.write("{:.2f},{:.6f},{:.12g},{:.12g}\n".format(*row))
    print("wrote", path)


if __name__ == "__main__":
    main()
