#!/usr/bin/python3
"""Position loops on the position twin and its variants (docs/position.md).

  /usr/bin/python3 bench/position_variants.py [BUILD_DIR] [--json]

For each twin variant (the position rig; Coulomb and static friction x1.5 with
the mass x2; LuGre friction; a 0.02 mm encoder with 20 um noise) and each
experiment (the issue's staircase 20/70/40/85/30 mm with 2.5 s dwell, another
staircase with 1.5 s dwell and steps of 15-50 mm, a 0.5 Hz sinusoid of 20 mm)
it runs `pneumid control` with each controller and prints the worst step's
overshoot, settling time (2 % band), |steady-state error| and ripple, or the
RMS tracking error of the sinusoid. Targets: overshoot <= 2 %, settling <=
1.0 s, |sse| <= 0.1 mm (0.2 mm for the heavy variant), RMS <= 1 mm.
"""
import json
import os
import subprocess
import sys
import tempfile

BUILD = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("-") else "build"
PNEUMID = os.path.join(BUILD, "pneumid")
TMP = tempfile.mkdtemp(prefix="pneumid_position_")

VARIANTS = {
    "rig": "",
    "friction x1.5, mass x2": "[mechanics]\ncoulomb_friction = 9.0\nstatic_friction = 13.5\nmass = 2.0\n",
    "LuGre": "[mechanics]\nlugre_stiffness = 1.0e6\nlugre_damping = 1000.0\n",
    "encoder 0.02 mm": "[sensors]\nposition_resolution = 2.0e-5\nposition_noise = 2.0e-5\n",
    "friction x2, mass x3": "[mechanics]\ncoulomb_friction = 12.0\nstatic_friction = 18.0\nmass = 3.0\n",
    "supply 0.4 MPa, dead volumes x3": (
        "[supply]\npressure = 4.0e5\n[cylinder]\ndead_volume_a = 3.0e-5\ndead_volume_b = 3.0e-5\n"),
    "valves x1.5, delays x2": (
        "[valves]\ninlet_conductance = 1.5e-9\nexhaust_conductance = 1.8e-9\n"
        "open_delay = 6.0e-4\nclose_delay = 1.0e-3\n"),
}
EXPERIMENTS = {
    "staircase 20/70/40/85/30 mm, 2.5 s": ("staircase:levels=0.02 0.07 0.04 0.085 0.03,dwell=2.5", 12.5),
    "staircase 60/15/45/95/75/25 mm, 1.5 s": (
        "staircase:levels=0.06 0.015 0.045 0.095 0.075 0.025,dwell=1.5",
        9.0,
    ),
    "sine 0.5 Hz, 20 mm": ("sine:from=0.03,to=0.07,frequency=0.5", 8.0),
}
# The controllers: a PD on an integrating model sampled once per PWM period,
# its input modulated across the valves' dead band (--input-gaps plant), with
# the velocity feed-forward 1/Ki + Kc Td of the model (the default); and the
# first PD (100 Hz, no modulation, no feed-forward) as the baseline; an MPC
# without a disturbance model (the plant's integrator removes the offset; the
# input disturbance model adds integral action, which hunts under stick-slip)
# and a GPC (integral action through its CARIMA model) on the same model.
CONTROLLERS = {
    "none (PD at 100 Hz, no modulation, no feed-forward)": [
        "--controller", "pid", "--Kc", "3000", "--Td", "0.02", "--Kff", "0", "--input-gaps", "none"],
    "PD at 300 Hz + dead-band modulation + velocity feed-forward": [
        "--controller", "pid", "--Kc", "6000", "--Td", "0.04", "--input-gaps", "plant",
        "--Ts", repr(1.0 / 300.0)],
    "MPC (no disturbance model) at 300 Hz + modulation": [
        "--controller", "mpc", "--rule", "explicit", "--P", "40", "--M", "5", "--lambda", "1e-5",
        "--disturbance", "none", "--measurement-noise", "1e-10", "--state-noise", "1e-6",
        "--input-gaps", "plant", "--Ts", repr(1.0 / 300.0)],
    "GPC at 300 Hz + modulation": [
        "--controller", "gpc", "--rule", "explicit", "--P", "40", "--M", "5", "--lambda", "1e-5",
        "--input-gaps", "plant", "--Ts", repr(1.0 / 300.0)],
}
MODEL = os.environ.get("POSITION_MODEL", "tf:num=0.004,den=1 0")  # integrator, (m/s) per %: what the PD is designed on


def run(variant, setpoint, duration, args):
    path = os.path.join(TMP, "variant.toml")
    with open(path, "w") as f:
        f.write('[simulation]\nmode = "position"\n' + VARIANTS[variant])
    out = os.path.join(TMP, "run.csv")
    cmd = [PNEUMID, "control", "--model", MODEL, "--plant", "ipa-position:config=" + path,
           "--setpoint", setpoint, "--duration", str(duration), "--json", "-o", out] + args
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if r.returncode != 0:
        return {"error": r.stderr.strip()}
    d = json.loads(r.stdout)
    res = {}
    if setpoint.startswith("sine"):
        import numpy as np

        data = np.genfromtxt(out, delimiter=",", names=True)
        keep = data["t"] >= 2.0  # after the first period and a half
        res["rms_mm"] = float(np.sqrt(np.mean((data["y"][keep] - data["r"][keep]) ** 2)) * 1e3)
        return res
    steps = d["steps"]
    res["overshoot_percent"] = max(s["overshoot_percent"] or 0.0 for s in steps)
    ts = [s["settling_time"] for s in steps]
    res["settling_s"] = None if None in ts else max(ts)
    res["sse_mm"] = max(abs(s["steady_state_error"]) for s in steps) * 1e3
    res["ripple_mm"] = max(s["ripple"] for s in steps) * 1e3
    return res


def main():
    table = []
    for variant in VARIANTS:
        for name, (sp, duration) in EXPERIMENTS.items():
            for cname, args in CONTROLLERS.items():
                r = run(variant, sp, duration, args)
                r.update({"variant": variant, "experiment": name, "controller": cname})
                table.append(r)
                if "--json" in sys.argv:
                    continue
                if "error" in r:
                    line = "error: " + r["error"]
                elif "rms_mm" in r:
                    line = f"RMS {r['rms_mm']:.3f} mm"
                else:
                    ts = "not settled" if r["settling_s"] is None else f"{r['settling_s']:.2f} s"
                    line = (f"os {r['overshoot_percent']:5.2f} %, settling {ts}, "
                            f"|sse| {r['sse_mm']:.3f} mm, ripple {r['ripple_mm']:.3f} mm")
                print(f"{variant:24s} {name:40s} {cname:36s} {line}", flush=True)
    if "--json" in sys.argv:
        print(json.dumps(table, indent=1))


if __name__ == "__main__":
    main()
