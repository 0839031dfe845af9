"""calibrate: grey-box identification of the IPA simulator's physical
parameters. Data simulated (with sensor noise and ADC quantization) from a
perturbed parameter file must give back the perturbed values, and the twin
must fit an experiment it was not calibrated on."""
import math
from pathlib import Path

import numpy as np
import pytest

import pneumid

TS = 0.01
DEFAULT_FREE = [
    "valves.inlet_conductance",
    "valves.exhaust_conductance",
    "valves.inlet_critical_ratio",
    "valves.exhaust_critical_ratio",
    "cylinder.bore",
    "valves.open_delay",
]


# The twin whose lag is in the chamber: its force shows the valves' fill and
# vent, so every default free parameter is determined (the built-in twin senses
# the chamber through a 0.22 s low-pass, behind which they hardly show).
CHAMBER_LAG = str(Path(__file__).resolve().parents[2] / "config" / "ipa_chamber_lag.toml")


def experiment(config, signal, duration, seed):
    plant = pneumid.make_plant(f"ipa:config={config}", TS, seed=seed)
    return pneumid.run_experiment(plant, signal, duration)


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    """A perturbed actuator (every default free parameter 5-12 % off the
    chamber-lag twin), its TOML, two calibration experiments and a held-out step."""
    base = pneumid.load_ipa_parameters(CHAMBER_LAG)
    rng = np.random.default_rng(2024)
    true = {
        name: base[name] * (1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(0.05, 0.12))
        for name in DEFAULT_FREE
    }
    d = tmp_path_factory.mktemp("calibrate")
    config = d / "perturbed.toml"
    config.write_text(pneumid.ipa_parameters_to_toml({**base, **true}, "perturbed actuator"))
    prbs = experiment(config, "prbs:low=10,high=90,order=7,clock=0.05,at=0.5", 4.0, 11)
    stairs = experiment(config, "staircase:levels=10 40 70 30,dwell=1", 4.0, 12)
    step = experiment(config, "step:from=0.61,to=82,at=0.5", 3.0, 13)
    summary = pneumid.calibrate([("prbs", prbs), ("staircase", stairs)], start=CHAMBER_LAG,
                                validation=[("step", step)], output=d / "twin.toml")
    return {"true": true, "dir": d, "config": config, "prbs": prbs, "stairs": stairs,
            "step": step, "summary": summary}


def test_perturbed_file_is_read_back(rig):
    loaded = pneumid.load_ipa_parameters(str(rig["config"]))
    for name, value in rig["true"].items():
        assert loaded[name] == value
    assert loaded["mode"] == "force"


def test_recovers_perturbed_parameters(rig):
    s = rig["summary"]
    assert s["termination"] == "convergence", s["message"]
    assert sorted(s["parameters"]) == sorted(DEFAULT_FREE)
    for name, true in rig["true"].items():
        p = s["parameters"][name]
        assert abs(p["value"] / true - 1.0) < 0.05, (name, p["value"], true)
        assert p["determined"] and not p["at_bound"]
        assert p["std"] is not None and 0.0 < p["std"] < 0.1 * abs(p["value"])
        assert p["lower"] <= p["value"] <= p["upper"]
        assert p["start"] == pytest.approx(pneumid.load_ipa_parameters(CHAMBER_LAG)[name])
    assert s["parameters"]["cylinder.bore"]["unit"] == "m"
    assert s["warnings"] == []
    # The start (the chamber-lag twin) fits worse than the calibrated twin.
    for e in s["experiments"]:
        assert e["fit_percent"] >= 99.0
        assert e["initial_fit_percent"] < e["fit_percent"]
    assert [e["name"] for e in s["experiments"]] == ["prbs", "staircase"]
    assert s["final_cost"] < s["initial_cost"]


def test_held_out_experiment_fit(rig):
    s = rig["summary"]
    (v,) = s["validation"]
    assert v["name"] == "step" and v["samples"] == len(rig["step"])
    assert v["fit_percent"] >= 99.0
    assert v["simulated"].shape == (len(rig["step"]),)
    assert pneumid.nrmse_fit(rig["step"].y(0), v["simulated"]) == pytest.approx(v["fit_percent"])
    # The experiments' simulations are the twin's output on their samples.
    e = s["experiments"][0]
    assert pneumid.nrmse_fit(rig["prbs"].y(0), e["simulated"]) == pytest.approx(e["fit_percent"])


