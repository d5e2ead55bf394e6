"""Every exception softbend raises on purpose lives here.

All of them derive from :class:`SoftbendError`. Errors about bad input also
derive from :class:`ValueError`, so callers that only know the standard library
can still catch them. The CLI turns any of them into one line on stderr and
exit code 2.

An error about one input carries that input's **key**, the name of the library
parameter (or file field) at fault, and, for a file, the place in it; the message
itself says only what is wrong. ``str(error)`` puts them together::

    >>> str(InputError("must be a number in (0, inf); got -2.0", key="t_mm"))
    't_mm: must be a number in (0, inf); got -2.0'
    >>> str(InputError("must be a number", key="gain", file="rig.toml", line=12))
    'rig.toml:12: gain: must be a number'

The command line maps keys to the options a user typed in one place
(:mod:`softbend.cli._options`), so the library never takes an option's name as
a parameter. A function that hands a value on to another one names its own
parameter with :func:`keyed`.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


class SoftbendError(Exception):
    """Base class of the errors softbend raises deliberately.

    Parameters
    ----------
    message : str
        What is wrong. With a ``key``, the message is the predicate
        (``"must be a number in (0, inf); got -2.0"``).
    key : str, optional
        The parameter or file field at fault, as the library names it (``"t_mm"``).
    file : str, optional
        The file the value came from.
    line, column : int, optional
        Where in ``file`` (1-based).
    """

    key: str | None = None
    inner_key: str | None = None
    file: str | None = None
    line: int | None = None
    column: int | None = None

    def __init__(
        self,
        *args: object,
        key: str | None = None,
        file: str | None = None,
        line: int | None = None,
        column: int | None = None,
    ) -> None:
        super().__init__(*args)
        if key is not None:
            self.key = key
        if file is not None:
            self.file = str(file)
        if line is not None:
            self.line = line
        if column is not None:
            self.column = column

    @property
    def detail(self) -> str:
        """The message without the key and the place."""
        return str(self.args[0]) if len(self.args) == 1 else super().__str__()

    def location(self) -> str:
        """``file:line:column`` (as much of it as is known), else ``""``."""
        if self.file is None:
            return ""
        parts = [self.file] + [str(n) for n in (self.line, self.column) if n is not None]
        return ":".join(parts)

    def described(self, subject: str | None = None) -> str:
        """The message led by its place and ``subject`` (default: the key)."""
        subject = self.key if subject is None else subject
        lead = [part for part in (self.location(), subject) if part]
        return ": ".join([*lead, self.detail])

    def __str__(self) -> str:
        return self.described()


@contextmanager
def keyed(key: str, *, file: str | None = None) -> Iterator[None]:
    """Name ``key`` as the input at fault for any :class:`SoftbendError` raised inside.

    For a function that passes one of its parameters on: the error a callee
    raises about the value then names the caller's parameter, which the command
    line maps to the option the user typed. The outermost ``keyed`` wins; a key
    it replaces first (the innermost) moves into the message, so the part at fault stays named.

    Examples
    --------
    >>> from softbend.errors import InputError, keyed
    >>> try:
    ...     with keyed("fix"):
    ...         raise InputError("must be in [100, 160]; got 200", key="l_mm")
    ... except InputError as error:
    ...     print(error)
    fix: l_mm: must be in [100, 160]; got 200
    """
    try:
        yield
    except SoftbendError as error:
        if error.key is not None and error.key != key and error.inner_key is None:
            error.inner_key = error.key
            error.args = (f"{error.key}: {error.detail}",)
        error.key = key
        if file is not None and error.file is None:
            error.file = str(file)
        raise


class InputError(SoftbendError, ValueError):
    """A value given to softbend is not one it accepts; ``key`` names the input."""


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
