"""Plain measurement CSVs of a described actuator: columns, units, designs, radians."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.actuators import Actuator, ActuatorError, DesignParameter
from softbend.errors import DatasetError
from softbend.transfer.measurements import load_actuator_measurements

ACTUATOR = Actuator(
    name="bellows",
    title="a bellows for tests",
    parameters=(
        DesignParameter("n_folds", "", 3, 9, kind="integer"),
        DesignParameter("wall_mm", "mm", 0.5, 2.0),
        DesignParameter("skin", kind="categorical", levels=("latex", "fabric")),
    ),
    pressure_column="p_kpa",
    pressure_unit="kPa",
)
HEADER = "actuator,n_folds,wall_mm,skin,p_kpa,angle_deg"
GOOD = [
    "A1,5,1.0,latex,0,0.5",
    "A1,5,1.0,latex,20,31.0",
    "A1,5,1.0,latex,40,58.2",
    "A2,7,1.5,fabric,0,-1.0",
    "A2,7,1.5,fabric,30,40.0",
]


def write(tmp_path, lines, name="lab.csv", header=HEADER, preamble=()):
    path = tmp_path / name
    path.write_text("\n".join([*preamble, header, *lines]) + "\n", encoding="utf-8")
    return path


def test_a_plain_file_reads_into_model_inputs(tmp_path):
    data = load_actuator_measurements(write(tmp_path, GOOD), ACTUATOR)
    assert data.actuator_ids == ("A1", "A2")
    np.testing.assert_array_equal(data.features[3], [7, 1.5, 1, 0])
    np.testing.assert_array_equal(data.angle_deg, [0.5, 31.0, 58.2, -1.0, 40.0])
    assert data.per_actuator().loc["A1", "pmax"] == 40
    assert len(data.subset(["A2"])) == 2
    assert not data.synthetic.any()


def test_the_key_value_header_is_optional_and_kept(tmp_path):
    path = write(tmp_path, GOOD, preamble=("# synthetic: true", "# rig: bench 2"))
    data = load_actuator_measurements(path, ACTUATOR)
    assert data.metadata == {"synthetic": "true", "rig": "bench 2"}
    assert data.synthetic.all()


def test_several_files_join(tmp_path):
    a = write(tmp_path, GOOD[:3], "a.csv")
    b = write(tmp_path, GOOD[3:], "b.csv")
    data = load_actuator_measurements([a, b], ACTUATOR)
    assert data.actuator_ids == ("A1", "A2")
    assert data.provenance["source"].tolist() == [str(a)] * 3 + [str(b)] * 2


@pytest.mark.parametrize(
    ("header", "lines", "match"),
    [
        ("actuator,n_folds,wall_mm,p_kpa,angle_deg", ["A1,5,1.0,0,0"], "lacks the column.*skin"),
        (
            "actuator,n_folds,wall,skin,p_kpa,angle_deg",
            ["A1,5,1.0,latex,0,0"],
            "lacks the column.*wall_mm.*has column.*wall",
        ),
        ("actuator,n_folds,wall_mm,skin,pressure_mpa,angle_deg", ["A1,5,1,latex,0,0"], "p_kpa"),
        (
            HEADER,
            ["A1,5.5,1.0,latex,0,0"],
            r"lab\.csv:2:2: n_folds must be a whole number in \[3, 9\]; got 5\.5$",
        ),
        (
            HEADER,
            ["A1,5,1.0,rubber,0,0"],
            r"lab\.csv:2:4: skin must be one of the levels latex, fabric",
        ),
        (HEADER, ["A1,5,9.0,latex,0,0"], r"wall_mm.*\[0.5, 2\]"),
        (HEADER, ["A1,5,1.0,latex,-3,0"], ">= 0 kPa"),
        (HEADER, ["A1,5,1.0,latex,nan,0"], "finite"),
        (
            HEADER,
            [",5,1.0,latex,0,0"],
            r"lab\.csv:2:1: actuator: must be non-empty text; got an empty cell",
        ),
        (HEADER, ["A1,5,1.0,latex,0,0", "A1,6,1.0,latex,10,20"], "two designs"),
    ],
)
def test_bad_files_are_one_error_naming_the_column(tmp_path, header, lines, match):
    with pytest.raises(ActuatorError, match=match):
        load_actuator_measurements(write(tmp_path, lines, header=header), ACTUATOR)


def test_small_angles_are_read_as_given(tmp_path):
    # whether they are radians depends on the actuator: transfer.against_base judges
    path = write(tmp_path, ["A1,5,1.0,latex,0,0", "A1,5,1.0,latex,40,0.9"])
    data = load_actuator_measurements(path, ACTUATOR)
    assert data.angle_deg[-1] == pytest.approx(0.9)


def test_missing_and_empty_files(tmp_path):
    with pytest.raises(DatasetError, match=r"none.csv: no such file"):
        load_actuator_measurements(tmp_path / "none.csv", ACTUATOR)
    with pytest.raises(DatasetError, match="followed by 0 data row"):
        load_actuator_measurements(write(tmp_path, []), ACTUATOR)


def test_both_id_columns_at_once_are_refused_naming_both(tmp_path):
    header = "actuator,actuator_id,n_folds,wall_mm,skin,p_kpa,angle_deg"
    path = write(tmp_path, ["A1,A1,5,1.0,latex,0,0.5"], header=header)
    match = r"lab\.csv:1:2: actuator_id: .*by the columns actuator and actuator_id"
    with pytest.raises(ActuatorError, match=match):
        load_actuator_measurements(path, ACTUATOR)


def test_one_reader_reads_each_actuator_s_files_in_its_format(tmp_path):
    from softbend.actuators import SFRBA
    from softbend.transfer.lab import shipped_measurements
    from softbend.transfer.measurements import (
        ActuatorMeasurements,
        Measurements,
        Readings,
        read_measurements,
        save_measurements,
    )

    other = read_measurements(write(tmp_path, GOOD), ACTUATOR)
    assert isinstance(other, ActuatorMeasurements) and other.actuator == ACTUATOR
    paper_b = save_measurements(shipped_measurements(), tmp_path / "paper_b.csv")
    read = read_measurements([paper_b], SFRBA)
    assert isinstance(read, Measurements) and read == shipped_measurements()
    assert isinstance(read, Readings) and read.actuator == SFRBA
    assert read.per_actuator()["pmax"].max() == read.frame["pressure_mpa"].max()


@pytest.mark.parametrize("actuator", ["bellows", "bellows-bend", "sfrba"])
def test_written_readings_read_back_in_the_actuator_s_own_format(tmp_path, actuator):
    import dataclasses

    import pandas as pd

    from softbend.actuators import SFRBA
    from softbend.transfer.measurements import (
        ActuatorMeasurements,
        Measurements,
        read_measurements,
        write_measurements,
    )

    # "bellows-bend": a lab's table whose angle column is its own name
    bend = dataclasses.replace(ACTUATOR, angle_column="bend_deg")
    described = {"bellows": ACTUATOR, "bellows-bend": bend, "sfrba": SFRBA}[actuator]
    bellows = [
        {"n_folds": 5, "wall_mm": 1.0, "skin": "latex"},
        {"n_folds": 7, "wall_mm": 1.5, "skin": "fabric"},
    ]
    designs = {
        "bellows": bellows,
        "bellows-bend": bellows,
        "sfrba": [{"l_mm": 100.0, "r_mm": 6.0, "t_mm": 2.0, "b_mm": 2.0, "phi_deg": 5.0,
                   "lc_mm": 8.0},
                  {"l_mm": 120.0, "r_mm": 7.0, "t_mm": 2.5, "b_mm": 2.0, "phi_deg": 10.0,
                   "lc_mm": 10.0}],
    }[actuator]  # fmt: skip
    rows = pd.DataFrame(
        [
            {"actuator_id": f"fem-{i}", **design, described.pressure_column: p,
             "angle_deg": 10.0 * i + 100.0 * p}
            for i, design in enumerate(designs, start=1)
            for p in (0.0, 0.02, 0.05)
        ]
    )  # fmt: skip
    path = write_measurements(rows, described, tmp_path / "curves.csv", {"synthetic": "true"})
    data = read_measurements(path, described)
    kind = Measurements if actuator == "sfrba" else ActuatorMeasurements
    assert isinstance(data, kind)
    assert data.actuator_ids == ("fem-1", "fem-2")
    np.testing.assert_allclose(data.angle_deg, rows["angle_deg"])
    assert data.synthetic.all()  # the header marks them simulated
    codes = [[p.encode(d[p.name]) for p in described.parameters] for d in designs]
    np.testing.assert_allclose(data.features[:, :-1], np.repeat(codes, 3, axis=0))
