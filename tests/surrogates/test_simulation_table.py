"""Training on any actuator's simulation table: columns, units, kinds, bad input, round trip."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from softbend.actuators import SFRBA, Actuator, ActuatorError, get_actuator
from softbend.errors import DatasetError
from softbend.surrogates.persistence import load_surrogate
from softbend.surrogates.predict import predict_angles
from softbend.surrogates.simulation_table import table_training_data
from softbend.surrogates.workflow import train_surrogates

from ..stand_ins import ACTUATOR_COLUMNS as COLUMNS
from ..stand_ins import actuator_law as truth
from ..stand_ins import actuator_table as table


@pytest.fixture(scope="module")
def sims(tmp_path_factory):
    path = tmp_path_factory.mktemp("sims") / "sims.csv"
    table().to_csv(path, index=False)
    return path


def read(path, **kwargs):
    options = {
        "design_columns": COLUMNS,
        "pressure_column": "p_kpa",
        "pressure_unit": "kPa",
        **kwargs,
    }
    return table_training_data(path, **options)


def test_a_table_becomes_training_data_grouped_by_design(sims):
    data = read(sims)
    assert data.X.shape == (24 * 6, 5)
    assert data.n_groups == 24
    a = data.actuator
    assert a.features == ("n_chambers", "wall_mm", "height_mm", "layer", "p_kpa")
    assert [p.kind for p in a.parameters] == ["integer", "continuous", "continuous", "categorical"]
    assert a.pressure_unit == "kPa"
    # a negative angle at zero pressure (pre-curved) is kept
    assert data.y.min() == pytest.approx(-3.0)
    # arrays of its own, writable, even where no row was dropped (no view of the read frame)
    assert all(a.flags.writeable and a.flags.owndata for a in (data.X, data.y, data.groups))


def test_rows_with_a_missing_value_are_dropped_and_counted(tmp_path):
    frame = table()
    frame.loc[[3, 10], "angle_deg"] = np.nan
    frame.loc[17, "p_kpa"] = np.nan
    path = tmp_path / "gaps.csv"
    frame.to_csv(path, index=False)
    data = read(path)
    assert data.n_samples == len(frame) - 3 and data.n_dropped == 3
    kept = frame.drop(index=[3, 10, 17])
    assert np.array_equal(data.y, kept["angle_deg"].to_numpy())
    assert np.array_equal(data.groups, kept["design_id"].to_numpy(dtype=object))


def test_parquet_reads_as_the_csv_does(sims, tmp_path):
    pytest.importorskip("pyarrow")
    parquet = tmp_path / "sims.parquet"
    pd.read_csv(sims).to_parquet(parquet)
    a, b = read(sims), read(parquet)
    np.testing.assert_array_equal(a.X, b.X)
    assert a.data_hash == b.data_hash


def with_cell(column, row, cell):
    """The stand-in table with one cell of ``column`` replaced by ``cell``."""
    frame = table()
    frame[column] = frame[column].astype(object)
    frame.loc[row, column] = cell
    return frame


def test_a_stray_text_cell_in_a_numeric_column_names_file_line_column_and_cell(tmp_path):
    path = tmp_path / "thick.csv"
    with_cell("wall_mm", 7, "thick").to_csv(path, index=False)
    with pytest.raises(DatasetError) as info:
        read(path)
    error = info.value
    # header is line 1, row 7 is line 9; wall_mm is the third column after design_id
    assert (error.file, error.line, error.column, error.key) == (str(path), 9, 3, "wall_mm")
    assert "must be a number" in error.detail and "'thick'" in error.detail.replace('"', "'")


def test_a_number_in_a_text_column_is_refused_not_made_a_level(tmp_path):
    path = tmp_path / "layers.csv"
    with_cell("layer", 4, "3").to_csv(path, index=False)
    with pytest.raises(DatasetError, match=r"layers\.csv:6:5: layer: mixes numbers and text"):
        read(path)


def test_a_text_cell_in_a_column_the_description_declares_numeric(tmp_path):
    path = tmp_path / "described.csv"
    with_cell("wall_mm", 2, "n/a").to_csv(path, index=False)
    described = Actuator.from_table(
        table(),
        design_columns=COLUMNS.split(","),
        pressure_column="p_kpa",
        pressure_unit="kPa",
        name="stand_in",
    )
    with pytest.raises(DatasetError, match=r"described\.csv:4:3: wall_mm: must be a number"):
        table_training_data(path, actuator=described)


def test_numeric_text_in_parquet_reads_as_numbers_and_a_stray_cell_names_its_row(sims, tmp_path):
    pytest.importorskip("pyarrow")
    frame = pd.read_csv(sims)
    for column in ("n_chambers", "wall_mm", "height_mm"):
        frame[column] = frame[column].astype(str)
    parquet = tmp_path / "text.parquet"
    frame.to_parquet(parquet)
    a, b = read(sims), read(parquet)
    assert [p.kind for p in b.actuator.parameters] == [p.kind for p in a.actuator.parameters]
    np.testing.assert_array_equal(a.X, b.X)
    frame.loc[7, "wall_mm"] = "thick"
    frame.to_parquet(parquet)
    with pytest.raises(DatasetError, match=r"text\.parquet: wall_mm: row 7: must be a number"):
        read(parquet)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"design_columns": "n_chambers,wall_mm,height_mm,lyr"}, "no column 'lyr'"),
        ({"pressure_column": "p_mpa"}, "no column 'p_mpa'"),
        ({"angle_column": "theta"}, "no column 'theta'"),
        ({"pressure_unit": "Pa"}, "kPa, MPa, bar, psi"),
        ({"angle_column": "angle_rad"}, "radians"),
        (
            {"pressure_column": "wall_mm"},
            "^pressure_column: 'wall_mm' is also one of the design columns",
        ),
        ({"design_columns": "wall_mm,wall_mm"}, "twice"),
    ],
)
def test_bad_options_are_one_error_naming_the_column(sims, kwargs, match):
    with pytest.raises(ActuatorError, match=match):
        read(sims, **kwargs)


def test_angles_in_radians_are_refused_with_the_factor(tmp_path):
    frame = table()
    frame["angle_deg"] = np.radians(frame["angle_deg"]) / 10
    path = tmp_path / "rad.csv"
    frame.to_csv(path, index=False)
    with pytest.raises(ActuatorError, match=r"57\.2958"):
        read(path)


def test_a_table_outside_a_registered_description_names_the_parameter(tmp_path):
    frame = pd.DataFrame(
        {
            "l_mm": [100.0, 100.0],
            "r_mm": [6.0, 6.0],
            "t_mm": [7.0, 7.0],  # thicker than the radius
            "b_mm": [2.0, 2.0],
            "phi_deg": [5.0, 5.0],
            "lc_mm": [8.0, 8.0],
            "pressure_mpa": [0.0, 0.1],
            "angle_deg": [0.0, 30.0],
        }
    )
    path = tmp_path / "b.csv"
    frame.to_csv(path, index=False)
    with pytest.raises(ActuatorError, match="t_mm < r_mm"):
        table_training_data(path, actuator=get_actuator("sfrba"))


def test_missing_options_without_a_description(sims):
    with pytest.raises(ActuatorError, match=r"^design_columns: is required") as info:
        table_training_data(sims, pressure_column="p_kpa", pressure_unit="kPa")
    assert info.value.key == "design_columns"
    with pytest.raises(ActuatorError, match=r"^pressure_unit: is required"):
        table_training_data(sims, design_columns=COLUMNS, pressure_column="p_kpa")


def test_negative_pressure_and_unreadable_files(tmp_path):
    frame = table(designs=3)
    frame.loc[3, "p_kpa"] = -5.0
    path = tmp_path / "neg.csv"
    frame.to_csv(path, index=False)
    with pytest.raises(DatasetError, match=r"neg\.csv: p_kpa: row 3: .*>= 0 kPa; got -5\.0"):
        read(path)
    bad = tmp_path / "bad.txt"
    bad.write_text("x")
    with pytest.raises(DatasetError, match="CSV or Parquet"):
        read(bad)


@pytest.fixture(scope="module")
def trained(sims, tmp_path_factory):
    out = tmp_path_factory.mktemp("m")
    _, summary = train_surrogates(
        read(sims), out, models="plr", grid_name="quick", folds=3, export_onnx=False
    )
    return out / "models" / "plr.json", summary


def test_a_model_of_a_table_records_its_description_and_round_trips(trained, sims):
    path, summary = trained
    assert summary["actuator"]["pressure_unit"] == "kPa"
    saved = load_surrogate(path)
    assert saved.actuator == read(sims).actuator
    assert saved.actuator != SFRBA
    document = json.loads(path.read_text())
    assert document["features"] == list(saved.actuator.features)
    assert document["units"]["p_kpa"] == "kPa"
    assert set(document["metadata"]["training_ranges"]) == set(saved.actuator.features)


def test_predict_by_name_matches_the_law_it_learned(trained):
    path, _ = trained
    pred = predict_angles(path, "n_chambers=10,wall_mm=2,height_mm=12,layer=paper", [0.0, 25, 50])
    expected = [truth(10, 2.0, 12.0, "paper", p) for p in (0.0, 25, 50)]
    np.testing.assert_allclose(pred.angle_deg, expected, atol=0.15 * max(expected))
    record = pred.to_dict()
    assert record["design"] == {
        "n_chambers": 10,
        "wall_mm": 2.0,
        "height_mm": 12.0,
        "layer": "paper",
    }
    assert "p_kpa" in record and "pressure_mpa" not in record


def test_positional_design_equals_by_name(trained):
    path, _ = trained
    a = predict_angles(path, "n_chambers=9,wall_mm=1.5,height_mm=10,layer=fabric", [20.0])
    b = predict_angles(path, "9,1.5,10,fabric", [20.0])
    np.testing.assert_array_equal(a.angle_deg, b.angle_deg)


def test_outside_the_training_ranges_is_not_supported(trained):
    path, _ = trained
    pred = predict_angles(path, "n_chambers=10,wall_mm=2,height_mm=12,layer=paper", [25.0, 80.0])
    assert pred.supported is not None
    assert pred.supported.tolist() == [True, False]
    assert any("p_kpa" in phrase for phrase in pred.extrapolated)
    with pytest.raises(ValueError, match="p_kpa"):
        predict_angles(
            path, "n_chambers=10,wall_mm=2,height_mm=12,layer=paper", [80.0], strict=True
        )


def test_a_design_past_the_sampled_span_is_an_extrapolation_not_an_error(trained):
    path, _ = trained
    design = "n_chambers=10,wall_mm=1.0,height_mm=12,layer=paper"  # the walls: 1.1 to 2.9 mm
    pred = predict_angles(path, design, [20.0])
    assert pred.outside_training_ranges == ["wall_mm 1 outside [1.1, 2.9]"]
    assert pred.supported is not None and not pred.supported.any()
    with pytest.raises(ValueError, match=r"wall_mm 1 outside \[1\.1, 2\.9\]"):
        predict_angles(path, design, [20.0], strict=True)


def test_declared_ranges_replace_the_sampled_span(sims):
    described = read(sims, ranges=["wall_mm=0.5:3.5", "n_chambers=4:20"]).actuator
    n, wall, height, _ = described.parameters
    assert (wall.low, wall.high, wall.sampled) == (0.5, 3.5, False)
    assert (n.kind, n.low, n.high, n.sampled) == ("integer", 4.0, 20.0, False)
    assert (height.low, height.high, height.sampled) == (8.0, 16.0, True)
    with pytest.raises(ActuatorError, match="must be in"):
        described.parse_design("n_chambers=10,wall_mm=0.4,height_mm=12,layer=paper")
    described.parse_design("n_chambers=10,wall_mm=2,height_mm=30,layer=paper")  # sampled only
    with pytest.raises(ActuatorError, match=r"^ranges: declares ranges"):
        table_training_data(sims, actuator=described, ranges=["wall_mm=1:3"])


def test_paper_b_design_names_are_refused_for_another_actuator(trained):
    path, _ = trained
    with pytest.raises(ValueError, match="not a design parameter"):
        predict_angles(path, "l_mm=100,r_mm=6,t_mm=2,b_mm=2,phi_deg=5,lc_mm=8", [10.0])


def test_a_large_parquet_table_reports_its_read_from_the_start(sims, tmp_path, monkeypatch):
    pytest.importorskip("pyarrow")
    import softbend._progress
    from softbend._progress import listening

    parquet = tmp_path / "sims.parquet"
    pd.read_csv(sims).to_parquet(parquet)
    monkeypatch.setattr(softbend._progress, "READ_REPORT_BYTES", 0)
    heard = []
    read_parquet = pd.read_parquet
    monkeypatch.setattr(
        pd, "read_parquet", lambda *a, **k: heard.append("read") or read_parquet(*a, **k)
    )
    with listening(lambda *call: heard.append(call)):
        read(parquet)
    describing = [("describing sims.parquet's designs", done, 3) for done in range(4)]
    assert heard == [
        ("reading sims.parquet, %", 0, 100),
        "read",
        ("reading sims.parquet, %", 100, 100),
        *describing,
    ]


@pytest.mark.parametrize(("column", "position"), [("p_kpa", 6), ("angle_deg", 7)])
def test_a_stray_text_cell_in_the_pressure_or_angle_names_its_line(tmp_path, column, position):
    path = tmp_path / "stray.csv"
    with_cell(column, 10, "n/a").to_csv(path, index=False)
    with pytest.raises(DatasetError) as info:
        read(path)
    error = info.value
    assert (error.line, error.column, error.key) == (12, position, column)
    assert error.detail == 'must be a number; got "n/a"'
