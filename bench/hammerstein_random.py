#!/usr/bin/env python3
"""`pneumid identify -m hammerstein` (default options) on staircases of random
design, each validated on two records of other random designs.

Each case draws an estimation staircase on the default IPA twin and two
validation records, all with seeded sensor noise:
  - estimation: `--design dense` (the default) every 10 % from a random start
    of 3..7 % plus five random levels, shuffled; `--design sparse` 8..14 levels
    drawn from 3..97 %; a dwell of 1.2..2.5 s;
  - a staircase of 5..10 levels within the estimation's range, 0.8..2.0 s each;
  - a multi-level PRBS of 3..9 levels within that range, clock 0.3..1.0 s, 20 s.
It prints the simulation fit (`pneumid validate`, NRMSE %) on each, marked W
where `validate` warns that the record visits an input the estimation data
leave the map undetermined in, or leaves its range, and a summary: how many
fits reach 95 %, and how many of the others were warned about.

Usage: /usr/bin/python3 bench/hammerstein_random.py build/pneumid [--seed 11] [--count 10]
                                                            [--design dense|sparse]
"""
import argparse
import json
import random
import subprocess
import sys
import tempfile
import pathlib

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from hammerstein_variants import simulate  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pneumid")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--count", type=int, default=10)
    ap.add_argument("--design", choices=["dense", "sparse"], default="dense")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    fits = []
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp)
        for i in range(a.count):
            if a.design == "dense":
                levels = list(range(rng.randint(3, 7), 100, 10)) + [rng.randint(5, 95)
                                                                    for _ in range(5)]
                rng.shuffle(levels)
            else:
                levels = [rng.randint(3, 97) for _ in range(rng.randint(8, 14))]
            dwell = round(rng.uniform(1.2, 2.5), 1)
            est = f"staircase:levels={' '.join(map(str, levels))},dwell={dwell}"
            simulate(a.pneumid, None, est, len(levels) * dwell, rng.randint(1, 999),
                     d / "est.csv")
            r = subprocess.run([a.pneumid, "identify", str(d / "est.csv"), "-m", "hammerstein",
                                "-o", str(d / "h.json")], capture_output=True, text=True)
            if r.returncode != 0:
                print(f"{i}: identify failed: {r.stderr.strip()[-300:]}")
                continue
            lo, hi = min(levels), max(levels)
            v_levels = [rng.randint(lo, hi) for _ in range(rng.randint(5, 10))]
            v_dwell = round(rng.uniform(0.8, 2.0), 1)
            p_lo = rng.randint(lo, max(lo, 40))
            p_hi = rng.randint(min(60, hi), hi)
            records = [
                (f"staircase:levels={' '.join(map(str, v_levels))},dwell={v_dwell}",
                 len(v_levels) * v_dwell),
                (f"prbs-levels:low={p_lo},high={p_hi},levels={rng.randint(3, 9)},"
                 f"clock={round(rng.uniform(0.3, 1.0), 1)},seed={rng.randint(1, 99)}", 20.0),
            ]
            row = []
            for signal, duration in records:
                simulate(a.pneumid, None, signal, duration, rng.randint(1, 999), d / "val.csv")
                v = subprocess.run([a.pneumid, "validate", str(d / "h.json") + "#hammerstein",
                                    str(d / "val.csv"), "--json"], capture_output=True, text=True)
                res = json.loads(v.stdout) if v.returncode == 0 else {}
                fit = res.get("fit_percent")
                warned = any("undetermined" in w or "beyond" in w for w in res.get("warnings", []))
                fits.append((fit, warned))
                row.append(f"{'-' if fit is None else f'{fit:.1f}'}{' W' if warned else ''}"
                           f" ({signal})")
            print(f"{i}: {est}\n    {row[0]}\n    {row[1]}", flush=True)
    good = sum(1 for f, _ in fits if f is not None and f >= 95.0)
    low = [(f, w) for f, w in fits if f is None or f < 95.0]
    print(f"fits >= 95 %: {good} of {len(fits)}; below 95 %: {len(low)}, "
          f"{sum(1 for _, w in low if w)} of them warned")
    return 0


if __name__ == "__main__":
    sys.exit(main())
