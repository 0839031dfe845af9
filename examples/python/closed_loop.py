"""From a step test to a closed MPC loop in Python, on the IPA simulator.

1. a step test of the built-in IPA simulator (PWM duty % in, force N out);
2. a first-order-plus-dead-time model fitted to it (fit-p1d);
3. an MPC tuned to the fastest robust design of the model (rule "auto"),
   duty limited to 0..100 %;
4. the closed loop with the simulator, twice: by simulate_closed_loop, and by
   a loop written out sample by sample (measure, update, clip, advance), the
   loop you would write around your own plant; both must agree.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/closed_loop.py [--output-dir DIR]

--module-dir DIR (or PNEUMID_PYTHON_DIR) names the directory of the pneumid
module when it is not on PYTHONPATH. With --output-dir the script writes
closed_loop.png there (matplotlib) and closed_loop.csv.
"""
import argparse
import os
import sys

import numpy as np

TS = 0.01  # s, the IPA's sample time
SETPOINT = "staircase:levels=0 40 80 40,dwell=2"  # N, 2 s per level
LOAD = (7.0, -15.0)  # a -15 N load from 7 s on
DURATION = 8.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--module-dir", default=os.environ.get("PNEUMID_PYTHON_DIR"),
                        help="directory of the pneumid module (e.g. build/python)")
    parser.add_argument("--output-dir", help="write the figure and the trace here")
    args = parser.parse_args()
    if args.module_dir:
        sys.path.insert(0, args.module_dir)
    import pneumid

    # 1-2. Step test and model.
    step_test = pneumid.run_experiment(pneumid.make_plant("ipa", TS),
                                       "step:from=0.61,to=82,at=1.0", 4.0)
    model = pneumid.identify("fit-p1d", step_test)
    p = model.params
    print(f"fit-p1d: K = {p['K']:.4f} N/%, tau = {p['tau']:.4f} s, theta = {p['theta']:.4f} s, "
          f"fit {model.fit_percent:.2f} %")

    # 3. The controller; make_controller designs it once (P, M, lambda).
    def new_controller():
        return pneumid.make_controller(model.tf, TS, "mpc", "auto", u_min=0.0, u_max=100.0)

    print("controller:", new_controller().describe())

    # 4a. The library's closed loop (what `pneumid control` runs).
    run = pneumid.simulate_closed_loop(new_controller(), pneumid.make_plant("ipa", TS), SETPOINT,
                                       DURATION, load_steps=[LOAD], u_min=0.0, u_max=100.0)
    m = run["metrics"]
    print(f"simulate_closed_loop: IAE {m['iae']:.3f} N s, overshoot per step "
          f"{[round(s['overshoot_percent'], 2) for s in m['steps']]} %, "
          f"load peak {m['load_peak_deviation']:.2f} N, recovered in {m['load_recovery_time']:.2f} s")

    # 4b. The same loop written out. The controller starts at the plant's
    #     current state (input 0, the first measurement), as the library does.
    ctrl = new_controller()
    plant = pneumid.make_plant("ipa", TS)
    plant.reset()
    ctrl.reset(0.0, plant.measure())
    y_log, u_log = [], []
    for t, r in zip(run["t"], run["r"]):
        plant.set_load_disturbance(LOAD[1] if t >= LOAD[0] - 1e-9 else 0.0)
        y = plant.measure()                    # read the sensor
        u = ctrl.update(r, y)                  # one control step
        u_applied = min(max(u, 0.0), 100.0)   # the actuator's range
        if u_applied != u:
            ctrl.applied(u_applied)            # anti-windup: tell the controller
        plant.advance(u_applied)               # hold u for one sample
        y_log.append(y)
        u_log.append(u_applied)
    y_log, u_log = np.array(y_log), np.array(u_log)
    dy = float(np.max(np.abs(y_log - run["y"])))
    du = float(np.max(np.abs(u_log - run["u"])))
    print(f"written-out loop: largest difference from simulate_closed_loop: y {dy:.3g} N, u {du:.3g} %")

    if args.output_dir:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        os.makedirs(args.output_dir, exist_ok=True)
        np.savetxt(os.path.join(args.output_dir, "closed_loop.csv"),
                   np.c_[run["t"], run["r"], run["y"], run["u"]], delimiter=",",
                   header="t [s],r [N],y [N],u [%]", comments="")
        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5.5))
        ax1.plot(run["t"], run["r"], "k--", lw=1, label="set-point")
        ax1.plot(run["t"], run["y"], "C0", lw=1.2, label="force (IPA simulator)")
        ax1.axvline(LOAD[0], color="C3", lw=0.8, ls=":", label=f"load {LOAD[1]:g} N")
        ax1.set_ylabel("force F [N]")
        ax1.set_title(f"MPC from the step test's fit-p1d model (IAE {m['iae']:.2f} N s)")
        ax1.legend(loc="upper left", fontsize=8)
        ax2.plot(run["t"], run["u"], "C1", lw=1)
        ax2.set_ylabel("duty u [%]")
        ax2.set_xlabel("time t [s]")
        for ax in (ax1, ax2):
            ax.grid(alpha=0.3)
        fig.tight_layout()
        path = os.path.join(args.output_dir, "closed_loop.png")
        fig.savefig(path, dpi=100)
        print("figure:", path)

    # Checks. Today: IAE 9.41 N s, overshoot 0.51 / 5.64 / 7.98 %, recovery 0.28 s.
    failures = []
    if dy > 1e-9 or du > 1e-9:
        failures.append("the written-out loop differs from simulate_closed_loop")
    if not m["iae"] < 11.0:
        failures.append(f"IAE {m['iae']:.3f} N s not below 11")
    if not all(s["overshoot_percent"] < 12.0 for s in m["steps"]):
        failures.append("an overshoot above 12 %")
    if not (m["load_recovery_time"] is not None and m["load_recovery_time"] < 0.5):
        failures.append("load not rejected within 0.5 s")
    if not (run["u"].min() >= 0.0 and run["u"].max() <= 100.0):
        failures.append("duty outside 0..100 %")
    for f in failures:
        print("CHECK FAILED:", f)
    print("closed_loop.py:", "all checks passed" if not failures else "failed")
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
