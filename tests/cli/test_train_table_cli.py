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


def test_a_stray_text_cell_is_one_line_naming_file_line_and_column(tmp_path, capsys):
    frame = table()
    frame["wall_mm"] = frame["wall_mm"].astype(object)
    frame.loc[7, "wall_mm"] = "thick"
    path = tmp_path / "thick.csv"
    frame.to_csv(path, index=False)
    code = main(["train", str(path), *TABLE_OPTIONS, "--out", str(tmp_path / "m")])
    assert code == 2
    line = one_error_line(capsys)
    assert f"{path}:9:3: wall_mm: must be a number" in line and "thick" in line
    assert not (tmp_path / "m").exists()


@pytest.fixture(scope="module")
def ranged_model(sims, tmp_path_factory):
    """plr of the stand-in table (walls 1.1 to 2.9 mm, heights 8 to 16 mm), heights declared
    6 to 18 mm."""
    out = tmp_path_factory.mktemp("ranged") / "m"
    args = ["train", str(sims), *TABLE_OPTIONS, "--range", "height_mm=6:18", "--out", str(out)]
    assert main([*args, "--models", "plr", "--folds", "3", "--no-onnx", "--json"]) == 0
    return out / "models" / "plr.json"


def predict(model, design, *extra):
    return main(["predict", str(model), "--design", design, "--pressures", "20", *extra])


def test_a_design_past_the_sampled_span_is_a_warning_and_strict_refuses(ranged_model, capsys):
    capsys.readouterr()
    design = "n_chambers=10,wall_mm=1.0,height_mm=12,layer=paper"
    assert predict(ranged_model, design) == 0
    err = capsys.readouterr().err
    assert "wall_mm 1 outside [1.1, 2.9]" in err and "--strict refuses" in err
    assert predict(ranged_model, design, "--strict") == 2
    assert "wall_mm 1 outside [1.1, 2.9]" in one_error_line(capsys)


def test_a_declared_range_is_recorded_and_refuses_a_design_outside(ranged_model, capsys):
    capsys.readouterr()
    parameters = json.loads(ranged_model.read_text())["metadata"]["actuator"]["parameters"]
    by_name = {p["name"]: p for p in parameters}
    assert (by_name["height_mm"]["low"], by_name["height_mm"]["high"]) == (6, 18)
    assert "sampled" not in by_name["height_mm"] and by_name["wall_mm"]["sampled"] is True
    # inside the declared range, past the heights the table sampled: an extrapolation
    assert predict(ranged_model, "n_chambers=10,wall_mm=2,height_mm=17,layer=paper") == 0
    assert "height_mm 17 outside [8, 16]" in capsys.readouterr().err
    assert predict(ranged_model, "n_chambers=10,wall_mm=2,height_mm=19,layer=paper") == 2
    assert "--design: height_mm must be in [6, 18] mm; got 19" in one_error_line(capsys)


@pytest.mark.parametrize(
    ("ranges", "needle"),
    [
        (["wallmm=1:3"], "NAME one of n_chambers, wall_mm, height_mm, layer"),
        (["wall_mm=3:1"], "numbers LOW < HIGH"),
        (["wall_mm=thin:3"], 'got "wall_mm=thin:3"'),
        (["layer=0:1"], "categorical"),
        (["wall_mm=1.5:3"], "the table's wall_mm spans [1.1, 2.9]"),
        (["wall_mm=1:3", "wall_mm=0:3"], "wall_mm twice"),
    ],
)
def test_bad_ranges_are_one_line_naming_the_option(sims, tmp_path, capsys, ranges, needle):
    options = [word for text in ranges for word in ("--range", text)]
    code = main(["train", str(sims), *TABLE_OPTIONS, *options, "--out", str(tmp_path / "m")])
    assert code == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --range: ") and needle in line
    assert not (tmp_path / "m").exists()


def test_a_range_with_a_campaign_is_refused(small_campaign, tmp_path, capsys):
    code = main(["train", str(small_campaign), "--range", "l=90:110", "--out", str(tmp_path / "m")])
    assert code == 2
    line = one_error_line(capsys)
    assert "campaign database" in line and "--range" in line


def test_a_large_table_shows_its_read_from_the_start(sims, tmp_path, capsys, monkeypatch):
    import softbend._progress

    monkeypatch.setattr(softbend._progress, "READ_REPORT_BYTES", 0)
    options = [*TABLE_OPTIONS, "--angle-column", "theta"]  # refused once the table is read
    assert main(["train", str(sims), *options, "--out", str(tmp_path / "m")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0].startswith("reading sims.csv, %: 0/100")
    assert any(line.startswith("reading sims.csv, %: 100/100") for line in lines)
    assert lines[-1].startswith("softbend: error: --angle-column: ") and "'theta'" in lines[-1]


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


@pytest.mark.parametrize(
    ("flag", "asked"), [([], None), (["--interpolation"], True), (["--no-interpolation"], False)]
)
def test_the_interpolation_flags_reach_training_and_the_default_is_the_table_size_rule(
    sims, tmp_path, capsys, monkeypatch, flag, asked
):
    import softbend.surrogates.workflow as workflow

    class AskedError(Exception):
        pass

    def train_into(source, out, **options):
        raise AskedError(options["interpolation"])

    monkeypatch.setattr(workflow, "train_into", train_into)
    args = ["train", str(sims), *TABLE_OPTIONS, "--out", str(tmp_path / "m"), *flag]
    with pytest.raises(AskedError) as told:
        main(args)
    assert told.value.args[0] is asked  # None: train_surrogates scores it below 100 designs
