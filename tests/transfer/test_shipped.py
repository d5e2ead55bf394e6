"""The shipped transfer data: the FEM-trained MLP and the virtual lab's readings."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.datasets import table1_fem_provenance
from softbend.surrogates.persistence import load_surrogate
from softbend.transfer.base import load_base, shipped_base_path
from softbend.transfer.lab import LAB_ACTUATORS, VirtualLab, actuator_id, shipped_measurements


def test_the_base_was_trained_on_the_shipped_dataset():
    saved = load_surrogate(shipped_base_path())
    sha = table1_fem_provenance()["files"]["samples.parquet"]["sha256"]
    assert saved.metadata["dataset_samples_sha256"] == sha, (
        "the FEM dataset changed: run 'softbend transfer base --out "
        "src/softbend/data/transfer/table1_fem_mlp.json'"
    )
    assert tuple(saved.metadata["hidden_sizes"]) == (63, 65)


def test_the_base_follows_the_fem_data_it_was_trained_on():
    from softbend.datasets import table1_fem
    from softbend.design import FEATURES

    samples = table1_fem()
    samples = samples[samples["converged"]]
    base = load_base()
    pred = base.predict(samples[list(FEATURES)].to_numpy())
    assert np.sqrt(np.mean((pred - samples["angle_deg"].to_numpy()) ** 2)) < 2.0  # degrees


def test_the_shipped_lab_is_labelled_and_covers_the_seven_actuators():
    measured = shipped_measurements()
    assert measured.metadata["synthetic"] == "true"
    assert measured.metadata["lab.plant"] == "fem"
    assert measured.actuator_ids == tuple(actuator_id(d) for d in LAB_ACTUATORS)
    assert len(measured) >= 100


@pytest.mark.slow
def test_the_shipped_lab_is_what_the_lab_measures_today():
    # Seven FEM sweeps (about two CPU minutes): the command in the file's header.
    again = VirtualLab().measure()
    shipped = shipped_measurements()
    assert again.actuator_ids == shipped.actuator_ids
    np.testing.assert_array_equal(again.frame["pressure_mpa"], shipped.frame["pressure_mpa"])
    np.testing.assert_allclose(again.angle_deg, shipped.angle_deg, atol=0.05)


def test_the_base_records_the_support_of_the_shipped_dataset():
    # Each design's largest converged pressure and the largest angle, as the dataset has them.
    from softbend.datasets import table1_fem
    from softbend.design import FEATURES
    from softbend.surrogates.support import Support, support_from_rows

    samples = table1_fem()
    samples = samples[samples["converged"]]
    expected = support_from_rows(samples[list(FEATURES)].to_numpy(), samples["angle_deg"])
    recorded = Support.from_dict(load_surrogate(shipped_base_path()).metadata["support"])
    assert recorded.designs.shape == (972, 6)
    np.testing.assert_array_equal(recorded.designs, expected.designs)
    np.testing.assert_array_equal(recorded.max_pressure_mpa, expected.max_pressure_mpa)
    assert recorded.max_angle_deg == expected.max_angle_deg <= 300.0
