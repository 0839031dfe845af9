#!/usr/bin/env python3
"""`pneumid commission` on IPA twin variants, measured on the targets' scenario.

For each variant (valves +-30 %, dead volume +-20 %, supply 0.5 MPa, sensor
filter 0, 0.05, 0.1 and 0.25 s, one sample of transport delay, three twins
with several changes at once, the chamber-lag twin and the default twin) the
script writes the variant's TOML from
config/ipa_default.toml, runs `pneumid commission --plant ipa --plant-config
VARIANT -o DIR --json` (wall time measured), then runs the written
controller.toml with `pneumid control --config` on a staircase across
10..180 N in both directions (dwell 2 s) with a -15 N load step at 17 s, and
the paper's DMC (fopdt-paper, shridhar-cooper) on the same scenario. It
prints one table row per variant: worst-step overshoot, the slowest step's
settling time, the largest steady-state ripple (peak to peak, % of the
set-point, and at levels of 20 N and above), the largest |steady-state
error|, IAE over the DMC's, commission's wall time and plant time, and the
targets missed (for the ripple, with the sensor's noise at rest, peak to
peak, as a share of that level: at 10 N it alone is above 2 %).

With `--random SEED`, `--count N` variants are drawn instead, every
parameter at once from the issue's ranges (inlet and exhaust conductance
x0.7..1.3, each dead volume x0.8..1.2, supply 0.5..0.6 MPa, sensor filter
0..0.25 s, 0 or 1 sample of transport delay), each measured on a staircase
of its own (seven levels drawn from 10..180 N in steps of 5 N, dwell 2 s,
-15 N load step in the last second); the row names the variant and its
levels.

Usage: /usr/bin/python3 bench/commission_variants.py build/pneumid [--only NAME]
       /usr/bin/python3 bench/commission_variants.py build/pneumid --random 7 --count 8
"""
import argparse
import json
import pathlib
import random
import re
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENARIO = ["--setpoint", "staircase:levels=10 50 100 150 180 120 60 10,dwell=2",
            "--duration", "18", "--load-step", "at=17,size=-15"]

# name -> {key: factor or ("=", value)} applied to config/ipa_default.toml
VARIANTS = {
    "default": {},
    "valves +30 %": {"inlet_conductance": 1.3, "exhaust_conductance": 1.3},
    "valves -30 %": {"inlet_conductance": 0.7, "exhaust_conductance": 0.7},
    "dead volume +20 %": {"dead_volume_a": 1.2, "dead_volume_b": 1.2},
    "dead volume -20 %": {"dead_volume_a": 0.8, "dead_volume_b": 0.8},
    "supply 0.5 MPa": {"pressure": ("=", 0.5e6)},
    "sensor filter 0 s": {"pressure_filter_time_constant": ("=", 0.0)},
    "sensor filter 0.05 s": {"pressure_filter_time_constant": ("=", 0.05)},
    "sensor filter 0.1 s": {"pressure_filter_time_constant": ("=", 0.1)},
    "sensor filter 0.25 s": {"pressure_filter_time_constant": ("=", 0.25)},
    "delay 1 sample": {"transport_delay_samples": ("=", 1)},
    "chamber-lag twin": "config/ipa_chamber_lag.toml",
    # several changes at once
    "mixed A": {"inlet_conductance": 1.2, "exhaust_conductance": 0.85, "dead_volume_a": 0.9,
                "pressure": ("=", 0.55e6), "pressure_filter_time_constant": ("=", 0.15),
                "transport_delay_samples": ("=", 1)},
    "mixed B": {"inlet_conductance": 0.75, "exhaust_conductance": 1.25, "dead_volume_a": 1.15,
                "dead_volume_b": 1.15, "pressure": ("=", 0.58e6),
                "pressure_filter_time_constant": ("=", 0.07)},
    "mixed C": {"inlet_conductance": 1.3, "dead_volume_a": 0.8, "pressure": ("=", 0.52e6),
                "pressure_filter_time_constant": ("=", 0.2), "transport_delay_samples": ("=", 1)},
}


def write_variant(spec, path):
    if isinstance(spec, str):
        path.write_text((ROOT / spec).read_text())
        return
    text = (ROOT / "config/ipa_default.toml").read_text()
    for key, change in spec.items():
        pattern = re.compile(rf"^({re.escape(key)}\s*=\s*)([-+0-9.eE]+)", re.M)
        m = pattern.search(text)
        if not m:
            sys.exit(f"commission_variants: no key {key} in config/ipa_default.toml")
        value = change[1] if isinstance(change, tuple) else float(m.group(2)) * change
        text = pattern.sub(lambda mm: mm.group(1) + repr(value), text, count=1)
    path.write_text(text)


