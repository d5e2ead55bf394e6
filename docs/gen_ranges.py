"""Write docs/ranges.md from the declarations in the code (run by `make docs`).

The page states the rule by which a name becomes a path (``softbend._names``) and,
for every parameter a user sets by name (``--set`` of the controllers and of the
transfer strategies, ``--rig-param`` and the ``[simulation]`` table of a rig), its
kind, default and declared range (``softbend.parameters.Range``) with the reason
for the bounds. Nothing on it is typed by hand: a parameter added without a
declared range shows as "not declared", and a test keeps the page current.

Usage: python docs/gen_ranges.py [--check] [--out FILE]

``--check`` writes nothing and exits 1 if the page differs from what it would write.
"""

from __future__ import annotations

import argparse
import inspect
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "ranges.md"

INTRO = """\
# Names and ranges

What softbend accepts where a user names an output or sets a parameter by name. This
page is generated from the declarations in the code by `docs/gen_ranges.py` (run by
`make docs`); do not edit it by hand. A value outside its range is one line naming the
parameter, its range and the value given, exit 2, before any work starts.
"""


def _names_section() -> list[str]:
    from softbend._names import MAX_NAME_CHARS

    return [
        "## Names that become paths",
        "",
        "A name given in a file or an option that names a file or folder of the output (the",
        "`name` of a `[[spec]]` of `design find --spec`, for one) becomes a path only if it is",
        "a plain entry of the output folder:",
        "",
        f"- 1 to {MAX_NAME_CHARS} characters: letters, digits, `-`, `_`, `.`, and spaces "
        "inside the name;",
        "- not `.` or `..`, and not starting with `.` (hidden; staging folders start with one);",
        "- no path separator (`/`, `\\`), no drive (`C:`), no control character;",
        "- not a name the command writes itself, nor a device name (`CON`, `NUL`, `COM1`, …);",
        "- not the name of another result of the same command, ignoring case.",
        "",
        "So nothing is written outside `--out`, and no result replaces another.",
        "",
    ]


def _kind(parameter: inspect.Parameter) -> str:
    from softbend.parameters import _kind as kind_of

    return {"ints": "integers", "float": "number", "int": "integer"}.get(
        kind_of(parameter), kind_of(parameter)
    )


def _default(parameter: inspect.Parameter) -> str:
    value = parameter.default
    if value is inspect.Parameter.empty or value is None:
        return "–"
    if isinstance(value, tuple):
        return ",".join(map(str, value))
    if isinstance(value, bool):
        return str(value).lower()
    return f"{value:g}" if isinstance(value, float) else str(value)


def _table(
    entry: Callable[..., Any], *, skip: Iterable[str] = (), keyword_only: bool = True
) -> list[str]:
    from softbend.parameters import declared_ranges, public_parameters

    known, _ = public_parameters(entry, skip=tuple(skip), keyword_only=keyword_only)
    ranges = declared_ranges(entry)
    if not known:
        return ["No parameters.", ""]
    lines = ["| parameter | kind | default | range | why |", "|---|---|---|---|---|"]
    for name, parameter in known.items():
        declared = ranges.get(name)
        kind = _kind(parameter)
        if declared is not None:
            shown, why = f"{declared.describe()}", declared.why or "–"
        elif kind in ("number", "integer", "integers"):
            shown, why = "**not declared**", "–"
        else:
            shown, why = "–", "–"
        shown, why = shown.replace("|", "\\|"), why.replace("|", "\\|")
        lines.append(f"| `{name}` | {kind} | {_default(parameter)} | {shown} | {why} |")
    return [*lines, ""]


def render() -> str:
    """The whole page, from the registries and declarations of the installed package."""
    from softbend.control.factory import CONTROLLERS
    from softbend.control.rigconfig import simulation_settings_entry
    from softbend.transfer.strategies import STRATEGIES
    from softbend.transfer.strategies.parameters import FILLED

    lines = [INTRO, *_names_section()]
    lines += [
        "## Controllers (`control simulate`, `control run`: `--set NAME=VALUE`, "
        "`[controller]` of a rig)",
        "",
    ]
    for name, factory in sorted(CONTROLLERS.items()):
        lines += [f"### `{name}`", "", *_table(factory)]
    lines += [
        "## The simulated rig (`--rig-param NAME=VALUE`, `[simulation]` of a rig)",
        "",
        *_table(simulation_settings_entry, keyword_only=False),
    ]
    lines += ["## Transfer strategies (`transfer refine`, `transfer loco`: `--set`)", ""]
    for name, cls in sorted(STRATEGIES.items()):
        lines += [f"### `{name}`", "", *_table(cls, skip=FILLED, keyword_only=False)]
    return "\n".join(lines).rstrip() + "\n"


def main(argv: list[str] | None = None) -> int:
    """Write (or with ``--check`` compare) the page; 0 when written or current."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare only; exit 1 if stale")
    parser.add_argument("--out", type=Path, default=PAGE, help="the page to write")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        current = args.out.read_text(encoding="utf-8") if args.out.is_file() else ""
        if current != text:
            print(f"{args.out} is out of date: run `make docs`", file=sys.stderr)
            return 1
        return 0
    from softbend._io import write_text_atomic

    write_text_atomic(args.out, text)
    print(f"{args.out} written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
