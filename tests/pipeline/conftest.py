"""Helpers of the pipeline section tests (stand-in inputs are in tests/stand_ins.py)."""

from __future__ import annotations

from pathlib import Path

import pytest


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
