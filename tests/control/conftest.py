"""Fixtures of the control tests: a cheap analytic θ(p) stand-in for the MLP."""

import pytest

from softbend.control.rig import AngleTable


def linear_angle(p):
    """θ(p) = 6° + 1200°/MPa·p: monotone, about the MLP's slope near 90° (stand-in)."""
    return 6.0 + 1200.0 * p


@pytest.fixture(scope="session")
def table():
    return AngleTable.from_callable(linear_angle, pmax_mpa=0.5, points=501)
