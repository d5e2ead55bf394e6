"""Fixtures of the control tests: a cheap analytic θ(p) stand-in for the MLP, a Modbus server."""

import sys

import pytest

from softbend.control.rig import AngleTable


def linear_angle(p):
    """θ(p) = 6° + 1200°/MPa·p: monotone, about the MLP's slope near 90° (stand-in)."""
    return 6.0 + 1200.0 * p


@pytest.fixture(scope="session")
def table():
    return AngleTable.from_callable(linear_angle, pmax_mpa=0.5, points=501)


@pytest.fixture
def server(table):
    """The simulated rig behind a Modbus TCP server on loopback (skipped without pymodbus)."""
    pytest.importorskip("pymodbus")
    from softbend.control.modbus_server import SimulatedModbusServer
    from softbend.control.rig import RigParams, SimulatedRig

    # The server runs in a thread of this process: a short GIL switch interval keeps
    # its answers as prompt as those of a separate device (the default 5 ms would
    # add up to 5 ms to a request whenever the loop holds the GIL).
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    try:
        with SimulatedModbusServer(SimulatedRig(table, RigParams(), seed=0)) as srv:
            yield srv
    finally:
        sys.setswitchinterval(interval)
