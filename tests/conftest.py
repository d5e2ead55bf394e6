"""Shared fixtures: a small analytical campaign for the surrogate and CLI tests."""

import os
import tempfile

import pytest

from softbend.campaign import load_samples, run_campaign
from softbend.design import DesignSpace
from softbend.surrogates.features import training_data


def pytest_configure(config):
    """Caches the tests fill (swept FEM plants) go to a temporary folder, not the user's."""
    os.environ["SOFTBEND_CACHE_DIR"] = tempfile.mkdtemp(prefix="softbend-test-cache-")


def _thorough() -> frozenset[str]:
    """``path::function`` of the tests outside the quick loop (tests/thorough.txt)."""
    from pathlib import Path

    listing = Path(__file__).with_name("thorough.txt").read_text(encoding="utf-8")
    return frozenset(
        line.strip() for line in listing.splitlines() if line.strip() and not line.startswith("#")
    )


def pytest_collection_modifyitems(config, items):
    """Mark ``thorough`` what tests/thorough.txt lists (every case of a function, or a file)."""
    from pathlib import Path

    listed = _thorough()
    root = Path(config.rootpath)
    for item in items:
        path = Path(item.path).relative_to(root).as_posix()
        if path in listed or f"{path}::{item.originalname}" in listed:
            item.add_marker(pytest.mark.thorough)


@pytest.fixture(scope="session")
def small_campaign(tmp_path_factory):
    """80 space-filling designs swept by the analytical model, 0-0.2 MPa (880 samples)."""
    import numpy as np

    db = tmp_path_factory.mktemp("surrogate-data") / "small.duckdb"
    run_campaign(
        db,
        DesignSpace.sample(80, method="lhs", seed=3),
        backend="analytical",
        pressures_mpa=np.round(np.arange(0.0, 0.2001, 0.02), 3),
        workers=0,
    )
    return db


@pytest.fixture(scope="session")
def small_data(small_campaign):
    return training_data(load_samples(small_campaign))


#: Inputs tried by the file-format property tests (tests/test_file_formats.py), per format.
_FUZZ_COUNTS: dict[str, int] = {}


@pytest.fixture(scope="session")
def fuzz_counter():
    """A per-format count of the inputs the property tests tried, printed in the summary."""
    from collections import Counter

    counts = Counter()
    yield counts
    _FUZZ_COUNTS.update(counts)


def pytest_terminal_summary(terminalreporter):
    if _FUZZ_COUNTS:
        total = sum(_FUZZ_COUNTS.values())
        parts = ", ".join(f"{name} {count}" for name, count in sorted(_FUZZ_COUNTS.items()))
        terminalreporter.write_line(f"file-format property tests: {total} inputs tried ({parts})")


@pytest.fixture(scope="session")
def fit_file(tmp_path_factory):
    """A fit.json of the shipped Dragon Skin 30 tensile test (neo-Hookean and Yeoh), as
    ``softbend materials fit`` writes it: the lab's own material for ``--material``."""
    from softbend.cli import main

    out = tmp_path_factory.mktemp("fit")
    assert main(["materials", "fit", "--models", "neo-hookean,yeoh", "-o", str(out)]) == 0
    return out / "fit.json"
