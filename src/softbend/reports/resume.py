"""Finished sections of an interrupted report, kept for the next run to take over.

The main job (:func:`softbend.reports.reproduce.run_reproduce`) writes its
sections one after another into a staging folder. Each finished section leaves a
checkpoint there, ``.sections/NAME.json``: its headline figures, the HTML
sections it added to the report, the files it wrote (relative to the folder, with
their sizes) and a *key*, the SHA-256 of the section's name, its settings and the
source code of the installed softbend. A run that fails or is stopped (Ctrl-C, a
kill) keeps its finished sections aside (:func:`keep`); the next run with the same
settings and the same code takes them over in order (:meth:`Sections.run`) and
computes the rest. It stops taking over at the first section it cannot take (not
finished, other settings, other code, a file missing or changed in size): every
later section is computed again, since it may read what an earlier one wrote.

Paths under the staging folder in a checkpoint's figures are stored as
:data:`PLACEHOLDER` and named under the new staging folder when taken over.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import softbend
from softbend._io import json_text, write_text_atomic
from softbend.reports.html import Report, Section

logger = logging.getLogger(__name__)

__all__ = ["CHECKPOINTS", "PLACEHOLDER", "Sections", "keep", "section_key", "source_digest"]

#: The folder of the checkpoints, relative to the report's folder.
CHECKPOINTS = Path(".sections")

#: What stands for the staging folder in a checkpoint's stored figures.
PLACEHOLDER = "<report folder>"

#: Version of the checkpoint layout.
_SCHEMA = 1


@cache
def source_digest() -> str:
    """SHA-256 of the installed softbend: every source and data file, by relative path.

    Compiled bytecode (``__pycache__``) is left out: it follows from the source.
    """
    root = Path(softbend.__file__).resolve().parent
    digest = hashlib.sha256()
    paths = (path for path in root.rglob("*") if path.is_file())
    for path in sorted(path for path in paths if "__pycache__" not in path.parts):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def section_key(name: str, settings: Any) -> str:
    """The key a checkpoint must match to be taken over.

    Parameters
    ----------
    name : str
        The section's name.
    settings : object
        Everything the section's result depends on besides the code (seed,
        options); written with ``repr`` of its JSON-ready form, so two runs with
        equal settings give the same key.

    Returns
    -------
    str
        SHA-256 hex digest of the name, the settings and :func:`source_digest`.
    """
    text = json_text({"name": name, "settings": settings}, sort_keys=True, indent=None)
    return hashlib.sha256(f"{text}\0{source_digest()}".encode()).hexdigest()


def _swap_paths(value: Any, old: str, new: str) -> Any:
    """``value`` with every text path under ``old`` named under ``new``."""
    if isinstance(value, dict):
        return {key: _swap_paths(item, old, new) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_swap_paths(item, old, new) for item in value]
    if isinstance(value, Path):
        value = str(value)
    if isinstance(value, str) and (value == old or value.startswith(old + os.sep)):
        return new + value[len(old) :]
    return value


def _files(folder: Path, skip: Iterable[Path]) -> dict[str, tuple[int, int]]:
    """Every file under ``folder`` (relative POSIX path -> (size, mtime in ns)), less ``skip``."""
    skipped = {folder / path for path in skip}
    found = {}
    for path in folder.rglob("*"):
        relative = path.relative_to(folder)
        if path.is_file() and path not in skipped and CHECKPOINTS not in relative.parents:
            stat = path.stat()
            found[relative.as_posix()] = (stat.st_size, stat.st_mtime_ns)
    return found


def _read(path: Path) -> dict[str, Any] | None:
    """A checkpoint, or None if it is missing, unreadable or of another layout."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or record.get("schema") != _SCHEMA:
        return None
    return record


