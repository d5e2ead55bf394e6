"""Paper A pipeline: synthetic experiments, identification, data and models, no figures."""

from __future__ import annotations

import dataclasses
import json

import pandas as pd
import pytest

from softbend.pipeline.paper_a import PaperA, run_paper_a

from .conftest import pictures


@pytest.fixture(scope="module")
def paper_a(tmp_path_factory):
    from .conftest import Phases

    out = tmp_path_factory.mktemp("paper_a")
    phases = Phases()
    return out, run_paper_a(out, seed=0, progress=phases), phases


def test_writes_experiments_metrics_and_models_but_no_figures(paper_a):
    out, result, _ = paper_a
    folder = out / "paper_a"
    assert len(list((folder / "data").glob("*.csv"))) == 12
    assert set(result.paths) == {
        "metrics",
        "summary",
        "model_positive_rho",
        "model_positive_length_mm",
        "model_negative_rho",
        "model_negative_length_mm",
    }
    assert all(path.is_file() for path in result.paths.values())
    saved = json.loads((folder / "models" / "positive_rho.json").read_text(encoding="utf-8"))
    assert "synthetic_data" in json.dumps(saved)
    metrics = pd.read_csv(result.paths["metrics"])
    assert set(metrics["mode"]) >= {"free-run"}
    assert pictures(out) == []


def test_held_out_free_run_error_is_small_and_the_worst_bounds_the_mean(paper_a):
    _, result, _ = paper_a
    mean, worst = result.summary["free_run_nrmse_mean"], result.summary["free_run_nrmse_worst"]
    assert (
        set(mean)
        == set(worst)
        == {
            "positive/rho",
            "positive/length_mm",
            "negative/rho",
            "negative/length_mm",
        }
    )
    for key in mean:
        assert 0.0 < mean[key] <= worst[key] < 0.10, key
    json.dumps(result.summary)


def test_progress_counts_every_fit_and_the_result_is_frozen(paper_a):
    _, result, phases = paper_a
    assert phases.all_finished()
    assert list(phases.last) == [
        "paper A: identification",
        "paper A: model selection (positive)",
        "paper A: model selection (negative)",
    ]
    assert isinstance(result, PaperA)
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.summary = {}  # type: ignore[misc]
