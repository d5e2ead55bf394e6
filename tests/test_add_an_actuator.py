"""docs/extending.md, "Add an actuator": one description, one ``register`` line, nothing else.

The page's bellows finger (three parameters: an integer, a continuous one with a resolution
and a categorical one; pressure in psi) is registered by running the page's block as written.
Its simulator is a closed form, θ = p·(1.2·n + 2·d − 3·firm) degrees (p in psi, n folds, d the
fold depth in mm, firm 1 for the firm skin), which a degree-2 polynomial fits exactly, so
every answer is known: at 5 psi, 90° ± 3° needs 1.2·n + 2·d − 3·firm in [17.4, 18.6], and
the fewest folds that reach it within d <= 6 mm are n = 5 with d = 6 mm on the soft skin.
"""

from __future__ import annotations

import csv
import itertools
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from softbend.cli import main

PAGE = Path(__file__).resolve().parents[1] / "docs" / "extending.md"
NAMES = ("n_folds", "fold_mm", "skin")


def bellows_angle(n: float, depth_mm: float, skin: str, p_psi: float) -> float:
    """The closed-form bending angle of the bellows finger, degrees."""
    return p_psi * (1.2 * n + 2.0 * depth_mm - 3.0 * (skin == "firm"))


def _block() -> str:
    blocks = re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S)
    (block,) = [b for b in blocks if '"bellows"' in b]
    return block


@pytest.fixture(scope="module")
def bellows():
    """The page's description, registered as the page registers it (and removed after)."""
    from softbend.actuators import ACTUATORS

    block = _block()
    assert block.count(".register(") == 1
    exec(compile(block, str(PAGE), "exec"), {"__name__": "extending_example"})
    try:
        yield ACTUATORS.get("bellows")
    finally:
        ACTUATORS.unregister("bellows")


@pytest.fixture(scope="module")
def model(bellows, tmp_path_factory):
    """The bellows' simulation table, written from the closed form, and its trained plr."""
    folder = tmp_path_factory.mktemp("bellows")
    rows = []
    for i, (n, depth, skin) in enumerate(
        itertools.product((4, 8, 12), (2.0, 4.0, 6.0), ("soft", "firm"))
    ):
        if n * depth > 60:  # the description's constraint: the table holds none
            continue
        for p in np.linspace(0.0, 6.0, 7):
            rows.append(
                {"design_id": f"b{i:02d}", "n_folds": n, "fold_mm": depth, "skin": skin,
                 "p_psi": p, "angle_deg": bellows_angle(n, depth, skin, p)}
            )  # fmt: skip
    table = folder / "bellows.csv"
    pd.DataFrame(rows).to_csv(table, index=False)
    out = folder / "bellows"
    args = ["train", str(table), "--actuator", "bellows", "--models", "plr",
            "--grid", "quick", "--folds", "2", "--no-onnx", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    return out / "models" / "plr.json"


def test_the_registered_description_is_the_page_s(bellows):
    assert bellows.names == NAMES and bellows.pressure_unit == "psi"
    assert bellows.features == (*NAMES, "p_psi")
    assert [p.kind for p in bellows.parameters] == ["integer", "continuous", "categorical"]


def test_the_trained_model_records_the_description(model, capsys):
    capsys.readouterr()
    saved = json.loads(model.read_text(encoding="utf-8"))
    described = saved["metadata"]["actuator"]
    assert described["name"] == "bellows" and described["pressure_unit"] == "psi"
    assert [p["name"] for p in described["parameters"]] == list(NAMES)
    assert described["constraints"] == ["n_folds * fold_mm <= 60"]


def test_predict_by_the_description_s_names_in_psi(model, capsys):
    capsys.readouterr()
    args = ["predict", str(model), "--design", "n_folds=8,fold_mm=4,skin=soft",
            "--pressures", "0,2,4", "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["actuator"] == "bellows"
    assert payload["design"] == {"n_folds": 8, "fold_mm": 4.0, "skin": "soft"}
    assert payload["p_psi"] == [0.0, 2.0, 4.0]
    expected = [bellows_angle(8, 4.0, "soft", p) for p in (0.0, 2.0, 4.0)]
    assert payload["angle_deg"] == pytest.approx(expected, abs=1e-6)


def test_a_design_against_the_description_is_one_line(model, capsys):
    capsys.readouterr()
    # 12 folds of 6 mm break the constraint n_folds * fold_mm <= 60
    args = ["predict", str(model), "--design", "n_folds=12,fold_mm=6,skin=soft",
            "--pressures", "2"]  # fmt: skip
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "n_folds * fold_mm <= 60" in err[0], err


def test_design_find_keeps_to_the_resolution_and_the_constraint(model, tmp_path, capsys):
    capsys.readouterr()
    out = tmp_path / "design"
    args = ["design", "find", "--model", str(model), "--angle", "90", "--at", "5",
            "--minimize", "n_folds", "--out", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["actuator"] == "bellows" and payload["pressure_unit"] == "psi"
    assert payload["spec"]["ranges"]["fold_mm"]["step"] == 0.5
    best = payload["candidates"][0]
    assert best["design"] == {"n_folds": 5, "fold_mm": 6.0, "skin": "soft"}
    assert best["angle_deg"] == pytest.approx(bellows_angle(5, 6.0, "soft", 5.0), abs=1e-6)
    for candidate in payload["candidates"]:
        design = candidate["design"]
        assert design["n_folds"] * design["fold_mm"] <= 60
        assert (design["fold_mm"] * 2) == int(design["fold_mm"] * 2)  # 0.5 mm steps
    with open(out / "candidates.csv", encoding="utf-8") as handle:
        header = next(csv.reader(handle))
    assert header[1:5] == [*NAMES, "pressure_psi"]


def test_the_description_as_json_is_the_same_for_the_shell(bellows, tmp_path):
    from softbend.actuators import actuator_from

    path = tmp_path / "bellows.json"
    path.write_text(json.dumps(bellows.to_dict()), encoding="utf-8")
    assert actuator_from(str(path)) == bellows
