"""step_response_std, bode_std and confidence bands: the parameter covariance of
identified models propagated to their responses (first order, Ljung sec. 9.6),
checked against a Monte Carlo estimate with scipy."""
import numpy as np
import pytest
import scipy.signal as sig

import pneumid

TS = 0.01
A = [1.0, -0.6087, -0.2702, -0.06021]  # the paper's ARX(3,3,1) (Eq. 5)
B = [0.0, 0.03938, 0.04506, 0.01286]


@pytest.fixture(scope="module")
def arx():
    rng = np.random.default_rng(3)
    n = 2000
    u = np.repeat(np.where(rng.random(n // 4) > 0.5, 90.0, 10.0), 4)
    y = sig.lfilter(B, A, u) + sig.lfilter([1.0], A, rng.normal(0, 0.3, n))
    data = pneumid.Dataset(np.arange(n) * TS, u.reshape(-1, 1), y.reshape(-1, 1))
    s = pneumid.identify_models(["arx", "cra"], data)
    return {m.method: m for m in s["models"]}


def test_covariance_is_exposed(arx):
    m = arx["arx"]
    cov = m.covariance
    assert cov["names"] == ["a1", "a2", "a3", "b1", "b2", "b3"]
    assert cov["matrix"].shape == (6, 6)
    assert np.allclose(np.sqrt(np.diag(cov["matrix"])), [m.param_std[k] for k in cov["names"]])
    assert "covariance" in m.to_dict()
    assert pneumid.has_covariance(m)


def test_step_std_matches_monte_carlo(arx):
    m = arx["arx"]
    t = np.arange(101) * TS
    sd = pneumid.step_response_std(m, t, discrete=True)
    p = m.params
    cov = m.covariance["matrix"]
    theta = np.concatenate([p["a"][1:], p["b"][p["nk"]:]])
    rng = np.random.default_rng(1)
    ys = []
    for th in rng.multivariate_normal(theta, cov, size=3000):
        a = np.concatenate([[1.0], th[:3]])
        b = np.concatenate([np.zeros(p["nk"]), th[3:]])
        ys.append(sig.lfilter(b, a, np.ones(t.size)))
    mc = np.std(ys, axis=0, ddof=1)
    assert sd.shape == t.shape and sd[0] == 0.0
    assert np.max(np.abs(sd[3:] - mc[3:]) / mc[3:]) < 0.10
    # The continuous (zoh) form agrees at the samples.
    assert np.allclose(pneumid.step_response_std(m, t), sd, rtol=1e-3, atol=1e-12)


def test_bode_std_matches_monte_carlo(arx):
    m = arx["arx"]
    w = np.logspace(-1, np.log10(np.pi / TS) - 0.05, 15)
    sd = pneumid.bode_std(m, w, discrete=True)
    p = m.params
    theta = np.concatenate([p["a"][1:], p["b"][p["nk"]:]])
    rng = np.random.default_rng(2)
    mags, phases = [], []
    for th in rng.multivariate_normal(theta, m.covariance["matrix"], size=3000):
        a = np.concatenate([[1.0], th[:3]])
        b = np.concatenate([np.zeros(p["nk"]), th[3:]])
        _, h = sig.freqz(b, a, worN=w * TS)
        mags.append(20 * np.log10(np.abs(h)))
        phases.append(np.degrees(np.unwrap(np.angle(h))))
    assert np.max(np.abs(sd["magnitude_db"] / np.std(mags, axis=0, ddof=1) - 1)) < 0.10
    assert np.max(np.abs(sd["phase_deg"] / np.std(phases, axis=0, ddof=1) - 1)) < 0.10


def test_model_without_covariance_has_no_band(arx, out_dir):
    m = arx["cra"]
    assert m.covariance is None and not pneumid.has_covariance(m)
    assert pneumid.step_response_std(m, np.linspace(0, 1, 5)).size == 0
    assert pneumid.bode_std(m, np.logspace(-1, 1, 5))["magnitude_db"].size == 0
    # Plots still work: only the models with a covariance get a band.
    pneumid.plot_identified_step([arx["arx"], m], str(out_dir / "uncertainty_step.svg"),
                                 confidence=3.0, t_final=1.0)
    svg = (out_dir / "uncertainty_step.svg").read_text()
    assert "arx (ARX) \u00b13 sd" in svg and "cra" in svg and "cra (" in svg
    assert svg.count("\u00b13 sd") == 1


def test_plots_and_report_with_confidence(arx, out_dir, tmp_path):
    pneumid.plot_identified_bode([arx["arx"]], str(out_dir / "uncertainty_bode.png"),
                                 confidence=2.0)
    assert (out_dir / "uncertainty_bode.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="confidence"):
        pneumid.plot_identified_step([arx["arx"]], str(tmp_path / "x.png"), confidence=-1.0)
    t = np.arange(300) * TS
    u = np.where(t >= 0.5, 80.0, 10.0)
    data = pneumid.Dataset(t, u.reshape(-1, 1), sig.lfilter(B, A, u).reshape(-1, 1))
    s = pneumid.write_identification_report(data, str(tmp_path / "rep"), ["arx"], confidence=3.0)
    assert "\u00b13 standard deviations" in open(s["html"], encoding="utf-8").read()
