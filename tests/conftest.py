"""Shared fixtures: a small analytical campaign for the surrogate and CLI tests."""

import pytest

from softbend.campaign import load_samples, run_campaign
from softbend.design import DesignSpace
from softbend.surrogates.features import training_data


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
