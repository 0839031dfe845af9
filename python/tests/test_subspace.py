"""n4sid options from Python: the D term and the weighting."""
import numpy as np
import pytest
from scipy.signal import dlsim

import pneumid

TS = 0.01


def plant_data(d, n=3000, seed=3):
    """x(t+1) = [1.5 -0.7; 1 0] x + [1; 0] u, y = [0.5 0.3] x + d u, white input."""
    a = np.array([[1.5, -0.7], [1.0, 0.0]])
    rng = np.random.default_rng(seed)
    u = rng.normal(0.0, 1.0, n)
    _, y, _ = dlsim((a, [[1.0], [0.0]], [[0.5, 0.3]], [[d]], TS), u)
    return pneumid.Dataset.from_uniform(TS, u, y[:, 0])


@pytest.mark.parametrize("weight", ["moesp", "n4sid", "cva"])
def test_n4sid_estimates_the_d_term_with_each_weighting(weight):
    data = plant_data(0.5)
    m = pneumid.identify("n4sid", data, na=2, feedthrough=True, n4sid_weight=weight)
    assert m.params["D"][0][0] == pytest.approx(0.5, abs=1e-6)
    assert m.fit_percent > 99.9
    assert pneumid.identify("n4sid", data, na=2).params["D"][0][0] == 0.0


def test_n4sid_rejects_an_unknown_weighting():
    with pytest.raises(ValueError, match="unknown subspace weighting 'ssarx'"):
        pneumid.identify("n4sid", plant_data(0.0), na=2, n4sid_weight="ssarx")


def test_estimate_initial_state_recovers_x0():
    a = np.array([[1.5, -0.7], [1.0, 0.0]])
    sys = pneumid.StateSpace(a, [[1.0], [0.0]], [[0.5, 0.3]], [[0.5]], TS)
    u = np.random.default_rng(4).normal(0.0, 1.0, (400, 1))
    y = pneumid.simulate_from_state(sys, u, [3.0, -2.0])
    _, yref, _ = dlsim((a, [[1.0], [0.0]], [[0.5, 0.3]], [[0.5]], TS), u[:, 0], x0=[3.0, -2.0])
    np.testing.assert_allclose(y[:, 0], yref[:, 0], atol=1e-10)
    np.testing.assert_allclose(pneumid.estimate_initial_state(sys, u, y), [3.0, -2.0], atol=1e-9)
