"""The lab's own actuator as the plant: a saved surrogate or a measurements CSV of its design."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.cli import main
from softbend.control.plants import lab_angle_table, plant_table
from softbend.design import sfrba_design
from softbend.registry import UnknownNameError
from softbend.transfer.lab import shipped_measurements
from softbend.transfer.measurements import load_measurements, save_measurements

SHIPPED_MLP = "src/softbend/data/transfer/table1_fem_mlp.json"
#: A design outside Table 1 and the virtual lab (the lab's own prototype).
OWN = sfrba_design(130, 7, 2.5, 3, 10, 9)
OTHER = sfrba_design(100, 6, 2, 2, 5, 8)


@pytest.fixture(scope="module")
def own_readings(tmp_path_factory):
    """Readings of the prototype: the virtual lab's (100,6,2,2,5,8) curve, relabelled."""
    lab = shipped_measurements()
    frame = lab.frame.copy()
    first = frame["actuator_id"].iloc[0]
    frame = frame[frame["actuator_id"] == first].copy()
    for column, value in zip(("l", "r", "t", "b", "phi", "lc"), OWN.as_array(), strict=True):
        frame[column] = value
    frame["actuator_id"] = "prototype-1"
    path = tmp_path_factory.mktemp("own") / "prototype.csv"
    save_measurements(type(lab).from_frame(frame), path)
    return path, frame


def test_a_saved_surrogate_is_the_plant(tmp_path):
    table = plant_table(SHIPPED_MLP, OWN, model_table=None)
    from softbend.surrogates.persistence import load_surrogate

    model = load_surrogate(SHIPPED_MLP).model
    p = np.array([0.0, 0.05, 0.1])
    got = [table(float(q)) for q in p]
    np.testing.assert_allclose(got, model.predict(OWN.feature_rows(p)), atol=0.05)


def test_a_measurements_file_is_the_plant(own_readings):
    path, frame = own_readings
    table = plant_table(str(path), OWN, model_table=None)
    loading = frame[frame["direction"] == "loading"]
    # The smoothed curve passes close to the readings (camera noise of a few degrees).
    fitted = [table(float(q)) for q in loading["pressure_mpa"]]
    residual = np.asarray(fitted) - loading["angle_deg"].to_numpy()
    assert np.sqrt(np.mean(residual**2)) < 5.0
    with pytest.raises(ValueError, match=r"no measured loading curve in .*prototype\.csv"):
        lab_angle_table(OTHER, measurements=load_measurements(path), source=str(path))


def test_an_unknown_plant_names_the_files_it_could_be():
    with pytest.raises(UnknownNameError, match="known: surrogate, fem, lab"):
        plant_table("moon.txt", OWN, model_table=None)


def test_control_simulate_on_the_lab_actuator(own_readings, tmp_path, capsys):
    path, _ = own_readings
    args = ["control", "simulate", "--design", "130,7,2.5,3,10,9", "--duration", "3",
            "--json", "--reference", "step:60"]  # fmt: skip
    results = {}
    for name, plant in (("model", SHIPPED_MLP), ("readings", str(path))):
        assert main([*args, "--plant", plant, "-o", str(tmp_path / name)]) == 0
        results[name] = json.loads(capsys.readouterr().out)
        assert results[name]["plant"] == plant
    # The readings are of another actuator than the MLP predicts for the design: a mismatch.
    assert results["model"]["metrics"]["mape_pct"] != results["readings"]["metrics"]["mape_pct"]
