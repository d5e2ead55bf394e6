"""A surrogate family added from outside softbend: one module, one ``register`` call.

The toy family below is all a user writes: a scikit-learn ``LinearRegression``
on the seven inputs, its grids, its factory and how it is saved (the rules of
every value its file may hold). Registered once, ``softbend train`` searches,
refits, saves and reports it and ``softbend predict`` reads it back, with no
change to softbend's files.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from sklearn.linear_model import LinearRegression

from softbend.cli import main
from softbend.surrogates.families import FAMILIES, Family, Storage
from softbend.surrogates.schema import Schema, array, boolean, integer, optional, real

from .conftest import one_error_line

# --- the user's module -------------------------------------------------------------------------

TOY = Family(
    name="toy-linear",
    title="linear regression",
    grids={
        "quick": ({"fit_intercept": True},),
        "paper": ({"fit_intercept": True}, {"fit_intercept": False}),
    },
    make=lambda params, settings: LinearRegression(**params),
    storage=Storage(
        module="sklearn.linear_model",
        class_name="LinearRegression",
        schema=Schema(
            params={
                "fit_intercept": boolean,
                "copy_X": boolean,
                "tol": real(low=0.0),
                "n_jobs": optional(integer(1)),
                "positive": boolean,
            },
            state={
                "n_features_in_": integer(1),
                "coef_": array("float64", 1),
                "intercept_": real(),
                "rank_": integer(0),
                "singular_": array("float64", 1),
            },
        ),
        required_state=("n_features_in_", "coef_", "intercept_"),
    ),
)


@pytest.fixture
def toy_family():
    FAMILIES.register("toy-linear", TOY)  # the one call
    yield TOY
    FAMILIES.unregister("toy-linear")


# --- softbend's CLI, unchanged -----------------------------------------------------------------


def test_a_family_registered_outside_softbend_trains_saves_and_predicts(
    toy_family, small_campaign, tmp_path, capsys
):
    from softbend.surrogates.persistence import load_surrogate

    out = tmp_path / "surrogates"
    args = ["train", str(small_campaign), "--out", str(out), "--models", "toy-linear"]
    assert main([*args, "--folds", "3", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert list(summary["models"]) == ["toy-linear"] and summary["best_by_mape"] == "toy-linear"
    toy = summary["models"]["toy-linear"]
    assert toy["params"] == "fit_intercept=True" and 0.5 < toy["r2"] <= 1.0
    assert toy["paper_b"] == {} and "onnx_max_abs_diff_deg" not in toy  # no ONNX export
    assert summary["files"]["toy-linear_model"] == str(out / "models" / "toy-linear.json")
    assert sorted(p.name for p in (out / "models").iterdir()) == ["toy-linear.json"]
    assert (out / "fig5_parity_errors.png").is_file() and (out / "cv_results.csv").is_file()

    # the saved file is the toy family's, and reads back through its storage
    path = out / "models" / "toy-linear.json"
    document = json.loads(path.read_text())
    assert document["kind"] == "toy-linear" and set(document["state"]) >= {"coef_", "intercept_"}
    saved = load_surrogate(path)
    assert saved.kind == "toy-linear" and type(saved.model) is LinearRegression
    X = np.array([[100, 6, 2, 2, 5, 8, p] for p in (0.0, 0.05, 0.1)], dtype=float)
    refit = saved.model.predict(X)
    predict = ["predict", str(path), "--design", "100,6,2,2,5,8", "--pressures", "0,0.05,0.1"]
    assert main(predict) == 0
    assert "toy-linear surrogate" in capsys.readouterr().out
    assert main([*predict, "--json"]) == 0
    prediction = json.loads(capsys.readouterr().out)
    assert prediction["kind"] == "toy-linear"
    np.testing.assert_array_equal(prediction["angle_deg"], refit)

    # a hand-edited value is refused by the family's own schema
    document["state"]["coef_"]["__ndarray__"][0] = "x"
    path.write_text(json.dumps(document))
    assert main(["predict", str(path), "--design", "100,6,2,2,5,8", "--pressures", "0.1"]) == 2
    assert f"{path}: state.coef_: must hold only finite numbers" in one_error_line(capsys)


def test_an_unknown_family_is_one_line_listing_the_known_ones_and_exit_2(
    toy_family, small_campaign, tmp_path, capsys
):
    out = tmp_path / "surrogates"
    args = ["train", str(small_campaign), "--out", str(out), "--models", "plr,toy-lin"]
    assert main(args) == 2
    line = one_error_line(capsys)
    assert "Unknown surrogate family 'toy-lin'" in line
    assert "known: plr, xgb, mlp, table, toy-linear." in line
    assert not out.exists()


def test_once_unregistered_the_family_is_unknown_again(small_campaign, tmp_path, capsys):
    assert "toy-linear" not in FAMILIES
    args = ["train", str(small_campaign), "--out", str(tmp_path / "o"), "--models", "toy-linear"]
    assert main(args) == 2
    assert "known: plr, xgb, mlp, table." in one_error_line(capsys)
