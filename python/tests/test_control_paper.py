"""Plants, tuning, closed loops and the paper workflow from Python.
Golden values: docs/paper.md, reference value 6."""
import numpy as np
import pytest
import scipy.signal as sig

import pneumid


def test_tune_paper_fopdt_reproduces_p_and_lambda():
    t = pneumid.tune(pneumid.paper_fopdt_model(), 0.01, "shridhar-cooper", M=5)
    assert t["P"] == 126
    assert t["lambda"] == pytest.approx(2.2508, abs=5e-4)
    m = pneumid.tune(pneumid.paper_fopdt_model(), 0.01, "modified")
    assert (m["P"], m["M"], m["lambda"]) == (126, 10, pytest.approx(1.92))


def test_results_are_the_json_of_the_command_line():
    # TuningResult::ToJson (pneumid tune --json), with the flat FOPDT keys kept
    t = pneumid.tune(pneumid.paper_fopdt_model(), 0.01, "shridhar-cooper", M=5)
    assert t["fopdt"]["method"] == "exact" and t["tau"] == t["fopdt"]["tau"]
    assert t["lambda_source"] == "lambda_condition" and t["Ts"] == 0.01
    # ClosedLoopMetrics::ToJson (pneumid control --json): steps, None when absent
    c = pneumid.make_controller(pneumid.paper_fopdt_model(), 0.01, "dmc", "shridhar-cooper", M=5)
    p = pneumid.make_plant("fopdt-paper", 0.01)
    m = pneumid.simulate_closed_loop(c, p, "step:from=0,to=1,at=0", 1.0)["metrics"]
    assert m["load_peak_deviation"] is None and len(m["steps"]) == 1
    assert m["steps"][0]["to"] == 1.0


def test_dmc_reference_closed_loop_on_linear_plant():
    g = pneumid.paper_fopdt_model()
    c = pneumid.make_controller(g, 0.01, "dmc", "explicit", M=5, P=126, lambda_=2.25)
    p = pneumid.make_plant("fopdt-paper", 0.01)
    r = pneumid.simulate_closed_loop(c, p, "step:from=0,to=1,at=0", 1.5)
    m = r["metrics"]
    # reference: first move 0.672, overshoot 2.0 %, settling 0.23 s (one sample)
    assert m["first_move"] == pytest.approx(0.672, abs=5e-4)
    assert m["overshoot_percent"] == pytest.approx(2.0, abs=0.1)
    assert m["settling_time"] == pytest.approx(0.23, abs=0.01)
    # the loop's output is the plant model driven by the applied input:
    # check it against scipy's zoh simulation of the same FOPDT
    gd = pneumid.c2d(g, 0.01, "zoh")
    _, yref = sig.dlsim((gd.num, gd.den, 0.01), r["u"])
    np.testing.assert_allclose(r["y"], np.ravel(yref), atol=1e-9)


def test_ipa_step_test_and_reaction_curve():
    ipa = pneumid.make_plant("ipa", 0.01, seed=3)
    d = pneumid.run_experiment(ipa, "step:from=0.61,to=82,at=0.5", 3.0)
    m = pneumid.identify("reaction-curve", d)
    # the simulator is calibrated to Eq. 5's response to the paper's step:
    # 0 -> 129 N, t63 = 0.2306 s (the paper read 0.245 s off its measured data)
    assert m.params["K"] == pytest.approx(1.585, rel=0.03)
    assert m.params["t63"] == pytest.approx(0.2306, abs=0.01)


def test_run_paper_rows():
    r = pneumid.run_paper()
    q = {row["quantity"]: row for row in r["rows"]}
    assert q["static gain of Eq. 5 (recomputed)"]["pneumid"] == "1.59796"
    assert q["modified P, M, lambda"]["pneumid"] == "126, 10, 1.92"
    assert r["termination"] == "success"


