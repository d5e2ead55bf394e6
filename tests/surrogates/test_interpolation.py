"""The interpolation score and the small-table defaults of training."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from softbend.surrogates.features import TrainingData, data_hash
from softbend.surrogates.interpolation import interpolation_rows
from softbend.surrogates.search import MODEL_NAMES, SMALL_DATA_DESIGNS
from softbend.surrogates.workflow import default_models, small_data_advice, train_surrogates

from .conftest import table1_inputs

PRESSURES = np.linspace(0.0, 0.5, 7)  # MPa


def _data(n_designs: int) -> TrainingData:
    designs = table1_inputs(n_designs, 4)[:, :6]
    X = np.array([[*d, p] for d in designs for p in PRESSURES])
    y = 120.0 * (X[:, 0] / 130.0) / (X[:, 2] / 3.0) * (X[:, -1] / 0.5) ** 1.5
    groups = np.repeat([f"d{k:03d}" for k in range(n_designs)], PRESSURES.size)
    return TrainingData(X=X, y=y, groups=groups, data_hash=data_hash(X, y, groups))


def test_every_other_interior_pressure_of_each_design_is_held_out():
    data = _data(3)
    order = np.random.default_rng(0).permutation(data.n_samples)  # rows in any order
    X, groups = data.X[order], data.groups[order]
    kept, held = interpolation_rows(X, groups)
    assert np.array_equal(np.sort(np.concatenate([kept, held])), np.arange(X.shape[0]))
    for name in np.unique(groups):
        mine = groups[held] == name
        # positions 1, 3, 5 of the 7 pressures: each between two kept ones
        assert np.allclose(np.sort(X[held][mine, -1]), PRESSURES[1:-1:2])
    # a curve of two points has no interior point: nothing held out
    assert interpolation_rows(X[:2], np.array(["a", "a"]))[1].size == 0


def test_small_tables_add_the_table_base_and_report_both_figures(tmp_path):
    assert default_models(SMALL_DATA_DESIGNS) == MODEL_NAMES
    assert default_models(SMALL_DATA_DESIGNS - 1) == (*MODEL_NAMES, "table")
    assert "table base" in small_data_advice(30, None, table=True)
    assert "table base" not in small_data_advice(30, None)
    data = _data(12)
    result, summary = train_surrogates(
        data, tmp_path, models=["plr", "table"], grid_name=None, folds=3, export_onnx=False
    )
    assert result.settings["grid"] == "small"
    table, plr = summary["models"]["table"], summary["models"]["plr"]
    for entry in (table, plr):
        figures = entry["interpolation"]
        assert figures["n_held_out"] == 12 * 3 and np.isfinite(figures["rmse_deg"])
    # the table base interpolates its own smooth curves far better than it generalises
    assert table["interpolation"]["rmse_deg"] < 0.1 * table["rmse_deg"]
    assert table["interpolation"]["rmse_deg"] < 1.0
    written = pd.read_csv(tmp_path / "summary.csv").set_index("model")
    assert written.loc["table", "interp_rmse_deg"] == pytest.approx(
        table["interpolation"]["rmse_deg"]
    )
    # without it: no figure, no column
    _, plain = train_surrogates(
        data, tmp_path / "plain", models=["plr"], folds=3, export_onnx=False, interpolation=False
    )
    assert "interpolation" not in plain["models"]["plr"]
    assert "interp_rmse_deg" not in pd.read_csv(tmp_path / "plain" / "summary.csv").columns


@pytest.mark.parametrize(
    ("n_designs", "families"), [(12, (*MODEL_NAMES, "table")), (100, MODEL_NAMES)]
)
def test_training_without_families_named_searches_the_defaults_of_its_size(
    n_designs, families, tmp_path, monkeypatch
):
    import softbend.surrogates.workflow as workflow

    class AskedError(Exception):
        pass

    def search(data, *, models, **options):
        raise AskedError(models)

    monkeypatch.setattr(workflow, "search", search)
    with pytest.raises(AskedError) as asked:
        train_surrogates(_data(n_designs), tmp_path, export_onnx=False)
    assert tuple(asked.value.args[0]) == families


@pytest.mark.parametrize(
    ("n_designs", "asked", "scored"),
    [
        (SMALL_DATA_DESIGNS - 1, None, True),  # the default: below the small-data bound
        (SMALL_DATA_DESIGNS, None, False),  # from it: one more fit per family, skipped
        (SMALL_DATA_DESIGNS, True, True),  # asked for: scored on any table
        (SMALL_DATA_DESIGNS - 1, False, False),  # declined: skipped on any table
    ],
)
def test_the_interpolation_score_is_scored_by_default_only_below_the_small_data_bound(
    n_designs, asked, scored, tmp_path, monkeypatch
):
    import softbend.surrogates.interpolation as interpolation

    calls: list[int] = []
    scores = interpolation.interpolation_scores

    def counted(data, *args, **kwargs):
        calls.append(data.n_groups)
        return scores(data, *args, **kwargs)

    monkeypatch.setattr(interpolation, "interpolation_scores", counted)
    _, summary = train_surrogates(
        _data(n_designs),
        tmp_path,
        models=["plr"],
        grid_name="small",
        folds=3,
        export_onnx=False,
        interpolation=asked,
    )
    assert calls == ([n_designs] if scored else [])
    assert ("interpolation" in summary["models"]["plr"]) is scored
    if scored:
        assert np.isfinite(summary["models"]["plr"]["interpolation"]["rmse_deg"])


def _rows_design_by_design(X, groups):
    """The held-out rows, one design at a time (the definition)."""
    held = []
    for name in dict.fromkeys(groups.tolist()):
        rows = np.flatnonzero(groups == name)
        ordered = rows[np.argsort(X[rows, -1], kind="stable")]
        held.extend(ordered[1:-1:2].tolist())
    return np.array(sorted(held), dtype=np.int64)


def test_the_held_out_rows_are_those_of_each_design_in_turn_with_ties_in_row_order():
    rng = np.random.default_rng(11)
    n = 400
    groups = rng.choice(np.array(["a", "b", "c", "dd", "e"] + [f"x{k}" for k in range(40)]), n)
    X = np.column_stack([rng.normal(size=n), rng.integers(0, 6, n).astype(float)])  # ties
    kept, held = interpolation_rows(X, groups)
    assert np.array_equal(held, _rows_design_by_design(X, groups))
    assert np.array_equal(kept, np.setdiff1d(np.arange(n), held))
    assert kept.dtype == held.dtype == np.int64
