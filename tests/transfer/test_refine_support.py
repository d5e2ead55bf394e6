"""A refined model keeps where its data hold: the measured designs and the base's."""

from __future__ import annotations

import warnings

import numpy as np

from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.support import Support, support_from_rows
from softbend.transfer.measurements import save_measurements
from softbend.transfer.refine import refine_surrogate


def test_the_support_of_a_refined_model_joins_the_readings_and_the_base(
    small_base, quick_measurements, tmp_path
):
    # The base "was trained" on one far design up to 0.5 MPa; the readings add their own.
    far = np.array([[160.0, 10.0, 4.0, 4.0, 15.0, 12.0, p] for p in (0.0, 0.25, 0.5)])
    base_support = support_from_rows(far, [0.0, 100.0, 200.0])
    base = save_surrogate(
        small_base, tmp_path / "base.json", metadata={"support": base_support.to_dict()}
    )
    csv = save_measurements(quick_measurements, tmp_path / "lab.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # too few actuators to calibrate: not the point here
        result = refine_surrogate(base, csv, "scale-offset", calibrated=False)
    support = Support.from_dict(
        load_surrogate(result.save(tmp_path / "m.json")).metadata["support"]
    )
    measured = support_from_rows(quick_measurements.features, quick_measurements.angle_deg)
    assert support.designs.shape[0] == measured.designs.shape[0] + 1
    np.testing.assert_allclose(support.max_pressure(measured.designs), measured.max_pressure_mpa)
    assert support.max_pressure(far[:1, :6])[0] == 0.5
    assert support.max_angle_deg == max(200.0, float(quick_measurements.angle_deg.max()))
