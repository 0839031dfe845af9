#!/usr/bin/python3
"""The commissioned position loop on the twin (docs/position.md).

  /usr/bin/python3 scripts/position_loop_figure.py BUILD_DIR OUT_DIR

Runs `pneumid commission --plant ipa-position`, then the controller.toml it
wrote with `pneumid control --config` on a staircase (60/15/45/95/75/25 mm,
1.5 s dwell) and on a 0.5 Hz sinusoid of 20 mm, and writes
OUT_DIR/position-loop.png: set-point and position (mm), the tracking error
(mm) and the signed valve command (%).
"""
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

BUILD, OUT = sys.argv[1], sys.argv[2]
PNEUMID = os.path.join(BUILD, "pneumid")
TMP = tempfile.mkdtemp(prefix="pneumid_position_loop_")


def run(*args):
    subprocess.run([PNEUMID, *args], check=True, capture_output=True, text=True)


run("commission", "--plant", "ipa-position", "-o", os.path.join(TMP, "c"))
config = os.path.join(TMP, "c", "controller.toml")
runs = [("staircase 60/15/45/95/75/25 mm", "staircase:levels=0.06 0.015 0.045 0.095 0.075 0.025,dwell=1.5", 9.0),
        ("sinusoid 0.5 Hz, 20 mm", "sine:from=0.03,to=0.07,frequency=0.5", 6.0)]
fig, axes = plt.subplots(3, 2, figsize=(12, 8), sharex="col")
for col, (title, setpoint, duration) in enumerate(runs):
    csv = os.path.join(TMP, f"run{col}.csv")
    run("control", "--config", config, "--setpoint", setpoint, "--duration", str(duration), "-o", csv)
    d = np.genfromtxt(csv, delimiter=",", names=True)
    ax = axes[0, col]
    ax.plot(d["t"], 1e3 * d["r"], "k--", lw=1, label="set-point")
    ax.plot(d["t"], 1e3 * d["y"], lw=1.2, label="position")
    ax.set_ylabel("x [mm]")
    ax.set_title(f"commissioned PD: {title}")
    ax.legend(loc="best")
    axes[1, col].plot(d["t"], 1e3 * (d["r"] - d["y"]), lw=1)
    axes[1, col].set_ylim(-1.5, 1.5)
    axes[1, col].set_ylabel("r - x [mm]")
    axes[2, col].plot(d["t"], d["u"], lw=0.6)
    axes[2, col].set_ylabel("command u [%]")
    axes[2, col].set_xlabel("time t [s]")
    for ax in axes[:, col]:
        ax.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(os.path.join(OUT, "position-loop.png"), dpi=100)
print(os.path.join(OUT, "position-loop.png"))
