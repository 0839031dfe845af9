#!/usr/bin/python3
"""`pneumid commission` on the position twin and its variants (docs/position.md).

  /usr/bin/python3 bench/position_commission.py [BUILD_DIR]

For each variant of bench/position_variants.py it commissions the variant
itself (`commission --plant ipa-position:config=FILE`), then runs the written
controller.toml with `control --config` on the two staircases and the
sinusoid of that script, and prints one row of the table of docs/position.md:
what commission said (passes, or its first failure), the design's Kc, and
afterwards the worst step's overshoot, the slowest settling, the largest
|steady-state error| over both staircases, and the sinusoid's RMS error
(after its first 2 s). About 30 s on a 2-core machine.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import position_variants as pv  # noqa: E402  (VARIANTS, EXPERIMENTS, PNEUMID)

TMP = tempfile.mkdtemp(prefix="pneumid_position_commission_")


def control(config, setpoint, duration):
    out = os.path.join(TMP, "run.csv")
    r = subprocess.run([pv.PNEUMID, "control", "--config", config, "--setpoint", setpoint,
                        "--duration", str(duration), "--json", "-o", out],
                       capture_output=True, text=True, check=True)
    d = json.loads(r.stdout)
    if setpoint.startswith("sine"):
        data = np.genfromtxt(out, delimiter=",", names=True)
        keep = data["t"] >= 2.0
        return {"rms_mm": float(np.sqrt(np.mean((data["y"][keep] - data["r"][keep]) ** 2)) * 1e3)}
    steps = d["steps"]
    ts = [s["settling_time"] for s in steps]
    return {"overshoot": max(s["overshoot_percent"] or 0.0 for s in steps),
            "settling": None if None in ts else max(ts),
            "sse_mm": max(abs(s["steady_state_error"]) for s in steps) * 1e3}


def main():
    print("| twin | commission | design | overshoot | settling | abs sse | sine RMS |")
    print("|---|---|---|---|---|---|---|")
    for i, (variant, text) in enumerate(pv.VARIANTS.items()):
        toml = os.path.join(TMP, f"variant{i}.toml")
        with open(toml, "w") as f:
            f.write('[simulation]\nmode = "position"\n' + text)
        out = os.path.join(TMP, f"c{i}")
        c = subprocess.run([pv.PNEUMID, "commission", "--plant", "ipa-position:config=" + toml,
                            "-o", out, "--json"], capture_output=True, text=True)
        if c.returncode not in (0, 4):
            print(f"| {variant} | exit {c.returncode}: {c.stderr.strip()[:100]} |")
            continue
        cj = json.loads(c.stdout)
        kept = cj["attempts"][-1] if cj.get("attempts") else {}
        verdict = "passes" if cj.get("passed") else "; ".join(kept.get("failures", [])[:1])
        kc = cj.get("controller", {}).get("settings", {}).get("Kc")
        if kc is None:
            kc = kept.get("settings", {}).get("Kc")
        runs = [control(os.path.join(out, "controller.toml"), sp, dur)
                for sp, dur in pv.EXPERIMENTS.values()]
        stairs = [r for r in runs if "overshoot" in r]
        rms = [r["rms_mm"] for r in runs if "rms_mm" in r]
        settle = [r["settling"] for r in stairs]
        settling = "not settled" if None in settle else f"{max(settle):.2f} s"
        print(f"| {variant} | {verdict} | Kc = {kc:.0f} | "
              f"{max(r['overshoot'] for r in stairs):.2f} % | {settling} | "
              f"{max(r['sse_mm'] for r in stairs):.3f} mm | {max(rms):.2f} mm |", flush=True)


if __name__ == "__main__":
    main()
