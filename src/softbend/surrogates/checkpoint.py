"""Checkpoint of a surrogate search: its finished configuration-folds survive a kill.

A :class:`SearchCheckpoint` is a JSON-lines file. Its first line is a header
holding the *fingerprint* of the search, everything that determines its scores
(the data hash, the folds, the seed, the grids, the MLP epochs and device, the
library versions); every later line is one finished (family, configuration,
fold): the fold's out-of-fold predictions as the exact float64 bytes (base64)
and the seconds its fit took. Each line is appended with one ``write`` and
made durable with ``fsync`` before the search goes on, so a search killed at
any moment (``kill -9``, a power cut) leaves every fold it finished on disk; a
line cut short by the kill is dropped when the file is opened again.

Opened for the same search, the file hands back those folds, which
:func:`softbend.surrogates.search.search` then loads instead of refitting: the
resumed search gives the same predictions, scores and best configurations as an
uninterrupted one. Opened for a different search (another fingerprint), or
unreadable, the file is discarded (emptied and started over) with a message,
never mixed with the new search. While a search holds the file it is locked
(``flock``, where the system has it): a second search on the same file is
refused instead of interleaving its folds with the first one's.
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np

from softbend.errors import SoftbendError

__all__ = ["FORMAT", "SearchCheckpoint", "checkpoint_path", "group_id"]

#: Version of the file layout, written in the header.
FORMAT = 1

_HEADER_KEY = "softbend_search_checkpoint"


def checkpoint_path(out_dir: str | os.PathLike[str]) -> Path:
    """Where ``softbend train --out OUT`` keeps its checkpoint: ``.OUT.train-checkpoint.jsonl``.

    The file lies beside the output folder, not inside it, because the folder
    is only swapped in when the search has finished.
    """
    out = Path(os.path.abspath(out_dir))
    return out.with_name(f".{out.name}.train-checkpoint.jsonl")


def _plain(value: object) -> Any:
    """JSON fallback for NumPy scalars and arrays."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON-serializable")


def _canonical(value: object) -> Any:
    """``value`` as it reads back from JSON (tuples become lists, NumPy scalars numbers)."""
    return json.loads(json.dumps(value, default=_plain, sort_keys=True))