def test_twin_toml_round_trip(rig):
    s = rig["summary"]
    twin_path = rig["dir"] / "twin.toml"
    assert s["output"] == str(twin_path)
    assert twin_path.read_text() == s["toml"]
    assert "pneumid.calibrate" in s["toml"]
    loaded = pneumid.load_ipa_parameters(twin_path)
    for name, value in s["twin"].items():
        assert loaded[name] == value, name
    for name, p in s["parameters"].items():
        assert loaded[name] == p["value"]
    # The twin file drives the simulator and reproduces the validation simulation.
    sim = pneumid.simulate_ipa_on_data(str(twin_path), rig["step"])
    assert np.allclose(sim, s["validation"][0]["simulated"], rtol=0, atol=1e-9)
    data = experiment(twin_path, "step:from=0.61,to=82,at=0.5", 1.0, 1)
    assert len(data) == 101


def test_free_subset_with_bounds_and_dict_start(rig):
    start = {"bore": 0.0175, "mode": "force", "pwm_mode": "switching"}
    s = pneumid.calibrate([rig["prbs"]], start=start, free=["bore", "inlet_conductance"],
                          bounds={"bore": (0.015, 0.02)}, num_threads=1, max_iterations=50)
    assert list(s["parameters"]) == ["cylinder.bore", "valves.inlet_conductance"]
    bore = s["parameters"]["cylinder.bore"]
    assert (bore["start"], bore["lower"], bore["upper"]) == (0.0175, 0.015, 0.02)
    assert s["twin"]["valves.exhaust_conductance"] == pneumid.load_ipa_parameters()[
        "valves.exhaust_conductance"]
    assert s["termination"] in ("convergence", "no_convergence")
    # The actuator's bore (21.5 mm, 6 % over the chamber-lag twin's) lies above
    # the bound: the estimate ends on it, and the free parameters improve the
    # fit of the start (53 %) whatever the termination.
    assert bore["value"] == pytest.approx(0.02, abs=1e-9)
    assert rig["true"]["cylinder.bore"] > 0.02
    e = s["experiments"][0]
    assert e["fit_percent"] > e["initial_fit_percent"] + 5.0
    # A single Dataset is a list of one; unnamed data are named by their source.
    t = pneumid.calibrate(rig["prbs"], free=["bore"], max_iterations=0)
    assert t["experiments"][0]["name"] == rig["prbs"].source
    assert t["iterations"] == 0 and t["termination"] == "no_convergence"


def test_unknown_parameter_name_raises(rig):
    with pytest.raises(ValueError, match="unknown IPA parameter 'nosuch'"):
        pneumid.calibrate([rig["prbs"]], free=["bore", "nosuch"])
    with pytest.raises(pneumid.InvalidArgument, match="unknown IPA parameter 'nosuch'"):
        pneumid.calibrate([rig["prbs"]], start={"nosuch": 1.0})
    with pytest.raises(ValueError, match="unknown IPA parameter 'nosuch'"):
        pneumid.calibrate([rig["prbs"]], free=["bore"], bounds={"nosuch": (0.0, 1.0)})


def test_bad_input_raises_with_the_library_message(rig):
    prbs = rig["prbs"]
    with pytest.raises(ValueError, match=r"start value of 'cylinder.bore', 0.020266 m, is outside"):
        pneumid.calibrate([prbs], free=["bore"], bounds={"bore": (0.03, 0.04)})
    with pytest.raises(ValueError, match="not a physical parameter"):
        pneumid.calibrate([prbs], free=["simulation.relative_tolerance"])
    with pytest.raises(ValueError, match="named twice"):
        pneumid.calibrate([prbs], free=["bore", "cylinder.bore"])
    with pytest.raises(ValueError, match="not a free parameter"):
        pneumid.calibrate([prbs], free=["bore"], bounds={"open_delay": (0.0, 0.01)})
    flat = pneumid.Dataset(prbs.time, np.full(len(prbs), 50.0), prbs.y(0))
    with pytest.raises(ValueError, match="flat: no excitation"):
        pneumid.calibrate([("flat", flat)])
    with pytest.raises(ValueError, match="at least one experiment"):
        pneumid.calibrate([])
    with pytest.raises(ValueError, match="neither a Dataset"):
        pneumid.calibrate([(prbs.time, prbs.u(0), prbs.y(0))])
    with pytest.raises(ValueError, match="initial state"):
        pneumid.calibrate([prbs], initial_state="warm")
    with pytest.raises(ValueError, match="must be a number"):
        pneumid.calibrate([prbs], start={"bore": "wide"})
    y = prbs.y(0).copy()
    y[40] = math.nan
    with pytest.raises(ValueError):  # NaN data never reach the calibration
        pneumid.Dataset(prbs.time, prbs.u(0), y)
