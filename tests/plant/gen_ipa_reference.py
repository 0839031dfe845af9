#!/usr/bin/python3
"""Independent reference for tests/plant/ipa_reference_test.cpp.

Chamber-A pressure of the IPA in force mode, averaged PWM mode, default
parameters (include/pneumid/plant/ipa_simulator.hpp), written out again here
from the equations (Richer & Hurmuzlu 2000 energy equation, ISO 6358 flow) and
integrated with scipy's Radau solver at tight tolerances.
Run: /usr/bin/python3 tests/plant/gen_ipa_reference.py
"""
import numpy as np
from scipy.integrate import solve_ivp

patm = 101325.0
ps = 0.6e6 + patm
T = 293.15
R = 287.0
rho0, T0 = 1.185, 293.15
bore = 0.017
Aa = np.pi / 4 * bore**2
Va = 18.1e-6 + Aa * 0.05
Cin, Cout, b, rl = 0.08e-8, 0.24e-8, 0.3, 0.999
a_in, a_out = 1.4, 1.0
Tpwm, t_open, t_close, t_min = 1 / 50.0, 0.002, 0.001, 0.002


def iso(C, pu, pd):
    if pd >= pu:
        return 0.0
    base = C * rho0 * pu * np.sqrt(T0 / T)
    r = pd / pu
    if r <= b:
        return base
    phi = lambda x: np.sqrt(1 - ((x - b) / (1 - b)) ** 2)
    if r > rl:
        return base * phi(rl) * (1 - r) / (1 - rl)
    return base * phi(r)


def fraction(w):
    if w >= Tpwm:
        return 1.0
    if w <= 0 or w < t_min:
        return 0.0
    return min(max((w - t_open + t_close) / Tpwm, 0.0), 1.0)


for duty in (60.0, 82.0):
    d = duty / 100
    fi, fo = fraction(d * Tpwm), fraction((1 - d) * Tpwm)

    def rhs(t, y):
        p = y[0]
        m_in = fi * iso(Cin, ps, p) + fo * iso(Cout, patm, p)
        m_out = fi * iso(Cin, p, ps) + fo * iso(Cout, p, patm)
        return [R * T / Va * (a_in * m_in - a_out * m_out)]

    times = [0.02, 0.05, 0.1, 0.2, 0.4, 1.0, 2.0]
    sol = solve_ivp(rhs, (0, 2.0), [patm], method="Radau", rtol=1e-11, atol=1e-6,
                    t_eval=times)
    print(f"// duty {duty} %: (t [s], p_a [Pa])")
    print(f"{{{duty}, {{" + ", ".join(f"{{{t}, {p:.6f}}}" for t, p in zip(sol.t, sol.y[0])) + "}},")
