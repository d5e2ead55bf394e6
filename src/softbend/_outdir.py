"""Output folders written as a whole, and the one rule for what an output folder may replace.

Every command that writes a folder builds it beside its place (:func:`staged_dir`) and
swaps it in when complete, so a folder is never a mix of two runs. What such a swap may
replace is decided here, once, for every command:

- a folder that does not exist, or an empty one;
- a folder of softbend's own results: every file and folder in it is listed in the
  manifest (:data:`MANIFEST`) the run that wrote it left there, by the same command.
  (Contents are not compared: opening a report's database may rewrite it.)

Anything else is refused, naming what is not the command's own (:func:`foreign_entries`),
and nothing is removed. The manifest is written first into the staging folder, marked
unfinished with the writer's PID: a staging folder left by a killed run is recognised by
that manifest and a dead PID (:func:`stale_staging`), never by its name alone.

``--out`` given as a symbolic link is resolved: the folder it points to is replaced and the
link stays a link. The current folder and the folders above it are refused.
"""

from __future__ import annotations

import glob
import json
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

from softbend._io import write_text_atomic
from softbend.errors import InputError, SoftbendError

__all__ = [
    "MANIFEST",
    "Manifest",
    "OutputFolderError",
    "check_replaceable",
    "current_command",
    "foreign_entries",
    "read_manifest",
    "remove_stale_staging",
    "replaceable_target",
    "running",
    "staged_dir",
    "stale_staging",
    "write_manifest",
]

#: The file that lists what a command wrote into its output folder.
MANIFEST = ".softbend-manifest.json"

_FORMAT = "softbend-output-manifest"
_VERSION = 1


class OutputFolderError(SoftbendError, OSError):
    """An output folder holds what a run may not replace; nothing was replaced."""


@dataclass(frozen=True)
class Manifest:
    """What a command wrote into one output folder.

    Attributes
    ----------
    command : str
        The command that wrote it (``"train"``, ``"fem run"``).
    pid : int
        The process that wrote it.
    complete : bool
        False while the folder is being written (a staging folder), True once done.
    entries : dict
        Every file and folder written, by its path relative to the folder (``/``
        separated): ``"file"``, ``"folder"`` or ``"link"``.
    """

    command: str
    pid: int
    complete: bool
    entries: dict[str, str] = field(default_factory=dict)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _walk(folder: Path) -> Iterator[tuple[str, Path]]:
    """Every entry under ``folder`` (links not followed) but its manifest: relative path, path."""
    for root, dirs, files in os.walk(folder, followlinks=False):
        base = Path(root)
        for name in sorted(dirs) + sorted(files):
            path = base / name
            relative = path.relative_to(folder).as_posix()
            if relative != MANIFEST:
                yield relative, path


def _entry(path: Path) -> str:
    """What an entry is: ``"link"``, ``"folder"`` or ``"file"``."""
    if path.is_symlink():
        return "link"
    return "folder" if path.is_dir() else "file"


