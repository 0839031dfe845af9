"""Datasets from numpy and files, identification, plots and reports."""
import json
import threading

import numpy as np
import pytest
import scipy.signal as sig

import pneumid

TS = 0.01


def first_order_step(K=1.6, tau=0.245, n=300, k_step=50, u0=0.61, u1=82.0):
    """The paper's step test on a first-order plant, exact at the samples
    (zero-order-hold input): y = K du (1 - exp(-(t - t_s) / tau))."""
    t = np.arange(n) * TS
    u = np.where(np.arange(n) >= k_step, u1, u0)
    ts = k_step * TS
    y = np.where(t > ts, K * (u1 - u0) * (1.0 - np.exp(-(t - ts) / tau)), 0.0)
    return t, u, y


def test_dataset_from_numpy_round_trip(out_dir):
    t, u, y = first_order_step()
    d = pneumid.Dataset(t, u.reshape(-1, 1), y.reshape(-1, 1), ["u"], ["%"], ["F"], ["N"])
    assert len(d) == 300
    assert d.sample_time() == pytest.approx(TS)
    np.testing.assert_array_equal(d.y(0), y)
    assert d.output_channels[0].unit == "N"
    path = out_dir / "step.csv"
    d.save(str(path))
    d2 = pneumid.Dataset.load(str(path), output_columns=["F"])
    np.testing.assert_allclose(d2.y(0), y, rtol=1e-12, atol=1e-12)


def test_dataset_rejects_bad_input(tmp_path):
    with pytest.raises(pneumid.InvalidArgument):
        pneumid.Dataset(np.array([0.0, 1.0, 1.0]), np.zeros((3, 1)), np.zeros((3, 1)))
    with pytest.raises(pneumid.InvalidArgument):
        pneumid.Dataset.from_uniform(0.01, np.zeros(3), np.zeros(4))
    bad = tmp_path / "bad.csv"
    bad.write_text("t,u,y\n0,1,2\n0.01,abc,3\n")
    with pytest.raises(pneumid.DataError, match="bad.csv"):
        pneumid.Dataset.load(str(bad))


def test_reaction_curve_recovers_first_order_plant():
    t, u, y = first_order_step()
    d = pneumid.Dataset.from_uniform(TS, u, y)
    m = pneumid.identify("reaction-curve", d)
    assert m.structure == "FOPDT"
    assert m.params["K"] == pytest.approx(1.6, rel=0.01)
    # tau within about one sample
    assert m.params["tau"] + m.params["theta"] == pytest.approx(0.245, abs=TS)
    assert m.fit_percent > 95.0
    assert json.loads(json.dumps(m.to_dict()))["method"] == "reaction-curve"


def test_arx_recovers_paper_model_from_prbs_data():
    rng = np.random.default_rng(7)
    u = np.repeat(rng.choice([20.0, 80.0], 200), 5)
    g = pneumid.paper_arx_model()
    y = pneumid.lsim(g, u, TS)
    # independent check of the simulation itself
    _, yref = sig.dlsim((g.num, g.den, TS), u)
    np.testing.assert_allclose(y, np.ravel(yref), rtol=1e-10, atol=1e-10)
    m = pneumid.identify("arx", pneumid.Dataset.from_uniform(TS, u, y), na=3, nb=3, nk=1)
    np.testing.assert_allclose(m.params["a"], [1.0, -0.60870, -0.27020, -0.06021], atol=1e-6)
    assert m.fit_percent > 99.9
    # typed parameters: integers stay int, coefficients are lists, as in the JSON form
    assert m.params["nk"] == 1 and isinstance(m.params["nk"], int)
    assert isinstance(m.params["a"], list) and isinstance(m.params["Ts"], float)
    assert m.to_dict()["params"] == m.params


def test_identify_unknown_method_lists_valid_names():
    t, u, y = first_order_step()
    with pytest.raises(ValueError, match="reaction-curve"):
        pneumid.identify("magic", pneumid.Dataset.from_uniform(TS, u, y))
    assert "arx" in pneumid.identify_methods()
    assert pneumid.identify_methods()[0] == "reaction-curve"
    assert pneumid.identify_methods()[-1] == "spa"


def test_identify_releases_the_gil():
    # While identify runs in a thread, this thread runs Python: with the GIL
    # held through the call it could not count at all until the call returned.
    t, u, y = first_order_step(n=200000)
    d = pneumid.Dataset.from_uniform(TS, u, y)
    results, started = [], threading.Event()

    def work():
        started.set()
        results.append(pneumid.identify("arx", d))

    th = threading.Thread(target=work)
    th.start()
    started.wait()
    counted = 0
    while th.is_alive():
        counted += 1
    th.join()
    assert counted > 1000, counted
    # The result is the same as a call in this thread.
    again = pneumid.identify("arx", d)
    assert results[0].params == again.params


def test_plots_write_png_and_svg(out_dir):
    models = [("FOPDT", pneumid.paper_fopdt_model()), ("ARX", pneumid.paper_arx_model())]
    png = out_dir / "step.png"
    pneumid.plot_step_responses(models, str(png), amplitude=81.39, t_final=2.0)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    svg = out_dir / "bode.svg"
    pneumid.plot_bode(models, str(svg))
    assert "Phase [deg]" in svg.read_text()
    with pytest.raises(ValueError, match=r"\.png or \.svg"):
        pneumid.plot_bode(models, str(out_dir / "bode.gif"))


def test_report_writes_html_with_plots_and_tables(out_dir):
    t, u, y = first_order_step()
    rng = np.random.default_rng(1)
    d = pneumid.Dataset.from_uniform(TS, u, y + rng.normal(0.0, 0.3, len(y)),
                                     output_name="F", output_unit="N")
    s = pneumid.write_identification_report(d, str(out_dir / "report"))
    assert s["termination"] == "success", s["failures"]
    html = open(s["html"]).read()
    assert html.count("<svg") == s["figures"] == 4
    assert html.count("<table") == s["tables"] == 3
