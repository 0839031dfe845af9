#!/usr/bin/env python3
"""Generates ipa_step.csv: a simulated step test of the IPA force loop.

The plant is the paper's ARX force model (Emhemed et al. 2015, Eq. 4-5,
Ts = 0.01 s): A(q) y = B(q) u with
  A = 1 - 0.60870 q^-1 - 0.27020 q^-2 - 0.06021 q^-3
  B = 0.03938 q^-1 + 0.04506 q^-2 + 0.01286 q^-3.
The PWM duty cycle u steps from 0.61 % to 82 % at t = 0.5 s (the reaction-curve
test of paper sec. 4); y is the force in N, with white measurement noise of
0.3 N standard deviation (fixed seed) so that the file is reproducible.
Run with /usr/bin/python3 (numpy, scipy) from this directory.
"""
import numpy as np
from scipy import signal

Ts = 0.01
n = 301
t = np.arange(n) * Ts
u = np.where(t < 0.5 - 1e-9, 0.61, 82.0)
a = [1.0, -0.60870, -0.27020, -0.06021]
b = [0.0, 0.03938, 0.04506, 0.01286]
# Start in the steady state of u = 0.61: y0 = K * 0.61 with K = sum(b) / sum(a).
K = sum(b) / sum(a)
zi = signal.lfilter_zi(b, a) * 0.61
y = signal.lfilter(b, a, u, zi=zi)[0]
rng = np.random.default_rng(2015)
y = y + rng.normal(0.0, 0.3, n)
with open("ipa_step.csv", "w") as f:
    f.write("# Simulated step test of the IPA force loop (see gen_ipa_step.py):\n")
    f.write("# ARX model of Emhemed et al. 2015, Eq. 4-5, Ts = 0.01 s, static gain %.5f N/%%,\n" % K)
    f.write("# duty 0.61 -> 82 % at t = 0.5 s, measurement noise 0.3 N std.\n")
    f.write("t [s],u [%],y [N]\n")
    for ti, ui, yi in zip(t, u, y):
        f.write(f"{ti:.2f},{ui:g},{yi:.4f}\n")
