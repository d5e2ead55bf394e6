"""A strategy defined outside softbend: one ``register`` call, then every command knows it.

The toy below lives in this file only: one class that declares the range of its
parameter beside it, and one ``register`` line. The command line then fits it
(``transfer refine --strategy toy --set ...``), holds ``--set`` to the declared
range, scores it (``transfer loco``), lists it with its range (``transfer
strategies``) and records its parameters, with no edit of softbend's files.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from sklearn.base import BaseEstimator, RegressorMixin

from softbend.cli import main
from softbend.parameters import Range, declare_ranges
from softbend.surrogates.corrected import AffineCorrected
from softbend.surrogates.persistence import save_surrogate
from softbend.transfer import STRATEGIES

DESIGN = "100,6,2,2,5,8"


@declare_ranges(share=Range(0, 1, "of the mean error", "0 keeps the base; 1 removes its error"))
class ShiftedBase(RegressorMixin, BaseEstimator):
    """The base plus a share of its mean error on the readings (a toy strategy)."""

    def __init__(self, base=None, *, share: float = 1.0) -> None:
        self.base = base
        self.share = share

    def fit(self, X, y):
        X, y = np.asarray(X, dtype=float), np.asarray(y, dtype=float)
        error = y - self.base.predict(X)
        self.offset_ = self.share * float(np.mean(error))
        spread = float(np.std(error - self.offset_))
        self.model_ = AffineCorrected(self.base, 1.0, self.offset_, spread)
        return self

    def predict(self, X):
        return self.model_.predict(X)


@pytest.fixture
def toy():
    STRATEGIES.register("toy", ShiftedBase)
    yield "toy"
    STRATEGIES.unregister("toy")


@pytest.fixture(scope="module")
def files(tmp_path_factory, small_base):
    folder = tmp_path_factory.mktemp("toy")
    lab = folder / "lab.csv"
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.12", "--out", str(lab)]
    assert main([*argv, "--json"]) == 0
    return save_surrogate(small_base, folder / "base.json"), lab


def _error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softbend: error: "), err
    return err[0]


def test_a_registered_strategy_is_refined_saved_and_predicts_through_the_cli(
    toy, files, tmp_path, capsys, small_base
):
    base, lab = files
    out = tmp_path / "toy.json"
    argv = ["transfer", "refine", str(base), str(lab), "--out", str(out), "--strategy", toy]
    assert main([*argv, "--set", "share=0.5"]) == 0
    capsys.readouterr()
    saved = json.loads(out.read_text())["metadata"]
    assert saved["strategy"] == "toy" and saved["parameters"] == {"share": 0.5}

    # The saved model is the toy's: the base shifted by half its mean error.
    from softbend.transfer.measurements import load_measurements

    data = load_measurements(lab)
    offset = 0.5 * float(np.mean(data.angle_deg - small_base.predict(data.features)))
    argv = ["predict", str(out), "--design", DESIGN, "--pressures", "0.05", "--json"]
    assert main(argv) == 0
    angle = json.loads(capsys.readouterr().out)["angle_deg"][0]
    row = np.array([[100, 6, 2, 2, 5, 8, 0.05]], dtype=float)
    assert angle == pytest.approx(float(small_base.predict(row)[0]) + offset, rel=1e-9)


def test_a_registered_strategy_is_scored_listed_and_its_parameters_recorded(
    toy, files, tmp_path, capsys
):
    base, lab = files
    out = tmp_path / "loco"
    argv = ["transfer", "loco", str(lab), "--base", str(base), "--out", str(out)]
    argv += ["--strategies", "fem-only,toy", "--set", "toy.share=0.25", "--no-learning-curve"]
    assert main([*argv, "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert [r["strategy"] for r in payload["summary"]] == ["fem-only", "toy"]
    settings = json.loads((out / "loco.json").read_text())["settings"]
    assert settings["options"] == {"toy": {"share": 0.25}}
    assert settings["parameters"]["toy"] == {"share": 0.25}

    assert main(["transfer", "strategies", "--json"]) == 0
    listed = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
    assert listed["toy"]["parameters"] == {"share": 1.0} and listed["toy"]["learns"]
    assert listed["toy"]["ranges"] == {"share": "[0, 1] of the mean error"}
    assert listed["toy"]["summary"].startswith("The base plus a share")
    assert main(["transfer", "strategies"]) == 0
    assert "toy" in capsys.readouterr().out


def test_a_misspelt_parameter_or_an_unknown_strategy_is_one_line_listing_the_known(
    toy, files, tmp_path, capsys
):
    base, lab = files
    argv = ["transfer", "refine", str(base), str(lab), "--out", str(tmp_path / "m.json")]
    assert main([*argv, "--strategy", toy, "--set", "shar=0.5"]) == 2
    line = _error_line(capsys)
    assert line == "softbend: error: --set: shar: is not a parameter; known: share"
    assert main([*argv, "--strategy", toy, "--set", "share=half"]) == 2
    line = _error_line(capsys)
    assert line.startswith("softbend: error: --set: share: must be a number")
    assert main([*argv, "--strategy", toy, "--set", "share=2"]) == 2
    line = _error_line(capsys)
    assert line == "softbend: error: --set: share: must be in [0, 1] of the mean error; got '2'"
    assert main([*argv, "--strategy", "tyo"]) == 2
    line = _error_line(capsys)
    assert line.lower().startswith("softbend: error: --strategy: unknown transfer strategy 'tyo'")
    assert "refined" in line and "toy" in line
    assert not (tmp_path / "m.json").exists()


def test_an_unregistered_strategy_is_unknown_again(files, tmp_path, capsys):
    base, lab = files
    argv = ["transfer", "refine", str(base), str(lab), "--out", str(tmp_path / "m.json")]
    assert "toy" not in STRATEGIES
    assert main([*argv, "--strategy", "toy"]) == 2
    line = _error_line(capsys)
    assert (
        "unknown transfer strategy 'toy'" in line.lower()
        and "known: fem-only, base-mean-residual" in line
    )
