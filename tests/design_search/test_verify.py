"""verify_candidates: the best designs swept by a campaign backend, set beside the surrogate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softbend.design_search.search import find_designs
from softbend.design_search.spec import ParameterRange, Specification, Target
from softbend.design_search.verify import fem_angle_at, verify_candidates


def test_the_angle_on_a_sweep_is_interpolated_and_nan_past_its_end():
    p = np.array([0.0, 0.1, 0.2])
    a = np.array([0.0, 50.0, 120.0])
    assert fem_angle_at(p, a, 0.15) == pytest.approx(85.0)
    assert fem_angle_at(p[::-1], a[::-1], 0.05) == pytest.approx(25.0)
    assert math.isnan(fem_angle_at(p, a, 0.25))
    assert math.isnan(fem_angle_at(p[:1], a[:1], 0.0))


def test_verification_sets_the_backend_s_angle_beside_the_surrogate(linear_model, tmp_path):
    # The analytical model plays the FEM: it does not follow θ = 10·p·l, so the check can fail.
    spec = Specification(
        Target("angle_at", angle_deg=90.0, pressure_mpa=0.08, tolerance_deg=3.0),
        {"t": ParameterRange(3, 3), "b": ParameterRange(3, 3), "lc": ParameterRange(10, 10),
         "phi": ParameterRange(10, 10), "r": ParameterRange(8, 8)},
    )  # fmt: skip
    result = find_designs(linear_model, spec, top=4)
    db = tmp_path / "verify.duckdb"
    verified = verify_candidates(result, 2, backend="analytical", workers=1, db_path=db)
    assert verified == result.candidates[:2] and db.is_file()
    for c in verified:
        p, a = c.fem_curve
        assert p[0] == 0.0 and p[-1] >= 0.08 - 1e-12  # swept past the target's pressure
        assert c.fem_angle_deg == pytest.approx(fem_angle_at(p, a, 0.08))
        assert c.fem_error_deg == pytest.approx(abs(c.fem_angle_deg - 90.0))
        assert c.fem_meets == (c.fem_error_deg <= 3.0)
        assert "fem_angle_deg" in c.to_dict()
    assert result.candidates[2].fem_meets is None  # not verified
    again = verify_candidates(result, 2, backend="analytical", workers=1, db_path=db)
    assert [c.fem_angle_deg for c in again] == [c.fem_angle_deg for c in verified]  # resumed
    with pytest.raises(ValueError, match=r"^k: must be an integer in"):
        verify_candidates(result, 0)


@pytest.mark.slow
def test_the_fem_confirms_the_shipped_mlp_s_answer_for_90_degrees_at_0_08_mpa():
    # The acceptance figure: the FEM sweep of the best design reaches 90° ± 3° at 0.08 MPa.
    from softbend.transfer.base import shipped_base_path

    spec = Specification(Target("angle_at", angle_deg=90.0, pressure_mpa=0.08))
    result = find_designs(shipped_base_path(), spec, top=1)
    (best,) = verify_candidates(result, 1, backend="fem", workers=1)
    assert best.fem_meets, (best.design, best.fem_angle_deg)
