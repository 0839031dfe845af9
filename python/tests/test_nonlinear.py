"""Nonlinear identification from Python: StaticMap against numpy, fit_static_map,
and identify('hammerstein' | 'wiener' | 'hw' | 'narx') on systems simulated here
with scipy."""
import numpy as np
import pytest
import scipy.signal as sig

import pneumid

TS = 0.01
KNOTS = np.array([0.0, 20.0, 40.0, 60.0, 80.0, 100.0])
VALUES = np.array([10.0, 14.0, 40.0, 80.0, 120.0, 128.0])
A = [1.0, -1.7, 0.72]
B = [0.0, 0.012, 0.008]  # B(1) = A(1): unit static gain


def levels(seed, n=4000):
    """Random levels on the grid 0, 10, .., 100 (first 0, then 100): the
    default 11 knots spread over the input range then hold the true kinks."""
    rng = np.random.default_rng(seed)
    values = 10.0 * rng.integers(0, 11, n)
    values[:2] = [0.0, 100.0]
    return np.repeat(values, rng.integers(5, 41, n))[:n]


def dataset(u, y):
    return pneumid.Dataset(np.arange(len(u)) * TS, u.reshape(-1, 1), y.reshape(-1, 1))


def test_static_map_evaluates_and_inverts_as_numpy():
    u = [0.0, 10.0, 20.0, 60.0, 88.0, 100.0]
    y = [0.0, 0.0, 18.7, 79.8, 193.2, 193.2]
    f = pneumid.StaticMap(u, y)
    x = np.linspace(-10.0, 110.0, 241)
    np.testing.assert_allclose(f.evaluate(x), np.interp(x, u, y), rtol=0, atol=1e-12)
    # Strictly increasing part: the inverse is numpy's interpolation with the roles exchanged.
    q = np.linspace(0.5, 193.0, 50)
    inv = np.array([f.inverse(v) for v in q])
    np.testing.assert_allclose(inv, np.interp(q, y[1:5], u[1:5]), rtol=0, atol=1e-12)
    assert f.inverse(0.0) == 10.0  # upper edge of the dead zone
    assert f.inverse(500.0) == 88.0  # start of the saturation
    assert f.dead_zone() == {"u_from": 0.0, "u_to": 10.0, "y": 0.0}
    assert f.saturation()["u_from"] == 88.0
    with pytest.raises(ValueError, match="not monotone"):
        pneumid.StaticMap([0, 1, 2], [0, 1, 0]).inverse(0.5)


def test_fit_static_map_of_a_staircase():
    u = np.repeat(np.arange(0.0, 101.0, 10.0), 200)
    y = sig.lfilter(B, A, np.interp(u, KNOTS, VALUES) - 10.0) + 10.0
    f, info = pneumid.fit_static_map(dataset(u, y))
    np.testing.assert_allclose(f.u, np.arange(0.0, 101.0, 10.0))
    np.testing.assert_allclose(f.y, np.interp(f.u, KNOTS, VALUES), atol=0.05)
    assert "staircase" in info["brief"]
    with pytest.raises(ValueError, match="never leaves one operating point"):
        pneumid.fit_static_map(dataset(np.full(300, 5.0), np.ones(300)))


def test_identify_hammerstein_and_wiener_recover_the_system():
    assert pneumid.nonlinear_methods() == ["static-map", "hammerstein", "wiener", "hw", "narx",
                                          "affine-narx"]
    assert "hammerstein" not in pneumid.identify_methods()
    u = levels(5)
    f = np.interp(u, KNOTS, VALUES)
    y = sig.lfilter(B, A, f - f[0]) + f[0]  # started at rest
    m = pneumid.identify("hammerstein", dataset(u, y), na=2, nb=2, nk=1)
    assert m.structure == "Hammerstein"
    assert m.fit_percent > 99.9
    np.testing.assert_allclose(m.params["A"], A, rtol=1e-3)
    # The map on the evenly spread knots (11 by default) is the true map.
    np.testing.assert_allclose(m.input_map.u, np.arange(0.0, 101.0, 10.0))
    np.testing.assert_allclose(m.input_map.y, np.interp(m.input_map.u, KNOTS, VALUES), atol=1e-6)
    x = sig.lfilter(B, A, u - u[0]) + u[0]
    w = pneumid.identify("wiener", dataset(u, np.interp(x, KNOTS, VALUES)), na=2, nb=2, nk=1)
    assert w.output_map is not None and w.fit_percent > 99.5
    # A Wiener system is a Hammerstein-Wiener one with the identity input map.
    hw = pneumid.identify("hw", dataset(u, np.interp(x, KNOTS, VALUES)), na=2, nb=2, nk=1)
    assert hw.structure == "Hammerstein-Wiener"
    assert hw.input_map is not None and hw.output_map is not None and hw.fit_percent > 99.0


def test_identify_narx_selects_terms():
    rng = np.random.default_rng(3)
    u = np.repeat(rng.choice(np.arange(0.0, 101.0, 5.0), 200), 10)
    u[:10], u[10:20] = 0.0, 100.0
    v = u / 50.0 - 1.0
    y = np.zeros(len(u))
    for t in range(2, len(u)):
        y[t] = -0.605 * y[t - 1] - 0.163 * y[t - 2] ** 2 + 0.588 * v[t - 1] - 0.240 * v[t - 2]
    m = pneumid.identify("narx", dataset(u, y), na=2, nb=2, nk=1)
    assert set(m.narx["terms"]) == {"y(t-1)", "y(t-2)^2", "u(t-1)", "u(t-2)"}
    assert m.fit_percent > 99.9
