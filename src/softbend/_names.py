"""Names taken from a file or an option that become paths: one rule, one function.

A command that writes several results into its ``--out`` folder names each one
after something the user gave (a ``[[spec]] name`` of a design specification,
an experiment, a strategy). Such a name becomes a path only through
:func:`output_name`, which keeps it a plain entry of that folder: never a path
elsewhere (``../escaped``, ``/home/me/notes``), never the folder itself (an
empty name), never a name the command writes itself (``search.json``) and never
another result's name (two specs called ``stiff``), so that no result replaces
another and nothing is written outside ``--out``.

The rule, as the guarantees page states it:

- 1 to 64 characters: letters, digits, ``-``, ``_``, ``.`` and spaces inside
  (not at either end);
- not ``.`` or ``..`` and not starting with ``.`` (hidden, and the staging
  folders beside an output start with one);
- no path separator (``/``, ``\\``), no drive (``C:``), no control character;
- not one of the names the command writes itself (its reserved names), nor a
  name of a device on Windows (``CON``, ``NUL``, ``COM1``, …);
- different from every other name of the same command, ignoring case (two
  names that differ only in case are one folder on macOS and Windows).
"""

from __future__ import annotations

import re
from collections.abc import Collection, Iterable

from softbend._validation import short_repr
from softbend.errors import InputError

__all__ = ["MAX_NAME_CHARS", "NAME_RULE", "check_output_names", "output_name"]

#: The longest name accepted, characters.
MAX_NAME_CHARS = 64

#: The rule in words, for messages and the guarantees page.
NAME_RULE = (
    f"1 to {MAX_NAME_CHARS} letters, digits, '-', '_', '.' or inner spaces, not starting "
    "with '.', with no '/' or '\\'"
)

_ALLOWED = re.compile(r"[\w\-. ]+")
_DEVICES = {"con", "prn", "aux", "nul"} | {f"{p}{i}" for p in ("com", "lpt") for i in range(10)}


def output_name(
    name: object,
    *,
    reserved: Collection[str] = (),
    taken: Collection[str] = (),
) -> str:
    """``name`` as the name of one entry of an output folder, or one :class:`InputError`.

    Parameters
    ----------
    name : object
        The name as given (a string from a file or an option).
    reserved : collection of str
        Names the command writes into the same folder itself.
    taken : collection of str
        Names already given to other results of the same command.

    Returns
    -------
    str
        The name, unchanged.

    Raises
    ------
    InputError
        One line with the key ``name``, naming the rule and the name at fault; a
        caller that hands its own parameter on re-keys it with
        :func:`softbend.errors.keyed`.
    """
    shown = short_repr(name, 80) if not isinstance(name, str) else _shown(name)
    if not isinstance(name, str):
        raise InputError(f"must be a text name ({NAME_RULE}); got {shown}", key="name")
    problem = _problem(name)
    if problem is not None:
        raise InputError(
            f"must be a plain name of a folder or file ({NAME_RULE}); {shown} {problem}",
            key="name",
        )
    folded = name.casefold()
    clash = next((r for r in reserved if r.casefold() == folded), None)
    if clash is not None:
        raise InputError(
            f"must not be a name the command writes itself ({', '.join(sorted(set(reserved)))}); "
            f"got {shown}",
            key="name",
        )
    other = next((t for t in taken if t.casefold() == folded), None)
    if other is not None:
        same = "is given twice" if other == name else f"differs from {other!r} only in case"
        raise InputError(
            f"must be a name of its own, or one result would replace the other; {shown} {same}",
            key="name",
        )
    return name


def _shown(name: str) -> str:
    return repr(name) if len(repr(name)) <= 80 else repr(name)[:77] + "..."


def _problem(name: str) -> str | None:
    """What makes ``name`` unfit as an entry of a folder, or None."""
    if not name:
        return "is empty"
    if len(name) > MAX_NAME_CHARS:
        return f"has {len(name)} characters"
    if "/" in name or "\\" in name:
        return "holds a path separator"
    if re.match(r"[A-Za-z]:", name):
        return "names a drive"
    if name.startswith("."):
        return "starts with '.'"
    if name != name.strip():
        return "starts or ends with a space"
    if not _ALLOWED.fullmatch(name):
        bad = next(c for c in name if not _ALLOWED.fullmatch(c))
        return f"holds the character {bad!r}"
    if name.split(".", 1)[0].casefold() in _DEVICES:
        return "is a device name on Windows"
    return None


def check_output_names(
    names: Iterable[object],
    *,
    reserved: Collection[str] = (),
) -> list[str]:
    """Every name of ``names`` through :func:`output_name`, each unlike the others.

    An error has the key ``names`` and says which one is at fault, from 1:
    ``names: name 2 must be a name of its own, ...``.
    """
    checked: list[str] = []
    for index, name in enumerate(names, start=1):
        try:
            checked.append(output_name(name, reserved=reserved, taken=checked))
        except InputError as error:
            raise InputError(f"name {index} {error.detail}", key="names") from None
    return checked
