"""The largest inputs softbend accepts, in one place.

A limit stops a command before it runs for hours or fills the memory on an input
that is almost certainly a mistake (a billion cycles, a log file given as a
measurements CSV, a model file nested thousands deep). Every limit is far above
what a real lab produces, and each can be raised with an environment variable
(``SOFTBEND_MAX_<NAME>``, e.g. ``SOFTBEND_MAX_CSV_ROWS=5000000``) where a larger
input is meant. Exceeding one is one :class:`~softbend.errors.LimitError` (a
``ValueError``; the CLI prints it as one line and exits 2) naming the input, the
limit and the variable.

==================  =============  ================================================
name                default        what it bounds
==================  =============  ================================================
``csv_rows``        200 000        data rows of one input CSV (measurements,
                                   curling experiments, tensile tests)
``file_mib``        64             size of one input file, MiB (CSV, JSON, TOML)
``cycles``          1 000          inflation/deflation cycles of one virtual-lab run
``designs``         1 000 000      designs of one campaign or design space
``nesting``         64             nesting depth of a structured file (model JSON)
``epochs``          100 000        training epochs of one model (MLP fits and
                                   transfer refits; paper B's longest: 15 000)
``loop_ticks``      10 000 000     ticks of one control-loop run, and steps of a
                                   simulated rig's run (duration over
                                   period: 2.8 h at 1 ms), each logged in memory
==================  =============  ================================================
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from softbend.errors import LimitError

__all__ = ["LIMITS", "Limit", "check_count_text", "check_file_size", "check_limit", "limit"]


@dataclass(frozen=True)
class Limit:
    """One input limit.

    Attributes
    ----------
    name : str
        Key in :data:`LIMITS`, lower case.
    default : int
        The limit unless the environment raises it.
    unit : str
        What is counted ("rows", "MiB", ...).
    bounds : str
        What the limit bounds, for messages and the documentation.
    """

    name: str
    default: int
    unit: str
    bounds: str

    @property
    def variable(self) -> str:
        """The environment variable that sets this limit."""
        return f"SOFTBEND_MAX_{self.name.upper()}"

    def value(self) -> int:
        """The limit in force: the environment variable (a positive integer) or the default."""
        text = os.environ.get(self.variable)
        if text is None or not text.strip():
            return self.default
        try:
            value = int(text.replace("_", "").strip())
        except ValueError:
            value = 0
        if value < 1:
            raise LimitError(
                f"The environment variable {self.variable} must be a positive integer "
                f"(the limit of {self.bounds}). Got {text!r}."
            )
        return value


LIMITS: dict[str, Limit] = {
    limit.name: limit
    for limit in (
        Limit("csv_rows", 200_000, "rows", "data rows of one input CSV"),
        Limit("file_mib", 64, "MiB", "the size of one input file"),
        Limit("cycles", 1_000, "cycles", "inflation/deflation cycles of one virtual-lab run"),
        Limit("designs", 1_000_000, "designs", "designs of one campaign or design space"),
        Limit("nesting", 64, "levels", "the nesting depth of a structured file"),
        Limit("epochs", 100_000, "epochs", "training epochs of one model"),
        Limit("loop_ticks", 10_000_000, "ticks", "ticks or rig steps of one control run"),
    )
}


def limit(name: str) -> int:
    """The value in force of the limit ``name`` (a key of :data:`LIMITS`)."""
    if name not in LIMITS:
        raise ValueError(f"Unknown limit {name!r}; the limits are {', '.join(sorted(LIMITS))}.")
    return LIMITS[name].value()


def check_limit(name: str, value: int | float, what: str) -> None:
    """Raise :class:`~softbend.errors.LimitError` if ``value`` is above the limit ``name``.

    Parameters
    ----------
    name : str
        A key of :data:`LIMITS`.
    value : int or float
        The size of the input (may be a huge integer: nothing overflows).
    what : str
        The input, as the message should name it, e.g. ``"--cycles"`` or
        ``"measurements.csv"``.
    """
    bound = limit(name)
    if value > bound:
        shown = f"{value:,}" if isinstance(value, int) else f"{value:,.1f}"
        _exceeded(name, bound, f"{what} is {shown} {LIMITS[name].unit}")


#: Counts up to this many digits are shown in full in a message.
_SHOWN_DIGITS = 40


def check_count_text(name: str, digits: str, what: str) -> int:
    """The count written as decimal ``digits``, checked against the limit ``name``.

    A count with more digits than the limit in force is over it whatever the
    digits are, and is refused by its length alone: Python does not read
    integers of more than 4300 digits, and a message showing thousands of them
    would be no help.
    """
    bound = limit(name)
    digits = digits.lstrip("0") or "0"
    if len(digits) > max(_SHOWN_DIGITS, len(str(bound))):
        _exceeded(name, bound, f"{what} is a number of {len(digits):,} digits")
    value = int(digits)
    check_limit(name, value, what)
    return value


def _exceeded(name: str, bound: int, said: str) -> None:
    entry = LIMITS[name]
    raise LimitError(
        f"{said}, more than the limit of {bound:,} {entry.unit} ({entry.bounds}); "
        f"set {entry.variable} higher to allow it."
    )


def check_file_size(path: str | os.PathLike[str], what: str | None = None) -> None:
    """Raise :class:`~softbend.errors.LimitError` if the file ``path`` is over ``file_mib``.

    A file that does not exist passes (the reader names it); ``what`` defaults to the path.
    """
    try:
        size = Path(path).stat().st_size
    except OSError:
        return
    check_limit("file_mib", size / 2**20, what or str(path))
