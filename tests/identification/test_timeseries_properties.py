"""Property-based tests of identification from any time-series table.

Random tables (NaN, infinite, constant columns, huge and tiny values, short
series, repeated experiment and column names, time going backwards) are read
with :func:`load_timeseries` and identified as ``softbend identify`` does:
the checks before any fit, then :func:`select_model` with a few candidates of
every family. Whatever the table, the result is either a selection whose
figures are all finite or one clean one-line error (a softbend error or a
``ValueError``): never another exception, never a NaN figure. The examples are
derandomized and few, so the test takes seconds; the number of tables tried
is printed in the test summary.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from softbend.errors import SoftbendError
from softbend.identification.selection import Candidate, select_model
from softbend.identification.timeseries_io import (
    check_experiments_for_lags,
    check_holdout,
    check_signals,
    load_timeseries,
)

#: One candidate of each family and a raced kernel one (the successive halving runs).
CANDIDATES = [
    Candidate("arx-1-1", "arx", 1, 1),
    Candidate("poly2-2-1", "poly2", 2, 1),
    Candidate("paper-a", "gg-svr", 2, 2, {"C": 100.0, "epsilon": 0.1}),
    Candidate("svr-1", "gg-svr", 1, 2, {"C": 10.0, "epsilon": 0.01, "shape": None}),
]
MAX_LAG = max(c.build(10).max_lag for c in CANDIDATES)

#: Cells that break naive numerics, put now and then into a column.
SPECIAL = ["nan", "inf", "-inf", "1e301", "-1e308", "1e100", "1e-300", "5e-324", "-0", "", "abc"]
#: Scales of a column: ordinary, tiny, huge (beyond 1e50 they must be refused).
SCALES = [1.0] * 5 + [1e-200, 1e-90, 1e-20, 1e20, 1e90, 1e150, 1e300]


def _column(draw: st.DrawFn, rng: np.random.Generator, base: np.ndarray) -> list[str]:
    """One column's cells: ``base`` scaled, or constant, or with special cells."""
    kind = draw(st.sampled_from(["plain"] * 6 + ["constant", "special"]))
    if kind == "constant":
        return [draw(st.sampled_from(["0", "3.5", "-1e200", "1e-310"]))] * base.size
    column = [repr(float(v)) for v in base * draw(st.sampled_from(SCALES))]
    if kind == "special":
        for _ in range(draw(st.integers(1, 2))):
            column[int(rng.integers(base.size))] = draw(st.sampled_from(SPECIAL))
    return column


@st.composite
def tables(draw: st.DrawFn) -> tuple[str, list[str], list[str], list[str]]:
    """CSV text, its inputs, its outputs and its experiment names.

    The outputs follow the inputs (a first-order lag with noise) unless a
    column is drawn constant or damaged; now and then the table has a
    column twice in its header, an experiment in two places or time going
    backwards.
    """
    n_inputs, n_outputs = draw(st.integers(1, 2)), draw(st.integers(1, 2))
    inputs = [f"u{i}" for i in range(n_inputs)]
    outputs = [f"y{j}" for j in range(n_outputs)]
    fault = draw(st.sampled_from([None] * 9 + ["header", "repeated", "backwards"]))
    names = draw(st.lists(st.sampled_from("abcde"), min_size=1, max_size=4, unique=True))
    if fault == "repeated" and len(names) > 1:
        names.append(names[0])
    lengths = [draw(st.integers(1, 40)) for _ in names]
    rows = sum(lengths)
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    u = rng.normal(size=(rows, n_inputs))
    y = np.cumsum(u.sum(axis=1, keepdims=True) * 0.2 + 0.01 * rng.normal(size=(rows, 1)), axis=0)
    y = y + rng.normal(size=(rows, n_outputs)) * 0.05
    header = ["run", "t", *inputs, *outputs]
    columns = [[name for name, k in zip(names, lengths, strict=True) for _ in range(k)]]
    time = np.concatenate([np.arange(k, dtype=float) for k in lengths])
    if fault == "backwards":
        time[int(rng.integers(rows))] = -1.0
    columns.append([repr(float(t)) for t in time])
    columns += [_column(draw, rng, u[:, i]) for i in range(n_inputs)]
    columns += [_column(draw, rng, y[:, j]) for j in range(n_outputs)]
    if fault == "header":
        header.append(draw(st.sampled_from(header[1:])))
        columns.append(columns[-1])
    lines = [",".join(header)] + [",".join(row) for row in zip(*columns, strict=True)]
    return "\n".join(lines) + "\n", inputs, outputs, names


def _held(draw: st.DrawFn, names: list[str]) -> list[str] | None:
    """The validation experiments: none mostly, else some (now and then unknown or twice)."""
    kind = draw(st.sampled_from([None] * 5 + ["some", "some", "empty", "unknown", "twice"]))
    if kind is None:
        return None
    some = draw(st.lists(st.sampled_from(names), min_size=1, max_size=2, unique=True))
    return {"some": some, "empty": [], "unknown": [*some, "zz"], "twice": [*some, some[0]]}[kind]


def _figures(selection) -> list[float]:
    table = selection.table
    run = table["pruned_after_folds"] == 0  # a pruned candidate is never run free: NaN
    values = list(table.loc[run, "cv_freerun_nrmse"]) + list(table["cv_onestep_nrmse"])
    if selection.validation:
        values += list(table.loc[run & (table["rung"] != "first"), "validation_freerun_nrmse"])
    return [float(v) for v in values] + [float(r) for r in selection.ranges]


@settings(
    max_examples=100,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(table=tables(), data=st.data())
def test_any_table_gives_finite_figures_or_one_clean_error(tmp_path, fuzz_counter, table, data):
    text, inputs, outputs, names = table
    path = tmp_path / "series.csv"
    path.write_text(text, encoding="utf-8")
    fuzz_counter["identification time series"] += 1
    held = _held(data.draw, names)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)  # no numpy warning either
            series = load_timeseries(path, inputs, outputs, experiment="run", time="t")
            check_holdout(series, held)
            check_signals(series, held)
            check_experiments_for_lags(series, MAX_LAG)
            selection = select_model(
                series, validate_on=held, folds=2, candidates=CANDIDATES, max_rows=40
            )
    except (SoftbendError, ValueError) as err:
        message = str(err)
        assert message and "\n" not in message, repr(message)
        return
    figures = _figures(selection)
    assert all(math.isfinite(v) for v in figures), selection.table
    assert "nan" not in selection.verdict()
