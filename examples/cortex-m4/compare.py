#!/usr/bin/env python3
"""Compares the host and target traces of main.c and reports the figures.

Each trace line is "k y u" with y and u as the bit patterns of their IEEE
values (8 hex digits: float, 16: double); the target's last lines give the
SysTick calibration and the cost of the controller steps. Exits 1 when the
input traces differ by more than --tolerance times the largest |u| (default:
1e-5 for float, 1e-12 for double) or a trace is incomplete.
"""
import argparse
import json
import struct
import sys


def decode(text):
    if len(text) == 8:
        return struct.unpack(">f", bytes.fromhex(text))[0], "float"
    return struct.unpack(">d", bytes.fromhex(text))[0], "double"


def read(path):
    rows, info = [], {}
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] in ("calibration", "cost"):
                for item in parts[1:]:
                    key, value = item.split("=")
                    info[key] = int(value)
                continue
            y, precision = decode(parts[1])
            u, _ = decode(parts[2])
            rows.append((int(parts[0]), y, u))
            info["precision"] = precision
    return rows, info


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("host")
    p.add_argument("target")
    p.add_argument("--size", help="arm-none-eabi-size output for the controller object")
    p.add_argument("--stack-usage", help="gcc -fstack-usage output (.su) of the controller object")
    p.add_argument("--icount-shift", type=int, default=6)
    p.add_argument("--tolerance", type=float)
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    host, _ = read(a.host)
    target, info = read(a.target)
    report = {"steps": len(target), "precision": info.get("precision")}
    ok = len(host) == len(target) and len(host) == info.get("steps", -1) and len(host) > 0
    if not ok:
        print(f"incomplete traces: host {len(host)} rows, target {len(target)} rows, "
              f"expected {info.get('steps')}", file=sys.stderr)
    scale = max([1.0] + [abs(r[2]) for r in host])
    worst = max([abs(h[2] - t[2]) for h, t in zip(host, target)] + [0.0])
    identical = sum(1 for h, t in zip(host, target) if h[2] == t[2])
    tol = a.tolerance if a.tolerance is not None else (1e-5 if info.get("precision") == "float" else 1e-12)
    report.update({"max_abs_difference_u": worst, "max_relative_difference_u": worst / scale,
                   "identical_inputs": identical, "tolerance": tol})
    if worst / scale > tol:
        ok = False
        print(f"traces differ: max |u_host - u_target| = {worst:.3g} ({worst / scale:.3g} relative)",
              file=sys.stderr)
    # Instructions: SysTick ticks per executed instruction from the calibration loop.
    if info.get("loop_ticks"):
        per_tick = info["loop_instructions"] / info["loop_ticks"]
        steps = info["steps"]
        mean_ticks = info["ticks_total"] / steps - info.get("empty_ticks", 0)
        report["instructions_per_tick"] = per_tick
        report["instructions_per_step_mean"] = mean_ticks * per_tick
        report["instructions_per_step_max"] = (info["ticks_max"] - info.get("empty_ticks", 0)) * per_tick
        report["icount_shift"] = a.icount_shift
    report["state_bytes"] = info.get("state_bytes")
    if a.size:
        with open(a.size) as f:
            lines = f.read().split("\n")
        text, data, bss = (int(v) for v in lines[1].split()[:3])
        report.update({"ctrl_text": text, "ctrl_data": data, "ctrl_bss": bss})
    if a.stack_usage:
        # Static frames only (no recursion, no variable-length arrays in the
        # module): the sum of all frames bounds the deepest call chain.
        frames = {}
        with open(a.stack_usage) as f:
            for line in f:
                parts = line.rstrip("\n").split("\t")
                if len(parts) >= 3:
                    frames[parts[0].split(":")[-1]] = (int(parts[1]), parts[2])
        report["stack_bytes_bound"] = sum(v[0] for v in frames.values())
        report["stack_all_static"] = all(v[1] == "static" for v in frames.values())
        if not report["stack_all_static"]:
            ok = False
            print("a function of the controller has a dynamic stack frame", file=sys.stderr)
    if a.json:
        print(json.dumps(report, indent=2))
    else:
        for k, v in report.items():
            print(f"{k}: {v:.4g}" if isinstance(v, float) else f"{k}: {v}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
