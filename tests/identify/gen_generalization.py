#!/usr/bin/python3
"""Recorded experiments of one known Hammerstein system for the
generalization tests (generalization_test.cpp): a model estimated on one
experiment must hold on experiments of other designs.

The system resembles the IPA force twin: a static map with a dead zone and
two steep rises (where a valve's pulse falls below its minimum width) followed
by a first-order lag with a dead time of two samples, Ts = 0.01 s:
    v(t) = f(u(t)),  f piecewise linear through U_KNOTS / F_VALUES,
    y(t) = 0.955 y(t-1) + 0.045 v(t-2) + e(t),  e white, std 0.3,
i.e. na = 1, nb = 1, nk = 2 and unit static gain. Every record starts at rest
at u = 0 (y = 0) with the input switched to its first level at t = 0, as a
plant run from standstill does (simulated with scipy.signal.lfilter,
independently of pneumid).

Records (columns t,u,y,y_true):
  gen_est.csv        staircase 5 15 25 .. 95 60 30 80 10 50 %, 2 s per level
  gen_val_stairs.csv staircase 40 70 20 95 55 30 85 47 %, 1.5 s per level
  gen_val_prbs.csv   7 random levels in [18, 82] %, 0.5 s clock, 20 s (seeded)
  gen_val_gap.csv    staircase 25 90 12 60 35 75 50 8 65 %, 1.2 s per level:
                     90 and 12 lie where gen_est.csv leaves the map undetermined
  gen_est_first_high.csv  staircase 75 20 50 35 95 65 5 85 45 25 60 40 15 10 30 %, 1.3 s per
                     level: its first level, switched on from rest at t = 0, is
                     visited only while the output rises from 0

Run from the repository root:
    /usr/bin/python3 tests/identify/gen_generalization.py
"""
import os

import numpy as np
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))
TS = 0.01
U_KNOTS = np.array([0.0, 12.0, 15.0, 30.0, 50.0, 70.0, 85.0, 88.0, 100.0])
F_VALUES = np.array([0.0, 0.0, 15.0, 26.0, 56.0, 107.0, 135.0, 193.0, 193.0])
POLE, NK, NOISE = 0.955, 2, 0.3


def staircase(levels, samples):
    return np.repeat(np.asarray(levels, dtype=float), samples)


def prbs_levels(low, high, count, clock, n, seed):
    rng = np.random.default_rng(seed)
    values = np.linspace(low, high, count)
    return np.round(np.repeat(rng.choice(values, n // clock + 1), clock)[:n], 6)


def respond(u):
    """From rest at u = 0: v = f(u), y = G v with G = (1 - p) q^-nk / (1 - p q^-1)."""
    v = np.interp(u, U_KNOTS, F_VALUES)
    b = np.zeros(NK + 1)
    b[NK] = 1.0 - POLE
    return signal.lfilter(b, [1.0, -POLE], v)


def write(name, u, seed, what):
    y_true = respond(u)
    y = y_true + np.random.default_rng(seed).normal(0.0, NOISE, len(u))
    t = TS * np.arange(len(u))
    path = os.path.join(HERE, "data", name + ".csv")
    with open(path, "w") as fh:
        fh.write("# {}; Hammerstein f knots {} values {}, y(t) = {} y(t-1) + {:.3f} v(t-{}), "
                 "noise std {} (gen_generalization.py)\n".format(
                     what, list(U_KNOTS), list(F_VALUES), POLE, 1.0 - POLE, NK, NOISE))
        fh.write("t,u,y,y_true\n")
        for row in zip(t, u, y, y_true):
            fh.write("{:.2f},{:.6f},{:.9g},{:.12g}\n".format(*row))
    print("wrote", path)


def main():
    write("gen_est", staircase([5, 15, 25, 35, 45, 55, 65, 75, 85, 95, 60, 30, 80, 10, 50], 200),
          101, "estimation staircase")
    write("gen_val_stairs", staircase([40, 70, 20, 95, 55, 30, 85, 47], 150), 102,
          "validation staircase")
    write("gen_val_prbs", prbs_levels(18, 82, 7, 50, 2000, 103), 104,
          "validation multi-level PRBS")
    write("gen_val_gap", staircase([25, 90, 12, 60, 35, 75, 50, 8, 65], 120), 105,
          "validation staircase through the undetermined intervals")
    write("gen_est_first_high", staircase([75, 20, 50, 35, 95, 65, 5, 85, 45, 25, 60, 40, 15, 10, 30],
                                         130), 106,
          "estimation staircase whose first level lies far from the rest at u = 0")


if __name__ == "__main__":
    main()
