"""TOML input files read under the same limits as JSON ones, with one message format.

Python's :mod:`tomllib` recurses once per level of nested arrays and inline
tables: a file nested some thousands deep ends in a ``RecursionError``
traceback. :func:`read_toml` reads a TOML file (a design specification, a rig
configuration) the way the JSON readers read theirs:

1. the ``file_mib`` limit of :mod:`softbend.limits`, and strict UTF-8 (a
   binary or UTF-16 file is named, not decoded into Python's words);
2. the nesting depth counted on the text (brackets outside strings and
   comments) against the ``nesting`` limit, before the parser sees it;
3. a syntax error as ``FILE, line L, column C: not valid TOML: what``;
4. the depth of the parsed tables (dotted keys nest too) against the same limit.

Every failure is one line, raised as the caller's error class.
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from softbend._io import read_input_text
from softbend._jsontext import Nesting, bracket_levels, nesting_message
from softbend.errors import DatasetError
from softbend.limits import limit

__all__ = ["parse_toml", "read_toml", "toml_nesting"]

#: Strings (basic, literal, multi-line) and comments: their brackets are not nesting.
_SKIPPED = re.compile(
    rb'"""(?:[^\\]|\\.)*?"""|\'\'\'.*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*',
    re.DOTALL,
)
_POSITION = re.compile(r"\(at line (?P<line>\d+), column (?P<column>\d+)\)")


def toml_nesting(text: str, bound: int | None = None) -> Nesting:
    """The nesting depth of the arrays and inline tables of TOML ``text``.

    A table header (``[a]``, ``[[a]]``) counts as one or two levels for its own
    line only, which no bound of a structured file is near; brackets in
    strings and comments are not counted.
    """
    data = text.encode("utf-8", "surrogatepass")
    codes = np.frombuffer(data, dtype=np.uint8)
    outside = np.ones(codes.size, dtype=bool)
    for match in _SKIPPED.finditer(data):
        outside[match.start() : match.end()] = False
    marks, level = bracket_levels(codes, outside)
    depth = int(level.max(initial=0))
    if bound is None or depth <= bound:
        return Nesting(depth, bound)
    offset = int(marks[int(np.argmax(level > bound))])
    line_start = data.rfind(b"\n", 0, offset) + 1
    key_match = re.match(rb"\s*([A-Za-z0-9_\-.\"' ]+?)\s*=", data[line_start:offset])
    key = key_match.group(1).decode("utf-8", "replace").strip() if key_match else None
    return Nesting(depth, bound, data.count(b"\n", 0, offset) + 1, key)


def _data_depth(value: object) -> int:
    """The nesting depth of parsed TOML data (tables and arrays), without recursion."""
    deepest = 0
    stack = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        children: Iterable[Any]
        if isinstance(item, dict):
            children = item.values()
        elif isinstance(item, list):
            children = item
        else:
            continue
        depth += 1
        deepest = max(deepest, depth)
        stack.extend((child, depth) for child in children)
    return deepest


def parse_toml(text: str, source: str, error: type[Exception] = DatasetError) -> dict[str, Any]:
    """TOML ``text`` parsed under the ``nesting`` limit; ``source`` names it in messages.

    Raises
    ------
    error
        One line: ``SOURCE, line L: nested N levels deep …``, ``SOURCE, line L,
        column C: not valid TOML: …``.
    """
    bound = limit("nesting")
    nesting = toml_nesting(text, bound)
    if nesting.too_deep:
        raise error(nesting_message(source, nesting))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = " ".join(str(exc).split())
        at = _POSITION.search(message)
        if at is None:
            raise error(f"{source}: not valid TOML: {message}.") from None
        what = message[: at.start()].strip().rstrip(".")
        raise error(
            f"{source}, line {at['line']}, column {at['column']}: not valid TOML: {what}."
        ) from None
    except RecursionError:  # a depth the text scan missed: still one line
        raise error(
            f"{source}: nested deeper than the limit of {bound:,} levels (the nesting "
            "depth of a structured file)."
        ) from None
    depth = _data_depth(data)
    if depth > bound:
        raise error(
            nesting_message(source, Nesting(depth, bound)).replace(
                "nested", "its tables (dotted keys or headers) nested", 1
            )
        )
    return data


def read_toml(
    path: str | os.PathLike[str], what: str, error: type[Exception] = DatasetError
) -> dict[str, Any]:
    """The TOML file ``path`` read under the limits; ``what`` names it in messages.

    Parameters
    ----------
    path : path
        The file; a missing file or a folder is a ``FileNotFoundError`` naming ``what``.
    what : str
        The file as messages name it, e.g. ``"specs.toml"`` or ``"rig.toml: the rig config"``.
    error : exception type, default DatasetError
        The class of every error about the file's content (one line).
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{what} does not exist or is not a file.")
    text = read_input_text(p, what, error=error)
    if "\x00" in text:
        raise error(f"{what} is not text (it holds NUL bytes): a TOML file is UTF-8 text.")
    return parse_toml(text, what, error)
