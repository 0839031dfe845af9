"""Two cascaded tanks with square-root outflow and overflow, for the NARX
simulation-focus test (narx_test.cpp, NarxTest.SimulationFocus*).

  A1 dh1/dt = k_p u - k1 sqrt(h1)            (+ what overflows when h1 > h_max
  A2 dh2/dt = k1 sqrt(h1) - k2 sqrt(h2)        is lost; h2 is held at h_max)
  y = h2 + e,  e white, std 0.02

integrated with RK4 (20 steps per sample, zero-order-hold input), Ts = 5 s.
Input: random levels in [0.5, 5] held 8 .. 40 samples, one record per seed.
Estimation starts at rest at its first input; validation starts away from rest
(h1 = 1, h2 = 6). Writes data/two_tanks_est.csv and data/two_tanks_val.csv
(seeds 11, 12), data/two_tanks_31_est.csv and data/two_tanks_31_val.csv
(seeds 31, 32) and data/two_tanks_41_est.csv and data/two_tanks_41_val.csv
(seeds 41, 42).

Run: python3 gen_two_tanks.py (numpy).
"""
import os

import numpy as np

A1, A2, KP, K1, K2, HMAX, TS, N = 15.0, 12.0, 0.4, 0.5, 0.45, 10.0, 5.0, 1000


def deriv(h, u):
    h1, h2 = max(h[0], 0.0), max(h[1], 0.0)
    q1 = K1 * np.sqrt(h1)
    return np.array([(KP * u - q1) / A1, (q1 - K2 * np.sqrt(h2)) / A2])


def simulate(u, h):
    out = np.empty(len(u))
    dt = TS / 20
    for t, uk in enumerate(u):
        out[t] = h[1]
        for _ in range(20):
            a = deriv(h, uk)
            b = deriv(h + 0.5 * dt * a, uk)
            c = deriv(h + 0.5 * dt * b, uk)
            d = deriv(h + dt * c, uk)
            h = np.clip(h + dt / 6 * (a + 2 * b + 2 * c + d), 0.0, HMAX)
    return out


def levels(rng):
    u = []
    while len(u) < N:
        u += [rng.uniform(0.5, 5.0)] * int(rng.integers(8, 41))
    return np.array(u[:N])


def write(path, title, u, y, y_true):
    with open(path, "w") as f:
        f.write(f"# {title} (gen_two_tanks.py)\n")
        f.write("t,u,y,y_true\n")
        for k in range(N):
            f.write(f"{k * TS:.1f},{u[k]:.6f},{y[k]:.6f},{y_true[k]:.6f}\n")


def main():
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
    # Records 11/12 (two_tanks_*.csv), 31/32 and 41/42 (two_tanks_31_*.csv,
    # two_tanks_41_*.csv), the 41/42 validation visiting outputs below the
    # estimation record's.
    for name, seed, start in (("est", 11, None), ("val", 12, (1.0, 6.0)),
                              ("31_est", 31, None), ("31_val", 32, (1.0, 6.0)),
                              ("41_est", 41, None), ("41_val", 42, (1.0, 6.0))):
        rng = np.random.default_rng(seed)
        u = levels(rng)
        if start is None:  # at rest at u(0): KP u = K1 sqrt(h1) = K2 sqrt(h2)
            start = ((KP * u[0] / K1) ** 2, (KP * u[0] / K2) ** 2)
        y_true = simulate(u, np.array(start, dtype=float))
        y = y_true + 0.02 * rng.standard_normal(N)
        write(os.path.join(here, f"two_tanks_{name}.csv"),
              f"two tanks, sqrt outflow, overflow at {HMAX}, Ts {TS} s, {name}", u, y, y_true)


if __name__ == "__main__":
    main()
