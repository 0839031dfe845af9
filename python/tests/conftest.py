import os
import pathlib

import pytest


@pytest.fixture(scope="session")
def out_dir():
    base = os.environ.get("PNEUMID_BINARY_DIR")
    d = pathlib.Path(base) / "test-output" / "python" if base else pathlib.Path("/tmp/pneumid-pytest")
    d.mkdir(parents=True, exist_ok=True)
    return d