def group_id(items: Iterable[Any]) -> str:
    """Short stable hash of a list of configurations trained together (MLP batches)."""
    text = json.dumps(_canonical(list(items)), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _key(
    family: str, params: dict[str, Any], fold: int, epochs: int | None, group: str | None
) -> str:
    parts = [family, params, int(fold), epochs, group]
    return json.dumps(_canonical(parts), sort_keys=True, separators=(",", ":"))


def _fsync_dir(folder: Path) -> None:
    """Make a new directory entry durable (not possible everywhere: then skipped)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _lock(fd: int) -> bool:
    """Take an exclusive lock on ``fd`` without waiting; False if another process holds one."""
    try:
        import fcntl
    except ImportError:  # no flock (Windows): unlocked
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


class SearchCheckpoint:
    """Durable record of the finished configuration-folds of one search.

    Parameters
    ----------
    path : path
        The JSON-lines file (created with its folder when the search starts).
    on_resume : callable, optional
        Called with one line of text when the file holds folds of the same search.
    on_discard : callable, optional
        Called with one line of text when the file held another search (or
        unreadable data) and was emptied.

    Notes
    -----
    Nothing touches the file before :meth:`start`, so a search refused for bad
    input leaves no file. Use it as a context manager (or call :meth:`close`) to
    release the file; :meth:`remove` deletes it once the search's results are
    safely elsewhere.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        on_resume: Callable[[str], None] | None = None,
        on_discard: Callable[[str], None] | None = None,
    ) -> None:
        self.path = Path(path)
        self._on_resume = on_resume
        self._on_discard = on_discard
        self._fd: int | None = None
        self._fingerprint: dict[str, Any] | None = None
        self._records: dict[str, tuple[np.ndarray, float]] = {}

    # --- lifetime -----------------------------------------------------------------------

    def __enter__(self) -> SearchCheckpoint:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        """Release the file (and its lock), keeping it on disk for a later resume."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def remove(self) -> None:
        """Delete the file: the search's results are kept elsewhere now."""
        self.path.unlink(missing_ok=True)  # still locked: no other search slips in between
        self.close()
        self._records.clear()

    @property
    def n_records(self) -> int:
        """Finished configuration-folds on hand (loaded or added since :meth:`start`)."""
        return len(self._records)

    def start(self, fingerprint: dict[str, Any]) -> int:
        """Open and lock the file for the search ``fingerprint``; return the folds it holds.

        Parameters
        ----------
        fingerprint : dict
            JSON-serializable description of everything that determines the scores.

        Returns
        -------
        int
            Finished configuration-folds found for this search (0 for a new or
            discarded file).

        Raises
        ------
        SoftbendError
            If another process holds the file.
        ValueError
            If this checkpoint was already started for another fingerprint.
        """
        fingerprint = _canonical(fingerprint)
        if self._fd is not None:
            if fingerprint != self._fingerprint:
                raise ValueError(
                    f"The checkpoint {self.path} was started for another search; "
                    "use one SearchCheckpoint per search."
                )
            return len(self._records)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        existed = self.path.exists()
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_APPEND, 0o666)
        if not _lock(fd):
            os.close(fd)
            raise SoftbendError(
                f"Another search is writing the checkpoint {self.path} (a second "
                "'softbend train' into the same output folder?); wait for it to finish "
                "or choose another output folder."
            )
        self._fd = fd
        self._fingerprint = fingerprint
        try:
            self._load(existed)
        except BaseException:
            self.close()
            raise
        if self._records and self._on_resume is not None:
            self._on_resume(
                f"resuming from {self.path}: {len(self._records)} configuration-folds of an "
                "interrupted search already done"
            )
        return len(self._records)

    # --- reading ------------------------------------------------------------------------

    def _read(self) -> bytes:
        assert self._fd is not None
        os.lseek(self._fd, 0, os.SEEK_SET)  # (writes still go to the end: O_APPEND)
        chunks = []
        while chunk := os.read(self._fd, 1 << 20):
            chunks.append(chunk)
        return b"".join(chunks)

    def _load(self, existed: bool) -> None:
        assert self._fd is not None
        data = self._read()
        if not data:
            self._reset(new=not existed)
            return
        end = data.rfind(b"\n") + 1  # a last line without its newline was cut by a kill
        lines = data[:end].split(b"\n")[:-1]
        header = _parse(lines[0]) if lines else None
        if not isinstance(header, dict) or header.get(_HEADER_KEY) != FORMAT:
            self._discard("it is not a readable search checkpoint")
            return
        theirs = header.get("fingerprint")
        if theirs != self._fingerprint:
            differ = sorted(
                k
                for k in set(self._fingerprint or {}) | set(theirs or {})
                if (theirs or {}).get(k) != (self._fingerprint or {}).get(k)
            )
            self._discard(
                f"it holds an interrupted search with other settings ({', '.join(differ)})"
            )
            return
        if end < len(data):
            os.ftruncate(self._fd, end)
            os.fsync(self._fd)
        for line in lines[1:]:
            record = _parse(line)
            try:
                key = _key(*record["key"])
                pred = np.frombuffer(base64.b64decode(record["pred"], validate=True), dtype="<f8")
                seconds = float(record["seconds"])
            except (TypeError, KeyError, ValueError):
                continue  # an unreadable record is recomputed
            self._records[key] = (pred.astype(np.float64), seconds)

    def _discard(self, why: str) -> None:
        if self._on_discard is not None:
            self._on_discard(f"discarded {self.path}: {why}; the search starts over")
        self._reset(new=False)

    def _reset(self, *, new: bool) -> None:
        assert self._fd is not None
        os.ftruncate(self._fd, 0)
        header = {_HEADER_KEY: FORMAT, "fingerprint": self._fingerprint}
        self._append([header])
        if new:
            _fsync_dir(self.path.parent)
        self._records.clear()

    # --- the records ----------------------------------------------------------------------

    def get(
        self,
        family: str,
        params: dict[str, Any],
        fold: int,
        *,
        size: int,
        epochs: int | None = None,
        group: str | None = None,
    ) -> tuple[np.ndarray, float] | None:
        """The finished fold ``(predictions, seconds)``, or None if it must be computed.

        ``size`` is the number of the fold's validation rows; a record of another
        size is not this fold's and is ignored. ``epochs`` and ``group`` tell
        apart MLPs trained for different epochs or in different batches.
        """
        found = self._records.get(_key(family, params, fold, epochs, group))
        if found is None or found[0].shape != (size,):
            return None
        return found[0].copy(), found[1]

    def add(
        self,
        family: str,
        params: dict[str, Any],
        fold: int,
        pred: np.ndarray,
        seconds: float,
        *,
        epochs: int | None = None,
        group: str | None = None,
    ) -> None:
        """Append one finished fold durably (written and fsynced before returning)."""
        self.add_many([(family, params, fold, pred, seconds, epochs, group)])

    def add_many(
        self,
        folds: Iterable[tuple[str, dict[str, Any], int, np.ndarray, float, int | None, str | None]],
    ) -> None:
        """Append finished folds ``(family, params, fold, pred, seconds, epochs, group)``.

        They are written together and fsynced once.
        """
        if self._fd is None:
            raise ValueError(f"The checkpoint {self.path} is not started; call start() first.")
        lines = []
        for family, params, fold, pred, seconds, epochs, group in folds:
            values = np.ascontiguousarray(pred, dtype="<f8")
            key = _key(family, params, fold, epochs, group)
            lines.append(
                {
                    "key": json.loads(key),
                    "seconds": float(seconds),
                    "pred": base64.b64encode(values.tobytes()).decode("ascii"),
                }
            )
            self._records[key] = (values.astype(np.float64), float(seconds))
        self._append(lines)

    def _append(self, records: list[dict[str, Any]]) -> None:
        assert self._fd is not None
        text = "".join(
            json.dumps(r, default=_plain, separators=(",", ":"), allow_nan=False) + "\n"
            for r in records
        )
        data = memoryview(text.encode("utf-8"))
        while data:
            written = os.write(self._fd, data)
            data = data[written:]
        os.fsync(self._fd)


def _parse(line: bytes) -> Any:
    try:
        return json.loads(line)
    except ValueError:
        return None
