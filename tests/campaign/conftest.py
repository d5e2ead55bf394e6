"""Shared fixtures of the campaign tests: a small design set and a coarse grid."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.actuators import Design
from softbend.campaign import default_pressures_mpa
from softbend.design import DesignSpace, sfrba_design

#: Long, wide, thin-walled: the analytical model stops converging at 0.255 MPa.
SOFT_DESIGN = sfrba_design(160, 10, 2, 2, 5, 8)


@pytest.fixture
def soft_design() -> Design:
    """A design whose analytical sweep stops converging at 0.255 MPa."""
    return SOFT_DESIGN


@pytest.fixture
def designs() -> DesignSpace:
    """Eleven designs over the Table 1 ranges, one of which stops converging below 0.5 MPa."""
    corners = DesignSpace.corners().designs
    picked = (SOFT_DESIGN, *corners[::7])
    return DesignSpace(tuple(dict.fromkeys(picked)), name="test-10")


@pytest.fixture
def grid() -> np.ndarray:
    """0 to 0.5 MPa in steps of 0.05 MPa (11 pressures)."""
    return default_pressures_mpa(0.5, 0.05)
