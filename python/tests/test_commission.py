"""pneumid.commission: the library function behind `pneumid commission`, on a
plant whose probe answers are known in closed form (a FOPDT: the two-point
method is exact up to one sample); the result is the JSON of the command
line."""

import pytest

import pneumid


def test_commission_of_a_fopdt_plant_measures_it_and_meets_the_specification(tmp_path):
    plant = pneumid.make_plant("fopdt:K=2,tau=0.5,theta=0.1", 0.01)
    r = pneumid.commission(plant, str(tmp_path), range=(2.0, 18.0), budget=160.0,
                           methods=["arx", "oe"], u_min=0.0, u_max=10.0,
                           settling=2.0)
    probe = r["experiment"]["probe"]
    assert probe["gain"] == pytest.approx(2.0, rel=0.01)
    assert probe["time_constant"] == pytest.approx(0.5, abs=0.015)
    assert probe["dead_time"] == pytest.approx(0.1, abs=0.015)
    assert r["termination"] == "success", r["message"]
    assert r["passed"] and r["verification"]["overshoot_percent"] <= 5.0
    assert len(r["trace"]["t"]) == len(r["trace"]["y"]) > 0
    assert len(r["data"]) > 1000
    assert (tmp_path / "models.json").exists()
    assert "files" not in r and not (tmp_path / "controller.toml").exists()


def test_commission_writes_the_files_of_the_command_with_a_plant_spec(tmp_path):
    spec = "fopdt:K=2,tau=0.5,theta=0.1"
    r = pneumid.commission(pneumid.make_plant(spec, 0.01), str(tmp_path), range=(2.0, 18.0),
                           budget=160.0, methods=["arx", "oe"], u_min=0.0, u_max=10.0,
                           settling=2.0, plant_spec=spec)
    toml = (tmp_path / "controller.toml").read_text()
    assert "[controller]" in toml and f'plant = "{spec}"' in toml
    for name in ["data.csv", "verification.csv", "c/pneumid_ctrl.c"]:
        assert str(tmp_path / name) in r["files"]["written"], name
        assert (tmp_path / name).exists(), name


def test_commission_reports_a_range_out_of_reach(tmp_path):
    plant = pneumid.make_plant("fopdt:K=2,tau=0.5,theta=0.1", 0.01)
    r = pneumid.commission(plant, str(tmp_path), range=(5.0, 50.0), u_min=0.0, u_max=10.0)
    assert r["termination"] == "failure"
    assert "cannot be reached" in r["message"]
    with pytest.raises(pneumid.InvalidArgument):
        pneumid.commission(plant, str(tmp_path), budget=-1.0, u_min=0.0, u_max=10.0)
