"""``softbend predict`` on hand-edited model files: one line and exit 2, never NaN."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.cli import main
from softbend.surrogates.features import FEATURES
from softbend.surrogates.persistence import save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor

from .conftest import one_error_line

ARGS = ["--design", "100,6,2,2,5,8", "--pressures", "0.05,0.1"]


@pytest.fixture(scope="module")
def saved_document(tmp_path_factory):
    rng = np.random.default_rng(0)
    low = np.array([100, 6, 2, 2, 5, 8, 0.0])
    high = np.array([180, 10, 4, 4, 15, 12, 0.5])
    X = low + (high - low) * rng.random((200, len(FEATURES)))
    y = 300 * X[:, 6] - 5 * X[:, 2] + 0.1 * X[:, 0]
    model = PolynomialRegressor(degree=2).fit(X, y)
    path = save_surrogate(model, tmp_path_factory.mktemp("m") / "plr.json")
    return json.loads(path.read_text())


def _nan_coefficient(state):
    state["coef_"]["__ndarray__"][1] = float("nan")


def _zero_scale(state):
    state["x_scale_"]["__ndarray__"][0] = 0.0


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        (_nan_coefficient, "state.coef_: must"),
        (_zero_scale, "state.x_scale_: must"),
        (lambda s: s.update(y_scale_=0.0), "state.y_scale_: must"),
        (lambda s: s.update(y_scale_="12.5"), "state.y_scale_: must"),
        (lambda s: s.pop("coef_"), "coef_ missing"),
        (lambda s: s.update(predict="boom"), "unknown state key(s) 'predict'"),
    ],
    ids=["nan coefficient", "zero x scale", "zero y scale", "string scale", "no coef", "predict"],
)
def test_a_hand_edited_model_is_one_line_and_exit_2(
    tmp_path, capsys, saved_document, change, needle
):
    document = json.loads(json.dumps(saved_document))
    change(document["state"])
    path = tmp_path / "plr.json"
    path.write_text(json.dumps(document))
    assert main(["predict", str(path), *ARGS, "--json"]) == 2
    line = one_error_line(capsys)
    assert str(path) in line and needle in line


def test_the_intact_model_still_predicts(tmp_path, capsys, saved_document):
    path = tmp_path / "plr.json"
    path.write_text(json.dumps(saved_document))
    assert main(["predict", str(path), *ARGS, "--json"]) == 0
    angles = json.loads(capsys.readouterr().out)["angle_deg"]
    assert len(angles) == 2 and all(np.isfinite(angles))
