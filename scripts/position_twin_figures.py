#!/usr/bin/python3
"""Figures of the position twin for docs/position.md.

  /usr/bin/python3 scripts/position_twin_figures.py BUILD_DIR OUT_DIR

writes OUT_DIR/position-step.png (open-loop command pulses: position, chamber
pressures) and OUT_DIR/position-breakaway.png (short pulses just above the
dead band: the rod force builds up while the piston sticks, and the piston
breaks away when the force reaches the static friction F_s), with the static Stribeck map (the
default) and with LuGre friction. Needs the Python module built in
BUILD_DIR/python and matplotlib.
"""
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(sys.argv[1], "python"))
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pneumid  # noqa: E402

OUT = sys.argv[2]
TS = 0.001
PATM = 101325.0
BORE, ROD = 0.020266, 0.006
AA = np.pi / 4 * BORE**2
AB = np.pi / 4 * (BORE**2 - ROD**2)


def plant(extra="", Ts=TS):
    path = os.path.join(tempfile.gettempdir(), "pneumid_position_fig.toml")
    with open(path, "w") as f:
        f.write('[simulation]\nmode = "position"\n' + extra)
    return pneumid.make_plant("ipa:config=" + path, Ts)


def run(p, command):
    x, pa, pb = [], [], []
    for u in command:
        p.advance(u)
        e = p.extras()
        x.append(e["x [m]"])
        pa.append(e["p_a [Pa]"])
        pb.append(e["p_b [Pa]"])
    return np.array(x), np.array(pa), np.array(pb)


def step_figure():
    t = np.arange(0, 3.0, TS)
    u = np.where((t >= 0.5) & (t < 0.8), 20.0, 0.0) + np.where((t >= 1.8) & (t < 2.1), -20.0, 0.0)
    x, pa, pb = run(plant(), u)
    fig, ax = plt.subplots(3, 1, sharex=True, figsize=(7, 6.5))
    ax[0].plot(t, u)
    ax[0].set_ylabel("command u [%]")
    ax[1].plot(t, x * 1e3)
    ax[1].set_ylabel("position x [mm]")
    ax[2].plot(t, (pa - PATM) / 1e5, label="chamber A")
    ax[2].plot(t, (pb - PATM) / 1e5, label="chamber B")
    ax[2].set_ylabel("pressure [bar gauge]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend()
    ax[0].set_title("Position twin: +20 % and -20 % for 0.3 s (the position rig)")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "position-step.png"), dpi=110)


def breakaway_figure():
    # One sample (three PWM periods) at 9.5 %, just above the dead band, every
    # 0.1 s: each adds a little gas to A and takes a little from B.
    Ts = 0.01
    t = np.arange(0, 3.0, Ts)
    u = np.where(np.arange(t.size) % 10 == 5, 9.5, 0.0)
    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(7, 5.5))
    for label, extra in [
        ("Stribeck map (default)", ""),
        ("LuGre, sigma0 = 1e6 N/m", "[mechanics]\nlugre_stiffness = 1.0e6\nlugre_damping = 1000.0\n"),
    ]:
        x, pa, pb = run(plant(extra, Ts), u)
        force = AA * (pa - PATM) - AB * (pb - PATM)
        ax[0].plot(t, force, label=label)
        ax[1].plot(t, (x - x[0]) * 1e3, label=label)
    ax[1].legend(fontsize=8)
    ax[0].axhline(9.0, color="r", ls="--", lw=0.8, label="F_s = 9 N")
    ax[0].axhline(6.0, color="gray", ls=":", lw=0.8, label="F_c = 6 N")
    ax[0].set_ylabel("pressure force on the piston [N]")
    ax[0].legend(fontsize=8)
    ax[1].set_ylabel("displacement [mm]")
    ax[1].set_xlabel("t [s]")
    ax[0].set_title("Breakaway: one 9.5 % sample every 0.1 s (dead band 9 %)")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "position-breakaway.png"), dpi=110)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    step_figure()
    breakaway_figure()
    print("figures written to", OUT)