@dataclass
class Sections:
    """Run a report's sections in order, taking over those an interrupted run finished.

    Parameters
    ----------
    stage : Path
        The folder this run writes into.
    kept : Path or None
        The folder of an interrupted run's finished sections (see :func:`keep`), or None.
    report : Report
        The report the sections add to.
    skip : iterable of Path
        Files under ``stage`` no section owns (resumed by their own means: the
        campaign database), relative to ``stage``.

    Attributes
    ----------
    resumed : list of str
        The sections taken over, in order.
    """

    stage: Path
    kept: Path | None
    report: Report
    skip: tuple[Path, ...] = ()
    resumed: list[str] = field(default_factory=list)
    _taking: bool = True

    def run(
        self, name: str, settings: Any, compute: Callable[[], dict[str, Any]]
    ) -> dict[str, Any]:
        """The figures of section ``name``: taken over when possible, else ``compute()``.

        Parameters
        ----------
        name : str
            The section's name (its checkpoint's file name).
        settings : object
            What its result depends on besides the code (see :func:`section_key`).
        compute : callable
            Runs the section: writes its files under ``stage``, adds its parts to
            the report and returns its JSON-ready figures.

        Returns
        -------
        dict
            The section's figures.
        """
        key = section_key(name, settings)
        if self._taking:
            taken = self._take(name, key)
            if taken is not None:
                self.resumed.append(name)
                return taken
            self._taking = False
        before = _files(self.stage, self.skip)
        first = len(self.report.sections)
        figures = compute()
        after = _files(self.stage, self.skip)
        written = {path: after[path][0] for path in after if before.get(path) != after[path]}
        record = {
            "schema": _SCHEMA,
            "name": name,
            "key": key,
            "figures": _swap_paths(figures, str(self.stage), PLACEHOLDER),
            "sections": [
                {"title": part.title, "parts": part.parts} for part in self.report.sections[first:]
            ],
            "files": written,
        }
        write_text_atomic(self.stage / CHECKPOINTS / f"{name}.json", json_text(record) + "\n")
        return figures

    def _take(self, name: str, key: str) -> dict[str, Any] | None:
        """Move a kept section's files into ``stage`` and add its parts; None if it cannot be."""
        if self.kept is None:
            return None
        checkpoint = self.kept / CHECKPOINTS / f"{name}.json"
        record = _read(checkpoint)
        if record is None or record.get("key") != key:
            return None
        files = record["files"]
        for relative, size in files.items():
            path = self.kept / relative
            if not path.is_file() or path.stat().st_size != size:
                logger.info("Section %s computed again: %s is missing or changed.", name, relative)
                return None
        for relative in files:
            target = self.stage / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(self.kept / relative, target)
        target = self.stage / CHECKPOINTS / f"{name}.json"
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(checkpoint, target)
        for part in record["sections"]:
            self.report.sections.append(Section(part["title"], list(part["parts"])))
        logger.info("Section %s taken over from an interrupted run.", name)
        return _swap_paths(record["figures"], PLACEHOLDER, str(self.stage))


def keep(stage: Path, kept: Path) -> list[str]:
    """Move the finished sections of ``stage`` (checkpoints and files) into ``kept``.

    A section already in ``kept`` under the same name is replaced. Best effort:
    a file that cannot be moved leaves that section out (the next run computes it
    again).

    Parameters
    ----------
    stage : Path
        The folder of a run that failed or was stopped.
    kept : Path
        Where the next run looks for finished sections.

    Returns
    -------
    list of str
        The names of the sections kept.
    """
    moved = []
    for checkpoint in sorted((stage / CHECKPOINTS).glob("*.json")):
        record = _read(checkpoint)
        if record is None:
            continue
        try:
            old = _read(kept / CHECKPOINTS / checkpoint.name)
            for relative in (old or {}).get("files", {}):
                (kept / relative).unlink(missing_ok=True)
            for relative in record["files"]:
                target = kept / relative
                target.parent.mkdir(parents=True, exist_ok=True)
                os.replace(stage / relative, target)
            (kept / CHECKPOINTS).mkdir(parents=True, exist_ok=True)
            os.replace(checkpoint, kept / CHECKPOINTS / checkpoint.name)
        except OSError as error:
            logger.warning("Section %s not kept for the next run: %s", record["name"], error)
            continue
        moved.append(str(record["name"]))
    return moved


def forget(kept: Path) -> None:
    """Remove the kept sections (after a run that finished: nothing is left to take over)."""
    shutil.rmtree(kept / CHECKPOINTS, ignore_errors=True)
