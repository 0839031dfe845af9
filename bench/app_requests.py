#!/usr/bin/env python3
"""`pneumid app` request timings: a 2e5-sample file opened and identified with
the page's default methods (target: <= 2 s together), the views of the best
model, and a closed loop of 1000 samples (the request behind a slider move).

Starts the app on a free port under a temporary root, simulates the file with
`pneumid simulate`, times each request (median of 5), prints one line each.

Usage: /usr/bin/python3 bench/app_requests.py build/pneumid
"""
import json
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request


def main():
    pneumid = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        subprocess.run([pneumid, "simulate", "--plant", "ipa", "--input",
                        "prbs-levels:low=10,high=90,levels=5,clock=0.5,seed=3", "--duration",
                        "2000", "--seed", "4", "-o", str(root / "big.csv")],
                       check=True, capture_output=True)
        app = subprocess.Popen([pneumid, "app", "--port", "0", "--root", str(root),
                                "--token", "bench"], stdout=subprocess.PIPE, text=True)
        try:
            url = None
            for _ in range(100):
                m = re.search(r"http://127\.0\.0\.1:\d+", app.stdout.readline())
                if m:
                    url = m.group(0)
                    break
            if url is None:
                sys.exit("app_requests: the app did not print its address")

            def call(path, body):
                req = urllib.request.Request(url + path, data=json.dumps(body).encode(),
                                             method="POST",
                                             headers={"X-Pneumid-Token": "bench",
                                                      "Content-Type": "application/json"})
                t0 = time.perf_counter()
                with urllib.request.urlopen(req) as f:
                    answer = json.load(f)
                return answer, time.perf_counter() - t0

            def median(path, body):
                runs = [call(path, body) for _ in range(5)]
                return runs[-1][0], statistics.median(t for _, t in runs)

            data, t_open = median("/api/data/open", {"path": "big.csv"})
            methods = ["reaction-curve", "arx", "fit-p1d"]
            ident, t_ident = median("/api/identify", {"data": data["id"], "methods": methods})
            best = ident["model_file"]["models"][0]
            _, t_views = median("/api/model/views", {"model": best, "data": data["id"]})
            _, t_control = median("/api/control", {
                "model": best, "controller": "mpc", "rule": "auto", "plant": "ipa", "Ts": 0.01,
                "setpoint": "step:from=0,to=40,at=0.5", "duration": 10})
            total = t_open + t_ident
            print(f"open {data['samples']} samples: {1000 * t_open:.0f} ms")
            print(f"identify ({', '.join(methods)}): {1000 * t_ident:.0f} ms")
            print(f"open + identify: {total:.2f} s (target <= 2 s): "
                  f"{'met' if total <= 2.0 else 'missed'}")
            print(f"views of {best['method']} on the same data: {1000 * t_views:.0f} ms")
            print(f"closed loop, mpc rule auto, 1000 samples: {1000 * t_control:.0f} ms")
        finally:
            app.terminate()
            app.wait()


if __name__ == "__main__":
    main()
