"""Every exception softbend raises on purpose lives here.

All of them derive from :class:`SoftbendError`. Errors about bad input also
derive from :class:`ValueError`, so callers that only know the standard library
can still catch them. The CLI turns any of them into one line on stderr and
exit code 2.
"""

from __future__ import annotations


class SoftbendError(Exception):
    """Base class of the errors softbend raises deliberately."""


class DatasetError(SoftbendError, ValueError):
    """A data file or table is malformed: a missing column, NaN, bad time axis."""


class SchemaError(SoftbendError, ValueError):
    """A stored artefact (database, saved model) has an unknown or newer schema."""


class LimitError(SoftbendError, ValueError):
    """An input is larger than a limit of :mod:`softbend.limits` (rows, cycles, bytes, depth).

    The message names the limit, its value and the environment variable that raises it.
    """


class ConvergenceError(SoftbendError, RuntimeError):
    """A numerical solver failed to converge.

    Parameters
    ----------
    message : str
        What failed.
    pressure_mpa : float, optional
        Load level at which the solver gave up, in MPa.
    step : int, optional
        Index of the load step.
    residual : float, optional
        Residual norm at the last iterate.
    """

    def __init__(
        self,
        message: str,
        *,
        pressure_mpa: float | None = None,
        step: int | None = None,
        residual: float | None = None,
    ) -> None:
        self.pressure_mpa = pressure_mpa
        self.step = step
        self.residual = residual
        details = []
        if pressure_mpa is not None:
            details.append(f"pressure_mpa={pressure_mpa:g}")
        if step is not None:
            details.append(f"step={step}")
        if residual is not None:
            details.append(f"residual={residual:.3g}")
        super().__init__(message + (f" ({', '.join(details)})" if details else ""))


class MissingExtraError(SoftbendError, ImportError):
    """A part of softbend needs an optional dependency that is not installed.

    The message names the extra that installs it, e.g. ``pip install 'softbend[fem]'``.
    """


class RigError(SoftbendError, RuntimeError):
    """A rig stopped answering sensibly: lost connection, timeout, garbage or stale reading.

    Parameters
    ----------
    message : str
        What happened, naming the rig.
    kind : {"connection", "timeout", "garbage", "stale", "protocol"}
        The class of fault, for logs and tests.
    """

    def __init__(self, message: str, *, kind: str = "connection") -> None:
        self.kind = kind
        super().__init__(message)
