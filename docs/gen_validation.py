"""Write docs/validation.md from a run's summary.json (run by `make docs` after `make run`).

Usage: python docs/gen_validation.py [SUMMARY_JSON] [--out FILE]
(default results/reproduce/summary.json and docs/validation.md)

The summary is checked before anything is written: a file that is missing, not
JSON, or not the summary ``softbend reproduce`` writes (a section missing, a
value of the wrong type) is one line naming the file and what is wrong, exit
code 2, and docs/validation.md is left as it was. The page is replaced whole.

The page holds what a rerun repeats: the figures and the run's setting, not its
dates and wall time (:data:`VOLATILE`), so that `make docs` after a fresh
`make run` leaves the tracked page unchanged unless a figure changed.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SUMMARY = ROOT / "results" / "reproduce" / "summary.json"
PAGE = ROOT / "docs" / "validation.md"

#: The sections of the summary the page reads, each a JSON object.
SECTIONS = ("paper_a", "paper_b", "paper_b_fem_data", "transfer", "control", "design")

#: Every key the summary must have: the sections, the run's provenance and what was reduced.
REQUIRED = (*SECTIONS, "provenance", "reduced_settings")

#: Provenance that differs from one run to the next of the same code on the same machine: left
#: off the page, so that `make docs` after a fresh `make run` leaves the tracked page as it was
#: unless a figure changed. The run's report (index.html) keeps them.
VOLATILE = ("started (UTC)", "finished (UTC)", "wall time")

#: The page's last line: where the left-off provenance is.
NOTE = (
    "The run's start, end and wall time are in its report (`results/reproduce/index.html`), "
    "not on this page: it changes only when a figure or the run's setting does."
)

#: JSON kinds by name, for the checks below.
_OBJECT, _LIST, _TEXT, _NUMBER, _NULL = "an object", "a list", "a string", "a number", "null"
#: A figure of the page: a number, a text that says why there is none, or null.
_FIGURE = (_NUMBER, _TEXT, _NULL)


class SummaryError(ValueError):
    """The file is not a summary of ``softbend reproduce`` the page can be made from."""


def json_kind(value: Any) -> str:
    """What a parsed JSON value is, as JSON names it (``"an object"``, ``"null"``…).

    >>> json_kind({}), json_kind([1]), json_kind("x"), json_kind(2.5), json_kind(None)
    ('an object', 'a list', 'a string', 'a number', 'null')
    """
    if value is None:
        return _NULL
    if isinstance(value, bool):
        return "true or false"
    if isinstance(value, int | float):
        return _NUMBER
    if isinstance(value, str):
        return _TEXT
    return _LIST if isinstance(value, list) else _OBJECT


def read_json(path: Path) -> Any:
    """The parsed JSON of ``path``, or :class:`SummaryError` naming the file and why not."""
    if not path.is_file():
        what = "is a folder" if path.is_dir() else "is missing"
        raise SummaryError(f"{path} {what}: `make run` writes the summary.json of a run.")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise SummaryError(
            f"{path}: not UTF-8 text (undecodable byte at offset {exc.start})."
        ) from None
    except OSError as exc:
        raise SummaryError(
            f"{path}: cannot be read ({exc.strerror or type(exc).__name__})."
        ) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise SummaryError(
            f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno})."
        ) from None
    except RecursionError:
        raise SummaryError(f"{path}: JSON nested too deeply to read.") from None


def _expect(value: Any, kinds: Sequence[str], where: str) -> None:
    """Raise :class:`SummaryError` unless ``value`` is one of the JSON ``kinds``."""
    if json_kind(value) not in kinds:
        raise SummaryError(
            f"'{where}' must be {' or '.join(kinds)}. Got {json_kind(value)} instead."
        )


def _members(value: Any, kinds: Sequence[str], where: str) -> None:
    """Check each member of an object or a list (``value`` itself may be null)."""
    items = value.items() if isinstance(value, dict) else enumerate(value or ())
    for key, member in items:
        _expect(member, kinds, f"{where}.{key}")


def check_summary(data: Any) -> dict[str, Any]:
    """``data`` if the page can be made from it, else :class:`SummaryError` saying what is wrong.

    It must be a JSON object with every key of :data:`REQUIRED`: the sections
    (objects), ``provenance`` (a non-empty object of plain values) and
    ``reduced_settings`` (a list of texts); and within the sections, what the
    page reads must have its type (figures: numbers, texts or null; tables of
    models, strategies, runs and specifications: objects).
    """
    if not isinstance(data, dict):
        raise SummaryError(f"it must be a JSON object. Got {json_kind(data)} instead.")
    missing = [key for key in REQUIRED if key not in data]
    if missing:
        raise SummaryError(
            f"it must have the keys {', '.join(REQUIRED)} (as `softbend reproduce` writes them). "
            f"Got one without {', '.join(missing)}."
        )
    for key in SECTIONS:
        _expect(data[key], [_OBJECT], key)
    _expect(data["provenance"], [_OBJECT], "provenance")
    if not data["provenance"]:
        raise SummaryError("'provenance' must describe the run. Got an empty object instead.")
    _members(data["provenance"], [_TEXT, _NUMBER, "true or false", _NULL], "provenance")
    _expect(data["reduced_settings"], [_LIST], "reduced_settings")
    _members(data["reduced_settings"], [_TEXT], "reduced_settings")

    paper_a = data["paper_a"]
    worst = paper_a.get("free_run_nrmse_worst")
    _expect(worst, [_OBJECT, _NULL], "paper_a.free_run_nrmse_worst")
    _members(worst, [_NUMBER], "paper_a.free_run_nrmse_worst")
    selection = paper_a.get("selection")
    _expect(selection, [_OBJECT, _NULL], "paper_a.selection")
    _members(selection, [_OBJECT], "paper_a.selection")
    for section in ("paper_b", "paper_b_fem_data"):
        for name in ("r2", "f_value", "mape_pct"):
            _expect(data[section].get(name), _FIGURE, f"{section}.{name}")
    models = data["paper_b_fem_data"].get("surrogates_random")
    _expect(models, [_OBJECT, _NULL], "paper_b_fem_data.surrogates_random")
    _members(models, [_OBJECT], "paper_b_fem_data.surrogates_random")
    transfer = data["transfer"]
    _expect(transfer.get("best"), [_TEXT, _NULL], "transfer.best")
    _expect(transfer.get("summary"), [_OBJECT, _NULL], "transfer.summary")
    _members(transfer.get("summary"), [_OBJECT], "transfer.summary")
    runs = data["control"].get("rig")
    _expect(runs, [_LIST, _NULL], "control.rig")
    _members(runs, [_OBJECT], "control.rig")
    specifications = data["design"].get("specifications")
    _expect(specifications, [_LIST, _NULL], "design.specifications")
    _members(specifications, [_OBJECT], "design.specifications")
    for i, spec in enumerate(specifications or ()):
        _expect(spec.get("best"), [_OBJECT, _NULL], f"design.specifications.{i}.best")
    return data


def page_text(summary: dict[str, Any]) -> str:
    """The validation page of a checked summary: its figures and the provenance that a rerun
    of the same code on the same machine repeats (:data:`VOLATILE` left off)."""
    from softbend.reports.summary_section import validation_markdown

    provenance = {k: v for k, v in summary["provenance"].items() if k not in VOLATILE}
    return validation_markdown({**summary, "provenance": provenance}) + "\n" + NOTE + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Check the summary, then write the page; the exit code (2: a summary that is not one)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("summary", nargs="?", type=Path, default=SUMMARY, help="summary.json")
    parser.add_argument("--out", type=Path, default=PAGE, help="the page to write")
    args = parser.parse_args(argv)
    try:
        data = read_json(args.summary)
        try:
            summary = check_summary(data)
        except SummaryError as exc:
            raise SummaryError(f"{args.summary} is not the summary.json of a run: {exc}") from None
    except SummaryError as exc:
        print(exc, file=sys.stderr)
        return 2
    from softbend._io import write_text_atomic

    try:
        write_text_atomic(args.out, page_text(summary))  # whole, or as it was
    except OSError as exc:
        print(f"{args.out}: cannot be written ({exc.strerror or exc}).", file=sys.stderr)
        return 1
    print(f"wrote {args.out} from {args.summary}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
