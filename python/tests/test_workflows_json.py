"""identify_json and tune_json give the dicts `pneumid identify --json` and
`pneumid tune --json` print for the same inputs (both call the library's
RunIdentifyWorkflow / RunTuneWorkflow), and the same errors."""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest
from scipy.signal import lfilter

import pneumid

SOURCE = pathlib.Path(os.environ.get("PNEUMID_SOURCE_DIR",
                                     pathlib.Path(__file__).resolve().parents[2]))
DATA = SOURCE / "tests" / "identify" / "data"
BINARY = pathlib.Path(os.environ.get("PNEUMID_BINARY_DIR", "")) / "pneumid"

pytestmark = pytest.mark.skipif(not BINARY.is_file(),
                                reason="needs the pneumid program ($PNEUMID_BINARY_DIR/pneumid)")


def cli(*args):
    """The JSON `pneumid ARGS --json` prints."""
    out = subprocess.run([str(BINARY), *map(str, args), "--json"], check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout)


def cli_error(*args):
    """The message of a failing `pneumid ARGS --json` ("pneumid CMD: error: MESSAGE")."""
    out = subprocess.run([str(BINARY), *map(str, args), "--json"], capture_output=True, text=True)
    assert out.returncode == 1, out
    return out.stderr.strip().split(": error: ", 1)[1]