def test_block_diagrams_and_bode():
    g = pneumid.TransferFunction(np.array([1.0]), np.array([1.0, 1.0]))
    cl = pneumid.feedback(g)
    assert cl.dc_gain() == pytest.approx(0.5)
    w = np.logspace(-1, 2, 20)
    b = pneumid.bode(g, w)
    _, h = sig.freqresp(([1.0], [1.0, 1.0]), w)
    np.testing.assert_allclose(b["magnitude_db"], 20 * np.log10(np.abs(h)), atol=1e-9)
    np.testing.assert_allclose(b["phase_deg"], np.degrees(np.angle(h)), atol=1e-7)


def test_bad_specs_raise():
    with pytest.raises(ValueError):
        pneumid.make_plant("no-such-plant", 0.01)
    with pytest.raises(ValueError):
        pneumid.tune(pneumid.paper_fopdt_model(), 0.01, "no-such-rule")


def test_make_controller_mpc_by_name():
    # The state-space MPC through the same factory as the CLI: horizons from
    # the tuning rule, the input limits as QP bounds.
    c = pneumid.make_controller(pneumid.paper_fopdt_model(), 0.01, "mpc", "shridhar-cooper",
                                u_min=0.0, u_max=100.0)
    assert c.describe().startswith("mpc P=126 M=5 ")
    assert "disturbance=input" in c.describe()
    c.reset(0.0, 0.0)
    u = [c.update(80.0, 0.0) for _ in range(5)]
    assert all(0.0 <= v <= 100.0 for v in u)
    assert u[0] > 0.0


@pytest.mark.parametrize("kind", ["dmc", "gpc", "pid", "mpc"])
def test_nan_measurement_holds_the_input_and_control_resumes(kind):
    # A NaN or Inf reading neither poisons the controller nor reaches its state:
    # the input is held, the fault is reported, and the loop recovers.
    g = pneumid.paper_fopdt_model()
    c = pneumid.make_controller(g, 0.01, kind, "shridhar-cooper", M=5, u_min=0.0, u_max=100.0)
    c.set_measurement_guard(y_min=-5.0, y_max=250.0)
    p = pneumid.make_plant("fopdt-paper", 0.01)
    c.reset(0.0, 0.0)
    us, ys, faults = [], [], []
    for k in range(600):
        y = p.measure()
        if 150 <= k < 160:
            y = float("nan") if k % 2 else float("inf")
        if 160 <= k < 165:
            y = -1000.0  # a disconnected sensor, out of the valid range
        u = c.update(60.0, y)
        us.append(u)
        ys.append(p.measure())
        faults.append(c.last_fault)
        p.advance(u)
    assert np.all(np.isfinite(us)) and min(us) >= 0.0 and max(us) <= 100.0
    assert faults[150] in ("measurement-not-finite",) and faults[162] == "measurement-out-of-range"
    assert faults[165] == "none" and c.fault_count == 15
    assert all(u == us[149] for u in us[150:165])
    assert np.max(np.abs(np.array(ys[215:]) - 60.0)) < 0.5
    with pytest.raises(ValueError):
        c.set_measurement_guard(y_min=10.0, y_max=0.0)


def test_position_pd_with_velocity_feed_forward_on_the_position_twin():
    # An integrating model (m/s per %) needs Kc; Kff defaults to 1/Ki + Kc Td.
    model = pneumid.TransferFunction(np.array([0.004]), np.array([1.0, 0.0]))
    Ts = 1.0 / 300.0
    with pytest.raises(pneumid.InvalidArgument, match="give the gains"):
        pneumid.make_controller(model, Ts, "pid")
    c = pneumid.make_controller(model, Ts, "pid", Kc=6000.0, Td=0.04, u_min=-100.0, u_max=100.0,
                                input_gaps="-100:-91,-9:0,0:9,91:100")
    assert "Kff=490" in c.describe()
    p = pneumid.make_plant("ipa-position", Ts)
    r = pneumid.simulate_closed_loop(c, p, "step:from=0.05,to=0.07,at=0.1", 1.5, u_min=-100.0,
                                     u_max=100.0)
    steps = [s for s in r["metrics"]["steps"] if s["time"] > 0]
    assert steps[0]["overshoot_percent"] <= 2.0
    assert abs(steps[0]["steady_state_error"]) <= 1e-4
