"""The nesting depth of JSON text, measured before it is parsed.

Python's :func:`json.loads` recurses once per level: a file nested some
thousands deep ends in a ``RecursionError`` traceback, and one nested a few
hundred deep still makes a file that no softbend writer produces. The depth is
counted on the text itself (brackets outside strings), so the ``nesting`` limit
of :mod:`softbend.limits` is enforced before parsing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from softbend.limits import LIMITS, check_limit, limit

__all__ = [
    "Nesting",
    "bracket_levels",
    "check_json_nesting",
    "check_nesting",
    "json_nesting",
    "nesting_message",
]

_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.DOTALL)
_KEY = re.compile(rb'"((?:[^"\\]|\\.)*)"\s*:', re.DOTALL)


@dataclass(frozen=True)
class Nesting:
    """How deep some JSON text nests, and where it first goes deeper than a bound.

    Attributes
    ----------
    depth : int
        Deepest nesting of arrays and objects (0 for a bare value).
    bound : int or None
        The bound it was measured against.
    line : int or None
        The line (1 for the first) of the first bracket deeper than ``bound``, or None.
    key : str or None
        The top-level key under which that bracket lies, or None (a top-level
        array, or no bracket deeper than the bound).
    """

    depth: int
    bound: int | None = None
    line: int | None = None
    key: str | None = None

    @property
    def too_deep(self) -> bool:
        """Whether the depth exceeds the bound."""
        return self.bound is not None and self.depth > self.bound


def bracket_levels(codes: np.ndarray, outside: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The offsets of the brackets (``[{]}``) where ``outside`` holds, and the level after each.

    ``codes`` are the bytes of the text; ``outside`` marks the bytes that are not
    in a string (or a comment). Shared by the JSON and the TOML readers.
    """
    opens = (codes == ord("[")) | (codes == ord("{"))
    closes = (codes == ord("]")) | (codes == ord("}"))
    marks = np.flatnonzero((opens | closes) & outside)
    return marks, np.cumsum(np.where(opens[marks], 1, -1))


def json_nesting(text: str, bound: int | None = None) -> Nesting:
    """The nesting depth of the JSON ``text`` and where it first exceeds ``bound``.

    Brackets inside strings are not counted; unbalanced brackets (invalid JSON,
    which the parser then reports) are counted as they come.
    """
    data = text.encode("utf-8", "surrogatepass")
    codes = np.frombuffer(data, dtype=np.uint8)
    outside = np.ones(codes.size, dtype=bool)
    starts = set()
    for match in _STRING.finditer(data):
        outside[match.start() : match.end()] = False
        starts.add(match.start())
    marks, level = bracket_levels(codes, outside)
    del outside
    depth = int(level.max(initial=0))
    if bound is None or depth <= bound:
        return Nesting(depth, bound)
    offset = int(marks[int(np.argmax(level > bound))])
    key = None
    for match in _KEY.finditer(data, 0, offset):
        before = int(np.searchsorted(marks, match.start()))
        if match.start() in starts and before and level[before - 1] == 1:
            key = match.group(1).decode("utf-8", "replace")
    return Nesting(depth, bound, data.count(b"\n", 0, offset) + 1, key)


def nesting_message(source: str, nesting: Nesting) -> str:
    """One line naming ``source``, the line and key of a too-deep nesting, and the limit."""
    entry = LIMITS["nesting"]
    where = f", line {nesting.line}" if nesting.line is not None else ""
    field = f" under the key '{nesting.key}'" if nesting.key is not None else ""
    return (
        f"{source}{where}: nested {nesting.depth:,} levels deep{field}, more than the limit of "
        f"{nesting.bound:,} levels ({entry.bounds}); set {entry.variable} higher to allow it."
    )


def check_nesting(text: str, source: str, error: type[Exception]) -> None:
    """Raise ``error`` (a :class:`~softbend.errors.SoftbendError`) for too deep JSON ``text``.

    The message (:func:`nesting_message`) names ``source``, the line and the
    top-level key where the text first nests deeper than the ``nesting`` limit.
    """
    nesting = json_nesting(text, limit("nesting"))
    if nesting.too_deep:
        raise error(nesting_message(source, nesting))


def check_json_nesting(text: str, what: str) -> None:
    """Raise :class:`~softbend.errors.LimitError` if ``text`` nests deeper than ``nesting``.

    Parameters
    ----------
    text : str
        JSON text, not yet parsed.
    what : str
        The file (and field) for the message.
    """
    check_limit("nesting", json_nesting(text).depth, what)
