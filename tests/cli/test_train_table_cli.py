"""``softbend train TABLE --design-columns ...`` and ``predict --design NAME=VALUE``."""

import json
import re

import pytest

from softbend.cli import main

from ..stand_ins import ACTUATOR_COLUMNS as COLUMNS
from ..stand_ins import actuator_table as table
from .conftest import one_error_line

TABLE_OPTIONS = [
    "--design-columns",
    COLUMNS,
    "--pressure-column",
    "p_kpa",
    "--pressure-unit",
    "kPa",
]


@pytest.fixture(scope="module")
def sims(tmp_path_factory):
    path = tmp_path_factory.mktemp("sims") / "sims.csv"
    table().to_csv(path, index=False)
    return path


def test_train_on_a_table_then_predict_by_name(sims, tmp_path, capsys):
    out = tmp_path / "m"
    args = ["train", str(sims), *TABLE_OPTIONS, "--out", str(out), "--models", "plr,xgb"]
    assert main([*args, "--folds", "3", "--no-onnx", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert [p["name"] for p in summary["actuator"]["parameters"]] == COLUMNS.split(",")
    assert all(m["paper_b"] == {} for m in summary["models"].values())
    model = out / "models" / "plr.json"
    design = "n_chambers=10,wall_mm=2,height_mm=12,layer=fabric"
    assert main(["predict", str(model), "--design", design, "--pressures", "10,40"]) == 0
    text = capsys.readouterr().out
    assert "p_kpa (kPa)" in text and "layer=fabric" in text
    assert not re.search(r"\b(l_mm|r_mm|pressure_mpa)\b", text)
    assert main(["predict", str(model), "--design", design, "--pressures", "90", "--json"]) == 0
    captured = capsys.readouterr()
    record = json.loads(captured.out)
    assert record["supported"] == [False] and "p_kpa 90 outside" in captured.err


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        (["--pressure-unit", "Pa"], "kPa, MPa, bar, psi"),
        (["--design-columns", "n_chambers,wall_mm,height,layer"], "'height'"),
        (["--angle-column", "theta"], "'theta'"),
        (["--actuator", "no-such"], "sfrba"),
    ],
)
def test_bad_table_options_are_one_line_exit_2(sims, tmp_path, capsys, change, needle):
    options = list(TABLE_OPTIONS)
    for flag, value in zip(change[::2], change[1::2], strict=True):
        if flag in options:
            options[options.index(flag) + 1] = value
        else:
            options += [flag, value]
    code = main(["train", str(sims), *options, "--out", str(tmp_path / "m")])
    assert code == 2
    assert needle in one_error_line(capsys)
    assert not (tmp_path / "m").exists()


def test_table_options_with_a_campaign_are_refused(small_campaign, tmp_path, capsys):
    code = main(
        ["train", str(small_campaign), "--pressure-unit", "kPa", "--out", str(tmp_path / "m")]
    )
    assert code == 2
    assert "campaign database" in one_error_line(capsys)


def test_a_constraint_dividing_by_zero_is_one_line_before_any_work(sims, tmp_path, capsys):
    description = {
        "name": "bellows",
        "title": "bellows",
        "parameters": [
            {"name": "n_chambers", "unit": "", "kind": "integer", "low": 6, "high": 14},
            {"name": "wall_mm", "unit": "mm", "low": 1.0, "high": 3.0},
            {"name": "height_mm", "unit": "mm", "low": 8.0, "high": 16.0},
            {"name": "layer", "unit": "", "kind": "categorical", "levels": ["fabric", "paper"]},
        ],
        "pressure_column": "p_kpa",
        "pressure_unit": "kPa",
        "constraints": ["1 / 0 < wall_mm"],
    }
    path = tmp_path / "bellows.json"
    path.write_text(json.dumps(description))
    code = main(["train", str(sims), "--actuator", str(path), "--out", str(tmp_path / "m")])
    assert code == 2
    assert one_error_line(capsys).endswith(
        "bellows.json: The constraint '1 / 0 < wall_mm' divides by zero (1 / 0); its numbers "
        "must give finite values."
    )
    assert not (tmp_path / "m").exists()
