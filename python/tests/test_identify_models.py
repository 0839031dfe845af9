"""identify_models, preprocess and simulate_model: the Python side of
`pneumid identify` with preprocessing, held-out validation and flags."""
import math

import numpy as np
import pytest
import scipy.signal as sig

import pneumid

TS = 0.01
A = [1.0, -0.6087, -0.2702, -0.06021]  # the paper's ARX(3,3,1) (Eq. 5)
B = [0.0, 0.03938, 0.04506, 0.01286]


def prbs_record(seed, n=3000, u_offset=0.0, y_offset=0.0):
    rng = np.random.default_rng(seed)
    u = np.repeat(np.where(rng.random(n // 3) > 0.5, 90.0, 10.0), 3)
    y = sig.lfilter(B, A, u) + sig.lfilter([1.0], A, rng.normal(0, 0.3, n))
    t = np.arange(n) * TS
    return pneumid.Dataset(t, (u + u_offset).reshape(-1, 1), (y + y_offset).reshape(-1, 1))


def test_each_method_fails_alone_and_the_best_fit_ranks_first():
    d = prbs_record(1)
    r = pneumid.identify_models(["reaction-curve", "arx", "oe"], d)
    assert [f["method"] for f in r["failures"]] == ["reaction-curve"]
    assert r["termination"] == "partial"
    best = r["models"][0]
    # Ranked by the simulation fit: the whiteness test on simulation errors
    # flags the true ARX model too (its equation noise is coloured by 1/A), a
    # flag that does not move it back.
    assert r["best"] == best.method
    assert best.fit_percent == max(m.fit_percent for m in r["models"])
    arx = next(m for m in r["models"] if m.method == "arx")
    assert {f["flag"] for f in arx.flags} <= {"residuals_not_white"}
    assert best.rank_reason.startswith("estimation fit")
    np.testing.assert_allclose(arx.params["a"], A, atol=0.03)


def test_split_ranks_by_the_held_out_fit():
    d = prbs_record(2)
    r = pneumid.identify_models(["arx", "fit-p1d"], d, split=0.7)
    for m in r["models"]:
        assert math.isfinite(m.validation_fit_percent)
    fits = [m.validation_fit_percent for m in r["models"] if not m.flags]
    assert fits == sorted(fits, reverse=True)
    assert r["warnings"] == []
    assert all(m.structure_chosen_on == "" for m in r["models"])


def test_a_held_out_part_on_one_level_is_warned_of():
    d = prbs_record(2)
    n = len(d)
    u = d.u(0).copy()
    u[int(0.7 * n) - 5:] = u[int(0.7 * n) - 5]
    flat = pneumid.Dataset(d.time, u.reshape(-1, 1), d.y(0).reshape(-1, 1))
    r = pneumid.identify_models(["arx"], flat, split=0.7)
    assert len(r["warnings"]) == 1
    assert "holds a constant input" in r["warnings"][0]


def test_preprocess_matches_numpy():
    d = prbs_record(3, u_offset=50.0, y_offset=300.0)
    out, record = pneumid.preprocess(d, detrend="constant")
    np.testing.assert_allclose(out.y(0), d.y(0) - d.y(0).mean(), atol=1e-12)
    np.testing.assert_allclose(out.u(0), d.u(0) - d.u(0).mean(), atol=1e-12)
    assert record["offsets"] == "constant"
    lin, _ = pneumid.preprocess(d, detrend="linear")
    np.testing.assert_allclose(lin.y(0), sig.detrend(d.y(0), type="linear"), atol=1e-9)
    dec, _ = pneumid.preprocess(d, decimate=3)
    assert len(dec) == 1000 and dec.sample_time() == pytest.approx(0.03)
    with pytest.raises(pneumid.DataError, match="Nyquist"):
        pneumid.preprocess(d, filter="lowpass:60")
    with pytest.raises(pneumid.InvalidArgument):
        pneumid.preprocess(d, decimate=0)


def test_offsets_travel_with_the_model():
    d = prbs_record(4, u_offset=50.0, y_offset=300.0)
    raw = pneumid.identify_models(["arx"], d, operating_point="zero")["models"][0]
    pre = pneumid.identify_models(["arx"], d, detrend="constant")["models"][0]
    assert pre.fit_percent > raw.fit_percent + 5
    # By default the ARX is identified around the means and keeps them as its
    # operating point: the same coefficients as from the detrended record.
    auto = pneumid.identify_models(["arx"], d)["models"][0]
    np.testing.assert_allclose(auto.params["a"], pre.params["a"], rtol=1e-9, atol=1e-12)
    assert auto.u0 == pytest.approx(d.u(0).mean()) and auto.y0 == pytest.approx(d.y(0).mean())
    assert auto.fit_percent == pytest.approx(pre.fit_percent, abs=1e-6)
    assert pre.preprocessing["offsets"] == "constant"
    # simulate_model is the simulation identify scores: same fit.
    out, _ = pneumid.preprocess(d, detrend="constant")
    yhat = pneumid.simulate_model(pre, out)
    assert pneumid.nrmse_fit(out.y(0), yhat) == pytest.approx(pre.fit_percent, abs=1e-9)
    assert pre.to_dict()["operating_point"] == {"u0": 0.0, "y0": 0.0}