def write_prbs(path, seed):
    """3000 samples of the paper's ARX(3,3,1) force model driven by a PRBS (t,u,y)."""
    rng = np.random.default_rng(seed)
    n = 3000
    u = np.repeat(np.where(rng.random(n // 3) > 0.5, 90.0, 10.0), 3)
    a = [1, -0.6087, -0.2702, -0.06021]
    y = lfilter([0, 0.03938, 0.04506, 0.01286], a, u) + lfilter([1], a, rng.normal(0, 0.3, n))
    np.savetxt(path, np.c_[np.arange(n) * 0.01, u, y], delimiter=",", header="t,u,y",
               comments="")
    return path


@pytest.fixture(scope="module")
def prbs(tmp_path_factory):
    d = tmp_path_factory.mktemp("workflows")
    return write_prbs(d / "prbs.csv", 5), write_prbs(d / "prbs2.csv", 6)


def load(path):
    return pneumid.Dataset.load(str(path))


def test_identify_step_methods():
    f = DATA / "fopdt.csv"
    j = pneumid.identify_json(load(f), "reaction-curve,fit-p1d,ptn", order=2)
    assert j == cli("identify", f, "-m", "reaction-curve,fit-p1d,ptn", "--order", 2)
    assert j["best"] == "fit-p1d" and j["ranked_by"] == "fit_percent"


def test_identify_split_detrend_and_failures(prbs):
    f, _ = prbs
    j = pneumid.identify_json(load(f), ["reaction-curve", "arx", "oe", "fit-p1d"], split=0.7,
                              detrend="constant")
    assert j == cli("identify", f, "-m", "reaction-curve,arx,oe,fit-p1d", "--split", 0.7,
                    "--detrend", "constant")
    assert j["ranked_by"] == "validation_fit_percent" and j["termination"] == "partial"
    assert j["failures"][0]["method"] == "reaction-curve"


def test_identify_validation_file(prbs):
    f, v = prbs
    j = pneumid.identify_json(load(f), "arx,fit-p1d", validation=load(v), na=2, nb=2)
    assert j == cli("identify", f, "-m", "arx,fit-p1d", "--validation", v, "--na", 2, "--nb", 2)
    assert j["validation_samples"] == 3000


def test_identify_window_loss():
    f = DATA / "fopdt.csv"
    j = pneumid.identify_json(load(f), "fit-p1d,fit-p2d", loss="huber", window="0.2:")
    assert j == cli("identify", f, "-m", "fit-p1d,fit-p2d", "--loss", "huber", "--window", "0.2:")
    assert "preprocessing" in j["models"][0]


def test_identify_nonlinear_chosen_structure():
    f = DATA / "hammerstein.csv"
    j = pneumid.identify_json(load(f), "static-map,hammerstein", knots=6)
    assert j == cli("identify", f, "-m", "static-map,hammerstein", "--knots", 6)


def test_identify_errors(prbs):
    f, v = prbs
    with pytest.raises(pneumid.InvalidArgument) as e:
        pneumid.identify_json(load(f), "arx", split=0.5, validation=load(v))
    assert str(e.value) == cli_error("identify", f, "-m", "arx", "--split", 0.5,
                                     "--validation", v)
    with pytest.raises(pneumid.DataError) as e:
        pneumid.identify_json(load(f), "reaction-curve,tangent")
    assert str(e.value) == cli_error("identify", f, "-m", "reaction-curve,tangent")


@pytest.mark.parametrize("args, kwargs", [
    (["--rule", "shridhar-cooper", "--M", 5], dict(rule="shridhar-cooper", M=5)),
    (["--rule", "paper-modified"], dict(rule="paper-modified")),
    (["--rule", "explicit", "--P", 50, "--M", 4, "--lambda", 0.5],
     dict(rule="explicit", P=50, M=4, lambda_=0.5)),
    (["--tau-digits", 0], dict(tau_digits=0)),
    (["--rule", "auto", "--controller", "mpc"], dict(rule="auto", controller="mpc")),
    (["--rule", "auto", "--controller", "pid", "--aggressiveness", 0.2],
     dict(rule="auto", controller="pid", aggressiveness=0.2)),
    (["--rule", "auto", "--controller", "dmc", "--response-time", 0.246],
     dict(rule="auto", controller="dmc", response_time=0.246)),
    (["--rule", "auto", "--plant", "ipa"], dict(rule="auto", plant="ipa")),
    (["--rule", "auto", "--measure", "settling", "--overshoot", 3, "--du-max", 5],
     dict(rule="auto", measure="settling", overshoot=3, du_max=5)),
])
def test_tune(args, kwargs):
    j = pneumid.tune_json("fopdt-paper", 0.01, **kwargs)
    assert j == cli("tune", "--model", "fopdt-paper", "--Ts", 0.01, *args)
    assert j["rule"] == kwargs.get("rule", "shridhar-cooper")


def test_tune_model_object():
    spec = "fopdt:K=1.6,tau=0.245,theta=0.001"
    j = pneumid.tune_json(pneumid.parse_model_spec(spec), 0.01, rule="auto")
    assert j == cli("tune", "--model", spec, "--Ts", 0.01, "--rule", "auto")


def test_tune_errors():
    with pytest.raises(pneumid.InvalidArgument) as e:
        pneumid.tune_json("fopdt-paper", 0.01, overshoot=3)
    assert str(e.value) == cli_error("tune", "--model", "fopdt-paper", "--Ts", 0.01,
                                     "--overshoot", 3)
    with pytest.raises(pneumid.InvalidArgument) as e:
        pneumid.tune_json("fopdt-paper", 0.01, rule="auto", P=20)
    assert str(e.value) == cli_error("tune", "--model", "fopdt-paper", "--Ts", 0.01,
                                     "--rule", "auto", "--P", 20)


def test_simulate_control_is_control_json():
    """simulate_control runs RunControlScenario as `pneumid control` does: a
    staircase with a load step on the IPA twin, and a --compare of two rules."""
    args = ["--model", "fopdt-paper", "--plant", "ipa", "--Ts", "0.01",
            "--setpoint", "staircase:levels=0 40 80 40,dwell=1", "--duration", "4"]
    expected = cli("control", *args, "--load-step", "at=3.5,size=-15", "--controller", "mpc")
    got = pneumid.simulate_control("fopdt-paper", plant="ipa", Ts=0.01,
                                   setpoint="staircase:levels=0 40 80 40,dwell=1", duration=4,
                                   load_steps=[(3.5, -15.0)], type="mpc")
    assert got == expected
    assert len(got["steps"]) == 3
    compared = cli("control", *args, "--compare", "shridhar-cooper,paper-modified")
    assert pneumid.simulate_control(
        "fopdt-paper", plant="ipa", Ts=0.01, setpoint="staircase:levels=0 40 80 40,dwell=1",
        duration=4, compare=["shridhar-cooper", "paper-modified"]) == compared
    with pytest.raises(pneumid.InvalidArgument, match="unknown controller setting 'lamda'"):
        pneumid.simulate_control("fopdt-paper", setpoint="step:to=1", duration=1, lamda=2.0)


def test_simulate_control_warns_as_control_does():
    """A set-point beyond the steady outputs of a Hammerstein model's map (the
    v0.1.0 staircase model reaches 0.07..193 N at duty 0..100 %) is a
    UserWarning with the words `pneumid control` prints on stderr."""
    model = str(SOURCE / "tests" / "data" / "model_files" / "v0.1.0-6962d7c" /
                "stair.nonlinear.json") + "#hammerstein"
    args = ["--model", model, "--plant", "ipa", "--setpoint", "staircase:levels=50 250,dwell=1",
            "--duration", "2"]
    out = subprocess.run([str(BINARY), "control", *args, "--json"], check=True,
                         capture_output=True, text=True)
    stderr = out.stderr.strip().split("pneumid control: warning: ", 1)[1]
    with pytest.warns(UserWarning) as caught:
        got = pneumid.simulate_control(model, plant="ipa", setpoint="staircase:levels=50 250,dwell=1",
                                       duration=2)
    assert [str(w.message) for w in caught] == [stderr]
    assert "beyond the steady outputs [0.06562, 193.2]" in stderr
    assert got == json.loads(out.stdout)
    assert got["warnings"] == [stderr]
