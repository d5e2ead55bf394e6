"""examples/pneunet: the synthetic PneuNet tables, their generator and its physical model."""

from __future__ import annotations

import hashlib
import importlib.util
import itertools
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

FOLDER = Path(__file__).resolve().parents[1] / "examples" / "pneunet"
DESIGN_COLUMNS = ["n_chambers", "n_layers", "wall_mm", "height_mm"]
RANGES = {
    "n_chambers": (6, 14, 1.0),
    "n_layers": (1, 3, 1.0),
    "wall_mm": (1.0, 3.0, 0.1),
    "height_mm": (8.0, 16.0, 0.5),
}


@pytest.fixture(scope="module")
def generate():
    spec = importlib.util.spec_from_file_location("pneunet_generate", FOLDER / "generate.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.modules.pop(spec.name, None)


@pytest.fixture(scope="module")
def simulations() -> pd.DataFrame:
    return pd.read_csv(FOLDER / "simulations.csv")


@pytest.fixture(scope="module")
def measurements() -> pd.DataFrame:
    return pd.read_csv(FOLDER / "measurements.csv")


def _grid() -> list[tuple[int, int, float, float]]:
    return list(itertools.product([6, 10, 14], [1, 2, 3], [1.0, 2.0, 3.0], [8.0, 12.0, 16.0]))


# ---------------------------------------------------------------- determinism


def test_the_generator_reproduces_the_shipped_files_byte_for_byte(generate, tmp_path):
    paths = generate.main(seed=0, out=tmp_path)
    assert sorted(p.name for p in paths.values()) == ["measurements.csv", "simulations.csv"]
    for path in paths.values():
        assert path.read_bytes() == (FOLDER / path.name).read_bytes(), path.name


def test_another_seed_gives_other_tables(generate, tmp_path):
    generate.main(seed=1, out=tmp_path)
    assert (tmp_path / "simulations.csv").read_bytes() != (FOLDER / "simulations.csv").read_bytes()


def test_the_readme_lists_the_files_sha256():
    readme = (FOLDER / "README.md").read_text(encoding="utf-8")
    listed = dict(
        (name, digest) for digest, name in re.findall(r"([0-9a-f]{64})\s+(\w+\.csv)", readme)
    )
    for name in ("simulations.csv", "measurements.csv"):
        assert listed.get(name) == hashlib.sha256((FOLDER / name).read_bytes()).hexdigest(), name


# ---------------------------------------------------------------- physics of the model


def test_zero_pressure_gives_a_straight_actuator(generate):
    for design in _grid():
        assert generate.bending_angle_deg(0.0, *design) == pytest.approx(0.0, abs=1e-12)


def test_the_angle_grows_with_pressure_at_a_falling_rate(generate):
    p = np.linspace(0.0, 80.0, 81)
    for design in _grid():
        angle = generate.bending_angle_deg(p, *design)
        slope = np.diff(angle)
        assert np.all(slope > 0), design
        assert np.all(np.diff(slope) < 1e-9), design  # the walls stiffen as they bulge


@pytest.mark.parametrize(
    ("name", "low", "high", "sign"),
    [
        ("n_chambers", 6, 14, +1),
        ("height_mm", 8.0, 16.0, +1),
        ("wall_mm", 1.0, 3.0, -1),
        ("n_layers", 1, 3, -1),
    ],
)
def test_the_angle_follows_each_design_parameter(generate, name, low, high, sign):
    index = DESIGN_COLUMNS.index(name)
    p = np.array([10.0, 40.0, 80.0])
    for design in _grid():
        lower, upper = list(design), list(design)
        lower[index], upper[index] = low, high
        change = generate.bending_angle_deg(p, *upper) - generate.bending_angle_deg(p, *lower)
        assert np.all(sign * change > 0), (name, design)


def test_top_pressures_and_angles_are_in_a_realistic_range(generate):
    for design in _grid():
        p_top = float(generate.max_pressure_kpa(*design))
        assert 20.0 <= p_top <= 80.0 and p_top % 5 == 0, design
        assert 30.0 < float(generate.bending_angle_deg(p_top, *design)) < 300.0, design


def test_the_built_actuators_bend_less_than_simulated(generate):
    p = np.linspace(5.0, 80.0, 16)
    for design in generate.BUILT_DESIGNS.values():
        simulated = generate.bending_angle_deg(p, *design)
        built = generate.bending_angle_deg(p, *design, build=generate.AS_BUILT)
        assert np.all(built < simulated)
        assert np.all(built > 0.6 * simulated)


def test_a_negative_pressure_is_refused(generate):
    with pytest.raises(ValueError, match="pressure"):
        generate.bending_angle_deg(-1.0, 8, 1, 2.0, 12.0)


# ---------------------------------------------------------------- the shipped tables


def test_the_simulation_table(simulations):
    assert list(simulations.columns) == ["design_id", *DESIGN_COLUMNS, "p_kpa", "angle_deg"]
    assert simulations.notna().all().all()
    designs = simulations.groupby("design_id", sort=False)
    assert designs.ngroups >= 100
    assert all(re.fullmatch(r"d\d{3}", str(name)) for name in designs.groups)
    assert (designs[DESIGN_COLUMNS].nunique() == 1).all().all()  # one design per id
    assert (designs.size() == 11).all()
    for _, sweep in designs:
        p = sweep["p_kpa"].to_numpy()
        assert p[0] == 0.0 and np.all(np.diff(p) > 0)
        assert np.all(np.diff(sweep["angle_deg"].to_numpy()) > 0)
    # kPa, not MPa or Pa: top pressures of tens of kPa.
    top = designs["p_kpa"].max()
    assert top.min() >= 20.0 and top.max() <= 80.0
    assert simulations.loc[simulations["p_kpa"] == 0.0, "angle_deg"].abs().max() < 1e-9


def test_the_measurement_table(measurements):
    assert list(measurements.columns) == ["actuator", *DESIGN_COLUMNS, "p_kpa", "angle_deg"]
    assert measurements.notna().all().all()
    actuators = measurements.groupby("actuator", sort=False)
    assert list(actuators.groups) == ["A1", "A2", "A3", "A4", "A5", "A6"]
    assert (actuators[DESIGN_COLUMNS].nunique() == 1).all().all()
    assert actuators.size().between(8, 12).all()
    assert (measurements["p_kpa"] >= 0).all() and measurements["p_kpa"].max() <= 80.0
    assert actuators["p_kpa"].min().eq(0.0).all()
    # Residual curvature and reading scatter: a few degrees at most at 0 kPa.
    assert measurements.loc[measurements["p_kpa"] == 0.0, "angle_deg"].abs().max() < 5.0
    # Varied in all four parameters.
    assert (actuators[DESIGN_COLUMNS].first().nunique() >= 3).all()


@pytest.mark.parametrize("table", ["simulations", "measurements"])
def test_design_columns_are_whole_or_on_their_resolution_and_in_range(table, request):
    frame = request.getfixturevalue(table)
    for name, (low, high, resolution) in RANGES.items():
        values = frame[name].to_numpy()
        assert values.min() >= low and values.max() <= high, name
        steps = (values - low) / resolution
        assert np.allclose(steps, np.round(steps), atol=1e-9), name
    for name in ("n_chambers", "n_layers"):
        assert frame[name].dtype.kind == "i", name


def test_the_simulated_designs_fill_the_ranges(simulations):
    designs = simulations.groupby("design_id")[DESIGN_COLUMNS].first()
    for name, (low, high, _) in RANGES.items():
        assert designs[name].min() == low and designs[name].max() == high, name
    assert set(designs["n_chambers"]) == set(range(6, 15))
    assert set(designs["n_layers"]) == {1, 2, 3}


def test_the_built_designs_lie_in_the_simulated_span(simulations, measurements):
    for name in DESIGN_COLUMNS:
        assert measurements[name].min() >= simulations[name].min(), name
        assert measurements[name].max() <= simulations[name].max(), name
    assert measurements["p_kpa"].max() <= simulations["p_kpa"].max()


def test_the_simulation_table_describes_an_actuator(simulations):
    from softbend.actuators import Actuator

    actuator = Actuator.from_table(
        simulations,
        design_columns=DESIGN_COLUMNS,
        pressure_column="p_kpa",
        pressure_unit="kPa",
        name="pneunet",
    )
    kinds = {parameter.name: parameter.kind for parameter in actuator.parameters}
    assert kinds == {
        "n_chambers": "integer",
        "n_layers": "integer",
        "wall_mm": "continuous",
        "height_mm": "continuous",
    }
