"""Empty arrays are bad input: each entry point raises ValueError naming the
function and the argument instead of returning an empty or undefined result."""
import numpy as np
import pytest

import pneumid

EMPTY = np.zeros(0)


def test_dataset_rejects_empty_columns():
    with pytest.raises(ValueError, match=r"Dataset: time is empty"):
        pneumid.Dataset(EMPTY, np.zeros((0, 1)), np.zeros((0, 1)))


def test_dataset_from_uniform_rejects_empty_input():
    with pytest.raises(ValueError, match=r"Dataset.from_uniform: u is empty"):
        pneumid.Dataset.from_uniform(0.01, EMPTY, EMPTY)


def test_lsim_rejects_empty_input():
    g = pneumid.paper_arx_model()
    with pytest.raises(ValueError, match=r"lsim: u is empty"):
        pneumid.lsim(g, EMPTY, 0.01)


def test_bode_rejects_an_empty_frequency_grid():
    g = pneumid.paper_arx_model()
    with pytest.raises(ValueError, match=r"bode: omega is empty"):
        pneumid.bode(g, EMPTY)
    # Without a grid the frequencies are chosen automatically.
    assert len(pneumid.bode(g)["omega"]) > 0
