"""Shared fixtures: coarse FEM settings so the physics checks stay fast."""

from __future__ import annotations

import pytest

from softbend.design import parse_sfrba
from softbend.fem import FEMOptions

#: Coarse mesh (the element size barely changes the angle: see the mesh study).
COARSE = FEMOptions(maxh_mm=6.0)
REFERENCE = parse_sfrba("100,6,2,2,5,10")


@pytest.fixture(scope="session")
def coarse() -> FEMOptions:
    return COARSE
