#!/usr/bin/python3
"""Reference tangents (Ziegler-Nichols) of the paper's ARX model, for
tests/identify/graphical_methods_test.cpp.

1. Continuous equivalent (paper Eq. 6, zoh d2c, coefficients of
   docs/paper.md, reference value 3), unit step on a 5 us grid: the tangent at the
   point of largest slope.
2. The ARX model's own sampled unit step (Ts = 0.01 s): the steepest
   sample-to-sample segment, which reproduces docs/paper.md, reference value 4
   (L = 0.0043 s, T = 0.2315 s).
"""
import numpy as np
from scipy import signal

num = [6.10237, -91.9458, 520011.9]
den = [1, 280.9917, 74994.63, 325421.7]
K = num[-1] / den[-1]
t = np.linspace(0, 1.5, 300001)
_, y = signal.step((num, den), T=t)
d = np.gradient(y, t)
i = np.argmax(d)
S = d[i] / K
print("continuous: t_i = %.5f s, L = %.5f s, T = %.5f s" % (t[i], t[i] - y[i] / K / S, 1 / S))

b = [0, 0.03938, 0.04506, 0.01286]
a = [1, -0.60870, -0.27020, -0.06021]
r = signal.lfilter(b, a, np.ones(400)) / (sum(b) / sum(a))
ts = np.arange(400) * 0.01
s = np.diff(r) / 0.01
k = np.argmax(s)
print("sampled (steepest segment %d-%d): L = %.5f s, T = %.5f s" %
      (k, k + 1, ts[k] - r[k] / s[k], 1 / s[k]))
