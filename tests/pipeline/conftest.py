"""Quick settings of the pipeline sections (the ones tests/reports/test_reproduce.py uses)."""

from __future__ import annotations

from pathlib import Path

import pytest

from softbend.design import DesignSpace


def small_space() -> DesignSpace:
    """Two levels of l, t and b: enough for the regression, fast enough for CI (8 designs)."""
    return DesignSpace.grid(
        {
            "l_mm": [100.0, 130.0],
            "r_mm": [6.0],
            "t_mm": [2.0, 3.0],
            "b_mm": [2.0, 3.0],
            "phi_deg": [5.0],
            "lc_mm": [8.0],
        },
        name="small",
    )


def stand_in_fem_dataset(folder: Path) -> Path:
    """A small dataset in the shipped format (analytical sweeps of 15 designs: fast, same table)."""
    from softbend.campaign import run_campaign
    from softbend.datasets import write_dataset

    db = folder / "stand_in.duckdb"
    run_campaign(db, DesignSpace.sample(15, seed=4), backend="analytical", workers=0)
    write_dataset(db, folder / "dataset", command="stand-in for the test")
    return folder / "dataset"


class Phases:
    """A ``progress(phase, done, total)`` that keeps the last call of each phase."""

    def __init__(self) -> None:
        self.last: dict[str, tuple[int, int]] = {}

    def __call__(self, phase: str, done: int, total: int) -> None:
        assert 0 <= done <= total, (phase, done, total)
        self.last[phase] = (done, total)

    def all_finished(self) -> bool:
        return bool(self.last) and all(d == t > 0 for d, t in self.last.values())


@pytest.fixture
def phases() -> Phases:
    return Phases()


def pictures(folder: Path) -> list[Path]:
    """Every figure under ``folder`` (a pipeline module draws none)."""
    return sorted(p for ext in ("png", "svg", "pdf") for p in folder.rglob(f"*.{ext}"))
