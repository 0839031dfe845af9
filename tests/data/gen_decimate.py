#!/usr/bin/env python3
"""Reference values for preprocess_test.cpp (Decimate).

Decimate(x, q) with the default options equals
scipy.signal.sosfiltfilt(butter(8, 0.8 / q, output='sos'), x)[::q].
Run with /usr/bin/python3 (numpy, scipy); paste the output into the test.
"""
import numpy as np
from scipy import signal

N, q = 120, 4
k = np.arange(N)
x = np.sin(0.05 * k) + 0.5 * np.sin(2.5 * k) + 0.01 * k + (k >= 40) * 1.5
sos = signal.butter(8, 0.8 / q, output='sos')
y = signal.sosfiltfilt(sos, x)[::q]
print(f"// scipy {__import__('scipy').__version__}: N = {N}, q = {q}")
print("const std::vector<double> kDecimated = {")
print(",\n".join("    " + ", ".join(f"{v:.17g}" for v in y[i:i + 3]) for i in range(0, len(y), 3)) + "};")

# Order 4, cutoff 0.5, q = 3 on the same signal.
sos = signal.butter(4, 0.5 / 3, output='sos')
y = signal.sosfiltfilt(sos, x)[::3]
print("const std::vector<double> kDecimatedOrder4 = {")
print(",\n".join("    " + ", ".join(f"{v:.17g}" for v in y[i:i + 3]) for i in range(0, len(y), 3)) + "};")