def random_variants(seed, count):
    """count variants with every parameter drawn from the issue's ranges, and
    a staircase of seven levels of 10..180 N for each: (variants, scenarios)."""
    rng = random.Random(seed)
    variants, scenarios = {}, {}
    for _ in range(count):
        spec = {"inlet_conductance": rng.uniform(0.7, 1.3),
                "exhaust_conductance": rng.uniform(0.7, 1.3),
                "dead_volume_a": rng.uniform(0.8, 1.2),
                "dead_volume_b": rng.uniform(0.8, 1.2),
                "pressure": ("=", round(rng.uniform(0.5e6, 0.6e6), -3)),
                "pressure_filter_time_constant": ("=", round(rng.uniform(0.0, 0.25), 3)),
                "transport_delay_samples": ("=", rng.choice([0, 1]))}
        levels = [rng.choice(range(10, 181, 5)) for _ in range(7)]
        name = ("inlet x{:.2f}, exhaust x{:.2f}, dead volumes x{:.2f}/x{:.2f}, {:.3f} MPa, "
                "filter {:.3f} s, delay {}; levels {}").format(
                    spec["inlet_conductance"], spec["exhaust_conductance"],
                    spec["dead_volume_a"], spec["dead_volume_b"], spec["pressure"][1] / 1e6,
                    spec["pressure_filter_time_constant"][1],
                    spec["transport_delay_samples"][1], " ".join(map(str, levels)))
        variants[name] = spec
        n = len(levels)
        scenarios[name] = ["--setpoint", "staircase:levels={},dwell=2".format(
            " ".join(map(str, levels))), "--duration", str(2 * n),
            "--load-step", "at={},size=-15".format(2 * n - 1)]
    return variants, scenarios


def metrics(j):
    steps = [s for s in j["steps"] if s["time"] > 0]
    ripple = [100 * s["ripple"] / abs(s["to"]) for s in steps if s["ripple"] is not None]
    ripple20 = [100 * s["ripple"] / abs(s["to"]) for s in steps
                if s["ripple"] is not None and abs(s["to"]) >= 20]
    settle = [s["settling_time"] if s["settled"] else float("inf") for s in steps]
    worst = max((s for s in steps if s["ripple"] is not None),
                key=lambda s: s["ripple"] / abs(s["to"]), default=None)
    return {
        "ripple_at": worst["to"] if worst else float("nan"),
        "overshoot": max(s["overshoot_percent"] for s in steps),
        "settling": max(settle),
        "ripple": max(ripple),
        "ripple20": max(ripple20),
        "sse": max(abs(s["steady_state_error"]) for s in steps),
        "iae": j["iae"],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pneumid")
    ap.add_argument("--only", default="")
    ap.add_argument("--scenario", default="",
                    help="another scenario for control --config and the DMC, e.g. "
                         "\"--setpoint staircase:levels=30 140 70,dwell=1.5 --duration 4.5\"")
    ap.add_argument("--extra", default="",
                    help="extra arguments for commission, e.g. \"--Ts 0.005\"")
    ap.add_argument("--random", type=int, default=None, metavar="SEED",
                    help="draw --count variants and scenarios from the issue's ranges")
    ap.add_argument("--count", type=int, default=8)
    args = ap.parse_args()
    scenario = args.scenario.split(" --") if args.scenario else []
    scenario = SCENARIO if not scenario else [
        a for i, s in enumerate(scenario)
        for a in (("--" if i else "") + s).split(" ", 1)]
    variants = VARIANTS
    scenarios = {}
    if args.random is not None:
        variants, scenarios = random_variants(args.random, args.count)
    print("| twin | chosen model | worst overshoot % | slowest settling s | ripple % (>= 20 N) "
          "| max abs sse N | IAE / DMC | commission wall s | plant time s | verdict |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, spec in variants.items():
            if args.only and args.only != name:
                continue
            scenario_of = scenarios.get(name, scenario)
            work = pathlib.Path(tmp) / f"{len(list(pathlib.Path(tmp).iterdir()))}"
            work.mkdir()
            toml = work / "twin.toml"
            write_variant(spec, toml)
            start = time.monotonic()
            c = subprocess.run([args.pneumid, "commission", "--plant", "ipa", "--plant-config",
                                str(toml), "-o", str(work / "c"), "--json",
                                *args.extra.split()],
                               capture_output=True, text=True)
            wall = time.monotonic() - start
            if c.returncode not in (0, 4):
                print(f"| {name} | - | commission exit {c.returncode}: {c.stderr.strip()[:120]} |")
                continue
            cj = json.loads(c.stdout)
            run = subprocess.run([args.pneumid, "control", "--config",
                                  str(work / "c" / "controller.toml"), *scenario_of, "--json"],
                                 capture_output=True, text=True, check=True)
            dmc = subprocess.run([args.pneumid, "control", "--controller", "dmc", "--model",
                                  "fopdt-paper", "--rule", "shridhar-cooper", "--plant",
                                  f"ipa:config={toml}", *scenario_of, "--json"],
                                 capture_output=True, text=True, check=True)
            m = metrics(json.loads(run.stdout))
            iae_dmc = json.loads(dmc.stdout)["iae"]
            missed = [what for what, bad in [
                ("overshoot", m["overshoot"] > 5), ("settling", m["settling"] > 0.5),
                ("ripple", m["ripple"] > 2), ("sse", m["sse"] > 0.5),
                ("IAE", m["iae"] > 0.7 * iae_dmc)] if bad]
            if "ripple" in missed:
                # The sensor's noise at rest, peak to peak, as % of the worst level.
                noise = 100 * cj["experiment"]["noise_peak_to_peak"] / abs(m["ripple_at"])
                missed[missed.index("ripple")] = (
                    f"ripple at {m['ripple_at']:.0f} N (noise at rest {noise:.2f} %)")
            verdict = "missed: " + ", ".join(missed) if missed else "all targets met"
            print(f"| {name} | {cj['chosen_model']} | {m['overshoot']:.2f} | {m['settling']:.3f} "
                  f"| {m['ripple']:.2f} ({m['ripple20']:.2f}) | {m['sse']:.2f} "
                  f"| {m['iae'] / iae_dmc:.3f} | {wall:.1f} | {cj['plant_time']:.1f} "
                  f"| {verdict} |", flush=True)


if __name__ == "__main__":
    main()