def read_manifest(folder: str | os.PathLike[str]) -> Manifest | None:
    """The manifest of an output folder, or None when it has none (or an unreadable one)."""
    try:
        data = json.loads((Path(folder) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("format") != _FORMAT:
        return None
    entries = data.get("entries")
    if not isinstance(entries, dict) or not all(
        isinstance(k, str) and isinstance(v, str) for k, v in entries.items()
    ):
        return None
    try:
        return Manifest(str(data["command"]), int(data["pid"]), bool(data["complete"]), entries)
    except (KeyError, TypeError, ValueError):
        return None


def write_manifest(folder: str | os.PathLike[str], command: str, *, complete: bool) -> Manifest:
    """List everything under ``folder`` in its manifest (written atomically); returns it."""
    folder = Path(folder)
    entries = {relative: _entry(path) for relative, path in _walk(folder)} if complete else {}
    manifest = Manifest(command, os.getpid(), complete, entries)
    payload = {
        "format": _FORMAT,
        "version": _VERSION,
        "command": command,
        "pid": manifest.pid,
        "complete": complete,
        "entries": entries,
    }
    write_text_atomic(folder / MANIFEST, json.dumps(payload, indent=1, sort_keys=True))
    return manifest


def foreign_entries(folder: str | os.PathLike[str], command: str) -> list[str]:
    """What replacing ``folder`` with the results of ``command`` would lose.

    Returns the paths (relative to ``folder``) of the entries that are not the
    command's own: with no manifest, or the manifest of another command or of an
    unfinished run, every entry; otherwise the entries the manifest does not list
    (or lists as another kind: a file where it wrote a folder). Empty for a
    missing or empty folder, and for one that holds only the command's own results.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    found = dict(_walk(folder))
    manifest = read_manifest(folder)
    if manifest is None or not manifest.complete or manifest.command != command:
        others = list(found)
        if manifest is None and (folder / MANIFEST).exists():
            others.insert(0, MANIFEST)
        return _tops(others)
    others = [
        relative
        for relative, path in found.items()
        if relative not in manifest.entries or _entry(path) != manifest.entries[relative]
    ]
    return _tops(others)


def _tops(paths: list[str]) -> list[str]:
    """The paths, a folder standing for what is inside it when it is listed itself."""
    chosen: list[str] = []
    for path in sorted(paths):
        if not any(path.startswith(f"{top}/") for top in chosen):
            chosen.append(path)
    return chosen


def replaceable_target(path: str | os.PathLike[str], *, key: str = "out") -> Path:
    """The folder an output named ``path`` is written to: a symbolic link resolved.

    Raises
    ------
    InputError
        For the current folder or a folder above it (they hold the command's own
        inputs and the user's work; an output folder is replaced as a whole), naming
        the path.
    """
    given = Path(path)
    target = Path(os.path.realpath(given))
    here = Path(os.path.realpath(os.getcwd()))
    if target == here or target in here.parents or not target.name:
        what = "the current folder" if target == here else "a folder above the current one"
        raise InputError(
            f"{given} is {what}; an output folder is replaced as a whole, so name a new "
            f"folder for the results, e.g. {Path(given, 'results')}.",
            key=key,
        )
    return target


def check_replaceable(
    path: str | os.PathLike[str], command: str | None = None, *, key: str = "out"
) -> Path:
    """Refuse, before any work, an output folder that replacing it as a whole would lose from.

    Parameters
    ----------
    path
        The output folder (a symbolic link is resolved).
    command
        The command that will write it; by default the running command line's.
    key
        The parameter named in the error.

    Returns
    -------
    Path
        The folder that will be replaced (:func:`replaceable_target`).

    Raises
    ------
    InputError
        For the current folder or one above it, a file, or a folder that holds
        entries not the command's own (:func:`foreign_entries`), naming up to three.
    """
    command = command or current_command()
    target = replaceable_target(path, key=key)
    if target.exists() and not target.is_dir():
        raise InputError(f"{path} is a file; an output folder is needed.", key=key)
    others = foreign_entries(target, command)
    if others:
        shown = ", ".join(others[:3]) + (f" and {len(others) - 3} more" if len(others) > 3 else "")
        manifest = read_manifest(target)
        if manifest is None:
            why = f"; it has no {MANIFEST}, so nothing in it is known to be softbend's"
        elif manifest.command != command:
            why = f"; they are the results of '{manifest.command}'"
        else:
            why = ""
        raise InputError(
            f"{path} is replaced as a whole by the results of '{command}', but it holds other "
            f"files ({shown}){why}; choose a new or empty folder, or one of its earlier results.",
            key=key,
        )
    return target


@contextmanager
def staged_dir(path: str | os.PathLike[str], command: str | None = None) -> Iterator[Path]:
    """Yield a fresh folder beside ``path`` that replaces ``path`` when the block ends.

    Everything is written into the staging folder; only when the block finishes
    is its manifest completed (:func:`write_manifest`), the old ``path`` (if any)
    checked to be the same command's own results (:func:`foreign_entries`), moved
    aside, the staging folder renamed to ``path`` and the old one removed. If the
    block raises (or the process is killed), ``path`` is untouched and the staging
    folder is removed (or left as a hidden ``.NAME.PID-*.new`` folder whose
    manifest names the PID, which the next run beside ``path`` removes once that
    process is gone), so ``path`` is never a mix of an old and a new run. On Linux
    the swap is one atomic ``renameat2(RENAME_EXCHANGE)``; elsewhere it is two
    renames. A symbolic link ``path`` is resolved: the folder it points to is
    replaced, the link stays.

    Parameters
    ----------
    path
        The output folder.
    command
        The command whose results these are (``"train"``): a folder of
        another command's results is never replaced. By default the command line's
        command (:func:`running`), else ``"softbend"``.

    Raises
    ------
    InputError
        Before the block, for the current folder or one above it.
    OutputFolderError
        When the block is done, for a ``path`` that holds entries not the command's
        own; nothing is replaced and the new results are left in the staging folder,
        which the message names.
    """
    command = command or current_command()
    target = replaceable_target(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_staging(target)
    staging = Path(
        tempfile.mkdtemp(dir=target.parent, prefix=f".{target.name}.{os.getpid()}-", suffix=".new")
    )
    os.chmod(staging, 0o777 & ~_umask())
    try:
        write_manifest(staging, command, complete=False)
        yield staging
        write_manifest(staging, command, complete=True)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    others = foreign_entries(target, command)
    if others or (target.exists() and not target.is_dir()):
        shown = ", ".join(others[:3]) + (f" and {len(others) - 3} more" if len(others) > 3 else "")
        raise OutputFolderError(
            f"{path} holds what is not this run's to replace ({shown or 'a file'}); nothing "
            f"was replaced, and the new results are in {staging}."
        )
    if target.exists() and _exchange(staging, target):
        shutil.rmtree(staging, ignore_errors=True)  # now holds the old folder
        return
    old = None
    if target.exists():
        old = target.with_name(f".{target.name}.old-{os.getpid()}")
        os.replace(target, old)
    os.replace(staging, target)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


#: The command whose results are being written (set by the command line for each command).
_COMMAND: ContextVar[str] = ContextVar("command", default="softbend")


@contextmanager
def running(command: str) -> Iterator[None]:
    """Write output folders as the results of ``command`` (``"fem run"``) within the block."""
    token = _COMMAND.set(command)
    try:
        yield
    finally:
        _COMMAND.reset(token)


def current_command() -> str:
    """The command being run (:func:`running`): ``"train"``, ``"fem run"``, else ``"softbend"``."""
    return _COMMAND.get()


def remove_stale_staging(path: str | os.PathLike[str]) -> list[Path]:
    """Remove the staging folders of :func:`staged_dir` left beside ``path`` by dead processes.

    Only a folder that proves it is one (:func:`stale_staging`) is removed.
    Returns the folders removed.
    """
    removed = []
    for folder in stale_staging(path):
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def stale_staging(path: str | os.PathLike[str]) -> list[Path]:
    """The staging folders of :func:`staged_dir` beside ``path`` whose process is gone.

    A folder counts when it is named ``.NAME.PID-*.new``, holds an unfinished
    manifest written by process PID, and no process PID exists: what a run
    killed before its swap had written, for a caller that resumes from it first.
    A folder that merely matches the name (no manifest, another PID, a finished
    manifest) is never one, nor is a folder of a live process.
    """
    path = Path(path)
    found = []
    for folder in sorted(path.parent.glob(f".{glob.escape(path.name)}.*-*.new")):
        pid_text = folder.name[len(path.name) + 2 :].split("-", 1)[0]
        if not pid_text.isdigit() or folder.is_symlink() or not folder.is_dir():
            continue
        manifest = read_manifest(folder)
        if manifest is None or manifest.complete or manifest.pid != int(pid_text):
            continue
        if _alive(int(pid_text)):
            continue
        found.append(folder)
    return found


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):  # no such process (or no such PID at all)
        return False
    except PermissionError:  # someone else's process
        return True
    return True


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux ``renameat2(RENAME_EXCHANGE)``); False if unsupported."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    result = renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange)
    return result == 0
