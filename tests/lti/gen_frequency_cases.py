#!/usr/bin/python3
"""Reference margins and Bode values for tests/lti/frequency_test.cpp.

Run: /usr/bin/python3 tests/lti/gen_frequency_cases.py
Crossovers are solved with scipy.optimize.brentq on the closed-form magnitude
and phase of each model; Bode values come from scipy.signal.freqresp/dfreqresp.
"""
import numpy as np
from scipy import optimize, signal

# 1 / (s (s + 1) (s + 2)): textbook example, phase crossover at sqrt(2), GM = 6.
mag = lambda w: 1.0 / (w * np.hypot(w, 1.0) * np.hypot(w, 2.0))
phase = lambda w: -np.pi / 2 - np.arctan(w) - np.arctan(w / 2)
wpc = optimize.brentq(lambda w: phase(w) + np.pi, 0.1, 10)
wgc = optimize.brentq(lambda w: mag(w) - 1, 0.01, 10)
print("type1: wpc=%.15g gm=%.15g wgc=%.15g pm_deg=%.15g" % (wpc, 1 / mag(wpc), wgc,
      180 + np.degrees(phase(wgc))))

# Paper FOPDT 1.6 exp(-0.001 s) / (0.245 s + 1).
K, tau, theta = 1.6, 0.245, 0.001
mag = lambda w: K / np.hypot(w * tau, 1.0)
phase = lambda w: -np.arctan(w * tau) - w * theta
wpc = optimize.brentq(lambda w: phase(w) + np.pi, 10, 1e5)
wgc = optimize.brentq(lambda w: mag(w) - 1, 0.01, 100)
print("fopdt: wpc=%.15g gm=%.15g wgc=%.15g pm_deg=%.15g" % (wpc, 1 / mag(wpc), wgc,
      180 + np.degrees(phase(wgc))))

# Bode of (s + 2) / (s^2 + 0.4 s + 4) at a few frequencies (scipy.signal.freqresp).
w = np.array([0.1, 1.0, 2.0, 5.0, 30.0])
_, h = signal.freqresp(([1, 2], [1, 0.4, 4]), w)
print("bode_c mag:", ", ".join("%.15g" % v for v in np.abs(h)))
print("bode_c phase_deg:", ", ".join("%.15g" % v for v in np.degrees(np.unwrap(np.angle(h)))))

# Paper ARX model, Ts = 0.01 (scipy.signal.dfreqresp), w in rad/s.
b = [0.0, 0.03938, 0.04506, 0.01286]
a = [1.0, -0.60870, -0.27020, -0.06021]
wd = np.array([0.5, 5.0, 50.0, 300.0])
_, hd = signal.dfreqresp((b, a, 0.01), wd * 0.01)
print("bode_arx mag:", ", ".join("%.15g" % v for v in np.abs(hd)))
print("bode_arx phase_deg:", ", ".join("%.15g" % v for v in np.degrees(np.unwrap(np.angle(hd)))))
