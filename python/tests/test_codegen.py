"""Embedded C code generation from Python: the module written by write_c()
compiles with gcc -std=c99 -pedantic -Werror and, loaded with ctypes,
returns the library controller's inputs (double precision: identical)."""
import ctypes
import shutil
import subprocess

import pytest

import pneumid


def test_generate_c_reports_sizes_and_texts():
    c = pneumid.make_controller(pneumid.paper_fopdt_model(), 0.01, "dmc", "explicit", M=5, P=126,
                                lambda_=2.25)
    g = pneumid.generate_c(c, precision="float", prefix="paper")
    assert g["controller"] == "dmc" and g["prefix"] == "paper" and g["precision"] == "float"
    assert "typedef float paper_real;" in g["header"]
    assert "paper_step(paper_state* s" in g["source"]
    assert g["ram_bytes"] % 4 == 0 and g["ram_bytes"] > 4 * 126
    with pytest.raises(pneumid.InvalidArgument, match="above the budget of 100 bytes"):
        pneumid.generate_c(c, max_ram=100)
    with pytest.raises(pneumid.InvalidArgument, match="not a C identifier"):
        pneumid.generate_c(c, prefix="a-b")


def test_generate_c_certificate_caps_the_qp_by_the_clock():
    c = pneumid.make_controller(pneumid.paper_fopdt_model(), 0.01, "mpc", u_min=0.0, u_max=100.0)
    fast = pneumid.generate_c(c, precision="float", cpu_mhz=168.0)["certificate"]
    slow = pneumid.generate_c(c, precision="float", cpu_mhz=30.0)["certificate"]
    assert fast["max_cycles_per_step"] <= fast["budget_cycles"] == 0.5 * 0.01 * 168e6
    assert 1 <= slow["qp_max_iterations"] < fast["qp_max_iterations"]
    assert slow["max_cycles_per_step"] <= slow["budget_cycles"]
    with pytest.raises(pneumid.InvalidArgument, match="certificate cannot be met"):
        pneumid.generate_c(c, precision="float", cpu_mhz=1.0, period=0.001)


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")
@pytest.mark.parametrize("kind", ["dmc", "gpc", "pid", "mpc"])
def test_written_module_runs_like_the_library(tmp_path, kind):
    model = pneumid.paper_fopdt_model()
    make = lambda: pneumid.make_controller(model, 0.01, kind, u_min=0.0, u_max=100.0)
    paths = pneumid.write_c(make(), str(tmp_path), prefix="ctl")
    assert sorted(p.split("/")[-1] for p in paths) == ["README.md", "ctl.c", "ctl.h"]
    so = tmp_path / "libctl.so"
    subprocess.run(["gcc", "-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror", "-O2",
                    "-ffp-contract=off", "-fPIC", "-shared", str(tmp_path / "ctl.c"), "-o",
                    str(so), "-lm"], check=True)
    lib = ctypes.CDLL(str(so))
    lib.ctl_step.restype = ctypes.c_double
    lib.ctl_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double]
    lib.ctl_reset.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double]
    g = pneumid.generate_c(make(), prefix="ctl")
    state = ctypes.create_string_buffer(g["ram_bytes"] + 16)
    reference = make()
    reference.reset(0.0, 0.0)
    lib.ctl_reset(state, 0.0, 0.0)
    # A first-order response to the inputs as the measurement: the loop is closed.
    y = 0.0
    for k in range(300):
        r = 40.0 if k >= 10 else 0.0
        u_lib = reference.update(r, y)
        u_c = lib.ctl_step(state, r, y)
        assert u_c == u_lib, (k, u_c, u_lib)
        y = 0.95 * y + 0.05 * 1.6 * u_lib
