#!/usr/bin/env python3
"""Generates the rig data the default IPA twin is calibrated to.

The paper's rig (Emhemed et al. 2015) is documented only through its models:
Eq. 4-5, the ARX(3,3,1) force model identified from the rig (Ts = 0.01 s),
  A = 1 - 0.60870 q^-1 - 0.27020 q^-2 - 0.06021 q^-3
  B = 0.03938 q^-1 + 0.04506 q^-2 + 0.01286 q^-3,
and Eq. 2 (FOPDT 1.6 / (0.245 s + 1) e^(-0.001 s)). The rig holds 0 N at the
duty 0.61 % (chamber vented, inside the valves' dead band), so Eq. 5 is
driven by u - 0.61 %. Two experiments, noise-free:
  eq5_step.csv   the paper's step: 0.61 -> 82 % at t = 0.5 s, 3 s;
  eq5_prbs.csv   a maximum-length PRBS between 0.61 and 82 % (order 8,
                 clock 0.05 s, scipy.signal.max_len_seq), from t = 0.5 s, 13.3 s;
  eq5_prbs_long.csv  the same PRBS repeated, from t = 0.5 s to 30 s (the
                 sequence of pneumid's prbs:low=0.61,high=82,order=8,clock=0.05,at=0.5).
Columns t [s], u [%] (PWM duty), y [N] (force). Run with /usr/bin/python3
(numpy, scipy) from this directory; docs/simulator.md ("The default twin")
uses them with `pneumid calibrate`.
"""
import numpy as np
from scipy import signal

Ts = 0.01
a = [1.0, -0.60870, -0.27020, -0.06021]
b = [0.0, 0.03938, 0.04506, 0.01286]
u_low, u_high, t0 = 0.61, 82.0, 0.5


def write(name, u, comment):
    t = np.arange(len(u)) * Ts
    y = signal.lfilter(b, a, u - u_low)
    with open(name, "w") as f:
        f.write("# Rig data from the paper's ARX model, Eq. 5 of Emhemed et al. 2015 "
                "(gen_rig_data.py):\n")
        f.write("# y = Eq. 5 driven by u - 0.61 %%, noise-free; %s\n" % comment)
        f.write("t [s],u [%],y [N]\n")
        for ti, ui, yi in zip(t, u, y):
            f.write("%.2f,%.10g,%.10g\n" % (ti, ui, yi))


n = 301
t = np.arange(n) * Ts
write("eq5_step.csv", np.where(t < t0 - 1e-9, u_low, u_high),
      "the paper's step 0.61 -> 82 % at 0.5 s")

order, clock = 8, 5  # clock in samples
bits = signal.max_len_seq(order)[0]
prbs = np.repeat(np.where(bits > 0, u_high, u_low), clock)
lead = int(round(t0 / Ts))
u = np.concatenate([np.full(lead, u_low), prbs, np.full(50, u_low)])
write("eq5_prbs.csv", u, "PRBS 0.61/82 %%, order %d, clock %g s, from 0.5 s" % (order, clock * Ts))

n_long = 3001
u_long = np.concatenate([np.full(lead, u_low), np.tile(prbs, 3)])[:n_long]
write("eq5_prbs_long.csv", u_long,
      "PRBS 0.61/82 %%, order %d, clock %g s, from 0.5 s, repeated to 30 s" % (order, clock * Ts))
