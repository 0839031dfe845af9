"""Models, conversions and responses, cross-checked against scipy.signal and
the paper's values (docs/paper.md, reference values 2-3)."""
import numpy as np
import pytest
import scipy.signal as sig

import pneumid

# Paper Eq. 5 (ARX(3,3,1), Ts = 0.01 s).
A = [1.0, -0.60870, -0.27020, -0.06021]
B = [0.0, 0.03938, 0.04506, 0.01286]


def test_module_metadata():
    assert pneumid.__version__
    assert "pneumid" in pneumid.__doc__


def test_paper_arx_model_coefficients_and_gain():
    g = pneumid.paper_arx_model()
    assert g.Ts == pytest.approx(0.01)
    np.testing.assert_allclose(g.den, A, atol=1e-12)
    np.testing.assert_allclose(g.num, B, atol=1e-12)
    # static gain sum(b) / (1 + sum(a)) = 1.59796 (docs/paper.md, reference value 2)
    assert g.dc_gain() == pytest.approx(1.59796, rel=1e-5)


def test_c2d_zoh_matches_scipy_cont2discrete():
    num, den = [6.102, -91.95, 520000.0], [1.0, 281.0, 74990.0, 325400.0]
    g = pneumid.TransferFunction(np.array(num), np.array(den))
    gd = pneumid.c2d(g, 0.01, "zoh")
    nd, dd, _ = sig.cont2discrete((num, den), 0.01, method="zoh")
    nd = np.ravel(nd)
    # scipy gives descending powers of z with equal lengths = ascending z^-1.
    np.testing.assert_allclose(gd.den / gd.den[0], dd / dd[0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(gd.num / gd.den[0], nd / dd[0], rtol=1e-7, atol=1e-10)


@pytest.mark.parametrize("method,scipy_method", [("tustin", "bilinear"), ("euler", "euler"),
                                                 ("backward_diff", "backward_diff")])
def test_c2d_other_methods_match_scipy(method, scipy_method):
    num, den = [2.0, 1.0], [1.0, 3.0, 2.0]
    gd = pneumid.c2d(pneumid.TransferFunction(np.array(num), np.array(den)), 0.05, method)
    nd, dd, _ = sig.cont2discrete((num, den), 0.05, method=scipy_method)
    nd = np.ravel(nd)
    # compare the frequency responses (coefficient vectors may be padded differently)
    w = np.array([0.1, 1.0, 10.0, 50.0])
    z = np.exp(1j * w * 0.05)
    ref = np.polyval(nd, z) / np.polyval(dd, z)
    got = np.array([gd.frequency_response(x) for x in w])
    np.testing.assert_allclose(got, ref, rtol=1e-9)


def test_d2c_of_paper_arx_gives_paper_eq6():
    gc = pneumid.d2c(pneumid.paper_arx_model(), "zoh").normalized()
    # matrix-logarithm ZOH (docs/paper.md, reference value 3)
    np.testing.assert_allclose(gc.den, [1.0, 280.9917, 74994.63, 325421.7], rtol=1e-5)
    np.testing.assert_allclose(gc.num[-3:], [6.10237, -91.9458, 520011.9], rtol=1e-5)


def test_step_of_discrete_model_matches_scipy_dlsim():
    g = pneumid.paper_arx_model()
    t, y = pneumid.step(g, t_final=1.0)
    u = np.ones(len(t))
    _, yref = sig.dlsim((B, A, 0.01), u)
    np.testing.assert_allclose(y, np.ravel(yref), rtol=1e-10, atol=1e-12)


def test_lsim_continuous_matches_scipy_zoh_simulation():
    rng = np.random.default_rng(3)
    u = rng.uniform(0.0, 1.0, 200)
    num, den = [1.6], [0.245, 1.0]
    y = pneumid.lsim(pneumid.TransferFunction(np.array(num), np.array(den)), u, 0.01)
    nd, dd, _ = sig.cont2discrete((num, den), 0.01, method="zoh")
    _, yref = sig.dlsim((np.ravel(nd), dd, 0.01), u)
    np.testing.assert_allclose(y, np.ravel(yref), rtol=1e-9, atol=1e-12)


def test_frequency_response_matches_scipy_freqresp():
    num, den = [1.6], [0.245, 1.0]
    w = np.logspace(-1, 3, 30)
    g = pneumid.TransferFunction(np.array(num), np.array(den), 0.0, 0.001)
    got = np.array([g.frequency_response(x) for x in w])
    _, h = sig.freqresp((num, den), w)
    np.testing.assert_allclose(got, h * np.exp(-1j * w * 0.001), rtol=1e-12)


def test_step_info_first_order():
    g = pneumid.TransferFunction.fopdt(1.0, 1.0, 0.0)
    info = pneumid.compute_step_info(g)
    # rise 10-90 %: ln(9) tau; settling 2 %: ln(50) tau
    assert info["rise_time"] == pytest.approx(np.log(9.0), abs=0.02)
    assert info["settling_time"] == pytest.approx(np.log(50.0), abs=0.02)
    assert info["overshoot"] == pytest.approx(0.0, abs=1e-6)


def test_model_spec_and_dict_round_trip():
    g = pneumid.parse_model_spec("fopdt:K=1.6,tau=0.245,theta=0.001")
    assert g.delay == pytest.approx(0.001)
    d = g.to_dict()
    assert set(d) >= {"num", "den", "Ts", "delay"}
    g2 = pneumid.TransferFunction.from_dict(d)
    assert g2.dc_gain() == pytest.approx(1.6)


def test_bad_arguments_raise_value_errors():
    with pytest.raises(pneumid.InvalidArgument):
        pneumid.TransferFunction(np.array([1.0]), np.array([0.0, 0.0]))
    with pytest.raises(ValueError, match="zoh"):
        pneumid.c2d(pneumid.paper_fopdt_model(), 0.01, "no-such-method")
    with pytest.raises(ValueError):
        pneumid.parse_model_spec("fopdt:K=abc")
