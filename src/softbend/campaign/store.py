"""The campaign database: one DuckDB file per campaign.

:class:`CampaignStore` opens (or creates) the file, binds it to one backend, its
settings (:mod:`softbend.campaign.settings`) and one pressure grid, records
designs, merges shards and reads the data back;
:func:`merge_campaigns` merges several shards into one database all or nothing. The
tables, their schema version and the checks of an existing file live in
:mod:`softbend.campaign.schema`.

Every design is written in one transaction (its ``designs`` row and all its
``samples`` rows, or nothing), so a campaign killed at any instant leaves only
complete designs, and a design recorded again (a failed design retried) replaces
its earlier row in the same transaction: no design and no sample is ever stored
twice. DuckDB allows one writing process per file: only the process that
coordinates a campaign writes; workers only compute.
"""

from __future__ import annotations

import errno
import json
import logging
import math
import os
import shutil
import uuid
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, cast

import numpy as np

from softbend._io import new_file_mode
from softbend._validation import check_choice
from softbend.actuators import Design
from softbend.campaign.family_schema import CampaignDesign, FamilySchema
from softbend.campaign.schema import SAMPLE_COLUMNS as SAMPLE_COLUMNS
from softbend.campaign.schema import (
    SCHEMA_VERSION,
    check_complete,
    check_duckdb_file,
    design_columns,
    ensure_schema,
    first_line,
    missing_database,
    open_error,
    quoted,
    read_family,
    softbend_version,
    transaction,
    unreadable,
    utc_now,
    write_error,
)
from softbend.campaign.settings import (
    SettingsMismatchError,
    UncheckedSettingsWarning,
    describe_differences,
    settings_differences,
)
from softbend.errors import SchemaError, SoftbendError
from softbend.models import SweepResult, check_pressures_mpa

if TYPE_CHECKING:
    import pandas as pd
    from duckdb import DuckDBPyConnection

    from softbend.actuators import Actuator
    from softbend.fem.families import FEMFamily

__all__ = [
    "SCHEMA_VERSION",
    "CampaignStore",
    "campaign_actuator",
    "load_designs",
    "load_samples",
    "merge_campaigns",
]

logger = logging.getLogger(__name__)

# One statement for all samples of a design: parallel lists unnested row-wise.
_INSERT_SAMPLES = (
    "INSERT INTO samples SELECT ?, unnest(?::DOUBLE[]), unnest(?::DOUBLE[]), "
    "unnest(?::DOUBLE[]), unnest(?::DOUBLE[]), unnest(?::BOOLEAN[]), unnest(?::INTEGER[])"
)


def _insert_design(columns: tuple[str, ...]) -> str:
    """The statement inserting one ``designs`` row of ``columns``."""
    return (
        f"INSERT INTO designs ({', '.join(map(quoted, columns))}) "
        f"VALUES ({', '.join('?' for _ in columns)})"
    )


def _samples_query(parameters: tuple[str, ...]) -> str:
    """The samples joined with the designs' ``parameters``, by design and pressure."""
    return (
        f"SELECT s.design_id, {', '.join('d.' + quoted(p) for p in parameters)}, "
        "s.pressure_mpa, s.angle_deg, s.tip_x_mm, s.tip_z_mm, s.converged "
        "FROM samples s JOIN designs d USING (design_id) "
        "ORDER BY s.design_id, s.pressure_mpa"
    )


def _nullable(values: np.ndarray) -> list[float | None]:
    """Floats for DuckDB with NaN as NULL (no value rather than a NaN value)."""
    return [v if math.isfinite(v) else None for v in values.tolist()]


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None


class CampaignStore:
    """Open (or create) the DuckDB database of a campaign.

    Parameters
    ----------
    path : str or os.PathLike
        Database file. Created with the current schema when missing (unless
        ``read_only``).
    read_only : bool
        Open an existing database for reading only (status, export, analysis).
    family : FEMFamily, FamilySchema or str, optional
        The FEM actuator family of the campaign's designs
        (:mod:`softbend.campaign.family_schema`). A new database is created for it
        (default paper B's, ``"sfrba"``); an existing one must hold it. None
        opens an existing database of any family.

    Raises
    ------
    FileNotFoundError
        ``read_only`` and no file at ``path``.
    SchemaError
        The file is not a readable DuckDB database (empty, not DuckDB such as a
        CSV, truncated, a damaged block: every block is read once on opening), not
        a softbend campaign, or has a schema version newer than
        :data:`SCHEMA_VERSION`, or ``path`` is a folder; one line naming the file.
    SoftbendError
        The file is locked by another process (a running campaign).
    ValueError
        ``family`` given and the existing database holds another family's designs.
    OSError
        A new file could not be written (a full disk): it names the file, and
        nothing of it is left. Any later write that fails the same way (recording
        a design, binding, merging, exporting) is an ``OSError`` naming the file
        written; every design committed before it stays in the database.

    Notes
    -----
    Use as a context manager or call :meth:`close`. DuckDB lets one process
    write a database file at a time, and a reader cannot open it while a
    campaign writes to it.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        read_only: bool = False,
        family: FEMFamily | FamilySchema | str | None = None,
    ) -> None:
        import duckdb

        wanted = family if isinstance(family, FamilySchema | None) else FamilySchema.of(family)

        self.path = Path(path)
        self.read_only = bool(read_only)
        if self.path.is_dir() or (self.read_only and not self.path.is_file()):
            raise missing_database(self.path)
        if not self.read_only and not self.path.parent.is_dir():
            raise FileNotFoundError(
                f"The folder of the campaign database {str(self.path)!r} does not exist."
            )
        existed = self.path.is_file()
        if existed:
            check_duckdb_file(self.path)  # a CSV or an empty file, before DuckDB reads it
        try:
            self._con = duckdb.connect(str(self.path), read_only=self.read_only)
        except duckdb.Error as exc:
            failed = None if existed else write_error(exc, self.path)
            if failed is not None:  # a new file that could not be written: no half-made file
                _remove_database(self.path)
            raise (failed or open_error(self.path, exc)) from None
        # Every DuckDB error while reading what opening needs (a truncated or corrupt file
        # fails here, at connect or on the first reads) is one SchemaError naming the file;
        # one while creating a new file (a full disk) is the OSError it is, and the
        # half-made file is removed.
        try:
            # No progress bar of DuckDB's own on a long query: it would write to stdout.
            self._con.execute("SET enable_progress_bar = false")
            if existed:
                check_complete(self._con, self.path)
            ensure_schema(self._con, self.path, read_only=self.read_only, family=wanted)
            self._family = read_family(self._con, self.path)
            if wanted is not None and wanted.name != self._family.name:
                raise ValueError(
                    f"The campaign in {str(self.path)!r} holds designs of the "
                    f"{self._family.name!r} family. Got family {wanted.name!r} instead; use a "
                    "new database for another family."
                )
            self._design_columns = design_columns(self._family.parameters)
            self._insert_design = _insert_design(self._design_columns)
            self._load_binding()
            self._recorded: set[str] = {
                row[0] for row in self._con.execute("SELECT design_id FROM designs").fetchall()
            }
        except duckdb.Error as exc:
            _close_quietly(self._con)
            failed = None if self.read_only else write_error(exc, self.path)
            if not existed:
                _remove_database(self.path)
            raise (failed or unreadable(self.path, first_line(exc))) from None
        except BaseException:
            _close_quietly(self._con)
            if not existed:
                _remove_database(self.path)
            raise

    def close(self) -> None:
        """Close the connection (checkpointing the write-ahead log).

        Raises
        ------
        OSError
            The checkpoint could not be written (a full disk); what was committed
            stays in the write-ahead log beside the file and is read on the next
            opening.
        """
        with self._writing():
            self._con.close()

    @contextmanager
    def _writing(self, path: str | os.PathLike[str] | None = None) -> Iterator[None]:
        """Within, a DuckDB error of a failed write is the :class:`OSError` it is.

        The error names ``path`` (default: this database), so a command's
        ``output_errors`` makes it one line; other DuckDB errors pass unchanged.
        """
        import duckdb

        try:
            yield
        except duckdb.Error as exc:
            failed = write_error(exc, self.path if path is None else path)
            if failed is None:
                raise
            raise failed from None

    def __enter__(self) -> CampaignStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"CampaignStore({str(self.path)!r}, read_only={self.read_only})"

    # -- campaign metadata -------------------------------------------------------
    def meta(self) -> dict[str, str]:
        """The ``meta`` table as a ``{key: value}`` dict of strings."""
        return dict(self._con.execute("SELECT key, value FROM meta").fetchall())

    def _set_meta(self, key: str, value: str) -> None:
        self._con.execute(
            "INSERT INTO meta VALUES (?, ?) ON CONFLICT (key) DO UPDATE SET value = excluded.value",
            [key, value],
        )

    def _load_binding(self) -> None:
        # Backend and grid change only through bind(); cached for the hot write path.
        meta = self.meta()
        text = meta.get("pressures_mpa")
        self._backend = meta.get("backend")
        self._grid = None if text is None else self._stored_grid(text)
        if self._grid is not None:
            self._grid.setflags(write=False)
        settings = meta.get("settings")
        self._settings = None if settings is None else self._stored_settings(settings)

    def _stored_settings(self, text: str) -> dict[str, Any]:
        """The backend settings kept in the ``meta`` table; a damaged entry is refused."""
        try:
            settings = json.loads(text)
        except (ValueError, RecursionError):
            settings = None
        if not isinstance(settings, dict):
            raise SchemaError(
                f"The campaign database {str(self.path)!r} has a damaged 'settings' in its "
                f"'meta' table: it must be a JSON object. Got {text[:80]!r}."
            )
        return settings

    def _stored_grid(self, text: str) -> np.ndarray:
        """The pressure grid kept in the ``meta`` table, checked like a grid of a run."""
        try:
            values = json.loads(text)
            if not isinstance(values, list) or not all(
                isinstance(v, int | float) and not isinstance(v, bool) for v in values
            ):
                raise ValueError("not a JSON list of numbers")
            return check_pressures_mpa(np.asarray(values, dtype=float))
        except (ValueError, RecursionError) as exc:
            reason = "nested too deeply" if isinstance(exc, RecursionError) else first_line(exc)
            raise SchemaError(
                f"The campaign database {str(self.path)!r} has a damaged 'pressures_mpa' in its "
                f"'meta' table: it must be a JSON list of increasing pressures >= 0 in MPa. "
                f"Got {text[:80]!r} ({reason})."
            ) from None

    def _meta_int(self, key: str) -> int | None:
        """An integer of the ``meta`` table (None when missing); a damaged one is refused."""
        text = self.meta().get(key)
        if text is None:
            return None
        try:
            return int(text)
        except ValueError:
            raise SchemaError(
                f"The campaign database {str(self.path)!r} has a damaged {key!r} in its 'meta' "
                f"table: it must be an integer. Got {text[:80]!r}."
            ) from None

    @property
    def family(self) -> str:
        """The FEM actuator family of the campaign's designs (``"sfrba"`` if none recorded)."""
        return self._family.name

    @property
    def family_schema(self) -> FamilySchema:
        """The family, its parameter columns and its recorded actuator description."""
        return self._family

    @property
    def parameters(self) -> tuple[str, ...]:
        """The design parameters' columns of the ``designs`` table, in order."""
        return self._family.parameters

    @property
    def backend(self) -> str | None:
        """Backend the campaign was started with (None before the first run)."""
        return self._backend

    @property
    def pressures_mpa(self) -> np.ndarray | None:
        """Pressure grid of the campaign in MPa (None before the first run)."""
        return self._grid

    @property
    def settings(self) -> dict[str, Any] | None:
        """Backend settings the campaign was started with (None if not recorded).

        See :func:`~softbend.campaign.settings.backend_settings`: the backend, the
        pressure grid, the FEM options and the material. None before the first
        run and in a database of a softbend that did not record them.
        """
        return None if self._settings is None else json.loads(json.dumps(self._settings))

    def bind(
        self,
        backend: str,
        pressures_mpa: np.ndarray,
        *,
        space: str | None = None,
        n_designs_planned: int | None = None,
        settings: dict[str, Any] | None = None,
        accept_new_settings: bool = False,
    ) -> None:
        """Fix the backend, its settings and the pressure grid, or check them on resume.

        Parameters
        ----------
        backend : str
            Backend name.
        pressures_mpa : numpy.ndarray
            Sweep grid, MPa, strictly increasing.
        space : str, optional
            Label of the design space (stored for reports).
        n_designs_planned : int, optional
            Number of designs this run asked for.
        settings : dict, optional
            The backend's settings (:func:`~softbend.campaign.settings.backend_settings`).
            Recorded by the first bind; checked by later ones. A database
            bound before without settings (of an older softbend) takes them,
            with an :class:`~softbend.campaign.settings.UncheckedSettingsWarning`
            when it holds designs already.
        accept_new_settings : bool
            Go on even if ``settings`` differ from the recorded ones (the recorded
            ones stay: they are those of the campaign's first run).

        Raises
        ------
        ValueError
            If the database already holds a campaign with another backend or grid:
            mixing them would make the data inconsistent; use a new database.
        SettingsMismatchError
            Other settings than the recorded ones, not accepted; it names each
            differing setting with both values.
        """
        grid = check_pressures_mpa(pressures_mpa)
        stored_backend, stored_grid = self.backend, self.pressures_mpa
        if stored_backend is not None and stored_backend != backend:
            raise ValueError(
                f"The 'backend' of the campaign in {str(self.path)!r} is {stored_backend!r}. "
                f"Got {backend!r} instead; use a new database for another backend."
            )
        if stored_grid is not None and not np.array_equal(stored_grid, grid):
            raise ValueError(
                f"The 'pressures_mpa' of the campaign in {str(self.path)!r} are "
                f"{_describe_grid(stored_grid)}. Got {_describe_grid(grid)} instead; "
                "use a new database for another pressure grid."
            )
        recorded = self._settings
        if settings is not None and recorded is not None:
            differences = settings_differences(recorded, settings)
            if differences and not accept_new_settings:
                raise SettingsMismatchError(self.path, differences)
            if differences:
                logger.warning(
                    "campaign %s resumed with other settings (accepted): %s",
                    self.path,
                    ", ".join(name for name, _, _ in differences),
                )
        elif settings is not None and stored_backend is not None and self._recorded:
            warnings.warn(
                f"The campaign database {str(self.path)!r} records no backend settings (an "
                f"older softbend's, or bound without them): its {len(self._recorded)} designs "
                "recorded before could not be checked against the settings of this run "
                "(mesh, material, options); these are recorded now and checked from now on.",
                UncheckedSettingsWarning,
                stacklevel=2,
            )
        with self._writing(), transaction(self._con):
            if stored_backend is None:
                self._set_meta("backend", backend)
            if stored_grid is None:
                self._set_meta("pressures_mpa", json.dumps(grid.tolist()))
            if settings is not None and recorded is None:
                self._set_meta("settings", json.dumps(settings, default=str, sort_keys=True))
            if space is not None:
                self._set_meta("space", str(space))
            if n_designs_planned is not None:
                self._set_meta("n_designs_planned", str(int(n_designs_planned)))
        self._load_binding()

    def runs(self) -> list[dict[str, Any]]:
        """The runs recorded by :meth:`log_run` (oldest first), shards merged in included.

        Raises
        ------
        SchemaError
            The ``runs`` entry of the ``meta`` table is not a JSON list of objects.
        """
        text = self.meta().get("runs", "[]")
        try:
            runs = json.loads(text)
        except (ValueError, RecursionError):
            runs = None
        if not isinstance(runs, list) or not all(isinstance(run, dict) for run in runs):
            raise SchemaError(
                f"The campaign database {str(self.path)!r} has a damaged 'runs' in its 'meta' "
                f"table: it must be a JSON list of objects. Got {text[:80]!r}."
            )
        return runs

    def log_run(self, run: dict[str, Any]) -> None:
        """Append one run's record (executor, cores, counts, times) to the ``runs`` metadata."""
        runs = [*self.runs(), run]
        with self._writing(), transaction(self._con):
            self._set_meta("runs", json.dumps(runs, default=str))

    def merge(self, source: str | os.PathLike[str]) -> dict[str, int]:
        """Copy the designs of another campaign database (a shard) into this one.

        The source must hold the same backend, settings and pressure grid (this database takes them
        if it has none yet; settings missing on either side, in a database of an older
        softbend, cannot be checked and are warned of). Each design is copied with its
        samples in one transaction per source: a design done here is kept; a design done in
        the source replaces a failed row here; a design failed in the source is copied only
        where this database has no row for it. Merging the same shard twice changes nothing.

        Parameters
        ----------
        source : str or os.PathLike
            Campaign database to read (not modified).

        Returns
        -------
        dict
            ``{"added": designs copied, "replaced_failed": failed rows replaced,
            "kept": designs of the source left out because this database has them}``.

        Raises
        ------
        ValueError
            The source holds another backend or pressure grid, or is this database.
        SettingsMismatchError
            The source holds other settings.
        """
        if self.read_only:
            raise SoftbendError(f"{str(self.path)!r} is open read-only; it cannot be merged into.")
        source_path = Path(source)
        if source_path.resolve() == self.path.resolve():
            raise ValueError(f"A campaign cannot be merged into itself: {str(source_path)!r}.")
        with CampaignStore(source_path, read_only=True) as other:
            backend, grid, settings = other.backend, other.pressures_mpa, other.settings
            _check_same_family((self.family, self.path), (other.family, source_path))
            their_runs = other.runs()
            theirs = {
                row[0]: row[1]
                for row in other._con.execute("SELECT design_id, status FROM designs").fetchall()
            }
        if backend is None or grid is None:
            return {"added": 0, "replaced_failed": 0, "kept": 0}
        if settings is None and self._settings is not None and theirs:
            warnings.warn(
                f"The campaign database {str(source_path)!r} records no backend settings (an "
                f"older softbend's, or bound without them): its {len(theirs)} designs could not be "
                f"checked against the settings of {str(self.path)!r}.",
                UncheckedSettingsWarning,
                stacklevel=2,
            )
        self.bind(backend, grid, settings=settings)
        with self._writing():
            take, replaced = self._copy_designs(source_path, theirs)
        if take:
            known = self.runs()
            for run in their_runs:
                if run not in known:
                    self.log_run({**run, "merged_from": str(source_path.name)})
        logger.info("merged %d designs of %s into %s", len(take), source_path, self.path)
        return {
            "added": len(take) - replaced,
            "replaced_failed": replaced,
            "kept": len(theirs) - len(take),
        }

    def _copy_designs(self, source_path: Path, theirs: dict[str, str]) -> tuple[list[str], int]:
        """Copy the designs of ``source_path`` that :meth:`merge` takes, in one transaction."""
        mine = {
            row[0]: row[1]
            for row in self._con.execute("SELECT design_id, status FROM designs").fetchall()
        }
        take = [
            i
            for i, status in theirs.items()
            if i not in mine or (status == "done" and mine[i] == "failed")
        ]
        replaced = sum(i in mine for i in take)
        self._con.execute(f"ATTACH '{_sql_text(source_path)}' AS merge_src (READ_ONLY)")
        try:
            with transaction(self._con):
                self._con.execute("CREATE TEMP TABLE merge_ids (design_id VARCHAR)")
                if take:
                    self._con.executemany("INSERT INTO merge_ids VALUES (?)", [[i] for i in take])
                self._con.execute(
                    "DELETE FROM samples WHERE design_id IN (SELECT * FROM merge_ids)"
                )
                self._con.execute(
                    "DELETE FROM designs WHERE design_id IN (SELECT * FROM merge_ids)"
                )
                columns = ", ".join(map(quoted, self._design_columns))
                self._con.execute(
                    f"INSERT INTO designs ({columns}) SELECT {columns} FROM merge_src.designs "
                    "WHERE design_id IN (SELECT * FROM merge_ids)"
                )
                self._con.execute(
                    "INSERT INTO samples SELECT * FROM merge_src.samples "
                    "WHERE design_id IN (SELECT * FROM merge_ids)"
                )
                self._con.execute("DROP TABLE merge_ids")
        finally:
            self._con.execute("DETACH merge_src")
        self._recorded.update(take)
        return take, replaced

    # -- writing -----------------------------------------------------------------
    def record_success(self, result: SweepResult, *, backend: str | None = None) -> None:
        """Store a finished sweep (its ``designs`` row and samples) in one transaction.

        A row already recorded for the design (e.g. a failed attempt) is replaced.

        Parameters
        ----------
        result : SweepResult
            The sweep; its converged pressures must be the leading values of the
            campaign grid when one is bound.
        backend : str, optional
            Backend name; default the campaign's (see :meth:`bind`).
        """
        if not isinstance(result, SweepResult):
            raise ValueError(
                f"The 'result' of CampaignStore.record_success must be a SweepResult. "
                f"Got {type(result).__name__} instead."
            )
        backend = self._backend_name(backend)
        self._check_on_grid(result)
        design = result.design
        self._check_family(design)
        stats = json.dumps(result.stats, default=str) if result.stats else None
        row = [
            design.design_id,
            *design.as_array().tolist(),
            "done",
            None,
            result.wall_time_s,
            len(result.pressure_mpa),
            _finite_or_none(result.max_pressure_mpa),
            _finite_or_none(result.max_angle_deg),
            int(result.newton_iterations.sum()),
            result.mesh_size,
            backend,
            softbend_version(),
            SCHEMA_VERSION,
            utc_now(),
            stats,
        ]
        with self._writing(), transaction(self._con):
            self._delete(design.design_id)
            self._con.execute(self._insert_design, row)
            if len(result.pressure_mpa):
                self._con.execute(
                    _INSERT_SAMPLES,
                    [
                        design.design_id,
                        result.pressure_mpa.tolist(),
                        _nullable(result.angle_deg),
                        _nullable(result.tip_x_mm),
                        _nullable(result.tip_z_mm),
                        result.converged.tolist(),
                        result.newton_iterations.tolist(),
                    ],
                )
        self._recorded.add(design.design_id)

    def record_failure(
        self,
        design: CampaignDesign,
        error_text: str,
        wall_time_s: float,
        *,
        backend: str | None = None,
    ) -> None:
        """Store a design whose sweep raised, with ``error_text``, in one transaction.

        Parameters
        ----------
        design : Design
            The design, of the campaign's family.
        error_text : str
            Why it failed, conventionally ``"ExceptionType: message"``.
        wall_time_s : float
            Time spent before the failure, s.
        backend : str, optional
            Backend name; default the campaign's.
        """
        if not isinstance(design, Design):
            raise ValueError(
                f"The 'design' of CampaignStore.record_failure must be a Design. "
                f"Got {design!r} instead."
            )
        self._check_family(design)
        backend = self._backend_name(backend)
        wall = float(wall_time_s)
        row = [
            design.design_id,
            *design.as_array().tolist(),
            "failed",
            str(error_text),
            wall if math.isfinite(wall) else None,
            0,
            None,
            None,
            None,
            None,
            backend,
            softbend_version(),
            SCHEMA_VERSION,
            utc_now(),
            None,
        ]
        with self._writing(), transaction(self._con):
            self._delete(design.design_id)
            self._con.execute(self._insert_design, row)
        self._recorded.add(design.design_id)

    def _check_family(self, design: Design) -> None:
        """Refuse a design of another family than the campaign's (its columns differ)."""
        family = design.actuator.fem_family or design.actuator.name
        names = tuple(design.as_dict())
        if family != self.family or names != self.parameters:
            raise ValueError(
                f"The designs of the campaign in {str(self.path)!r} are of the {self.family!r} "
                f"family ({', '.join(self.parameters)}). Got a design of {family!r} "
                f"({', '.join(names)}) instead."
            )

    def _delete(self, design_id: str) -> None:
        # Only when something is there: a DELETE costs as much as the insert.
        if design_id in self._recorded:
            self._con.execute("DELETE FROM samples WHERE design_id = ?", [design_id])
            self._con.execute("DELETE FROM designs WHERE design_id = ?", [design_id])

    def _backend_name(self, backend: str | None) -> str:
        name = backend if backend is not None else self.backend
        if not name:
            raise ValueError(
                "The 'backend' of the recorded design must be given: bind the campaign to a "
                "backend first (CampaignStore.bind) or pass backend=..."
            )
        return str(name)

    def _check_on_grid(self, result: SweepResult) -> None:
        grid = self.pressures_mpa
        if grid is None:
            return
        done = result.pressure_mpa[result.converged]
        if len(done) > len(grid) or not np.array_equal(done, grid[: len(done)]):
            raise ValueError(
                f"The pressures of design {result.design} must be the leading values of the "
                f"campaign grid ({_describe_grid(grid)}). Got {_describe_grid(done)} instead."
            )

    # -- reading -----------------------------------------------------------------
    def finished_ids(self, *, include_failed: bool = False) -> set[str]:
        """IDs of the designs recorded as done (and failed, if ``include_failed``)."""
        statuses = ("done", "failed") if include_failed else ("done",)
        rows = self._con.execute(
            f"SELECT design_id FROM designs WHERE status IN ({', '.join('?' for _ in statuses)})",
            list(statuses),
        ).fetchall()
        return {row[0] for row in rows}

    def failed_ids(self) -> set[str]:
        """IDs of the designs recorded as failed."""
        rows = self._con.execute("SELECT design_id FROM designs WHERE status = 'failed'").fetchall()
        return {row[0] for row in rows}

    def status_summary(self, *, max_failures: int = 20) -> dict[str, Any]:
        """Counts and metadata of the campaign, JSON-serialisable.

        Keys: ``path``, ``schema_version``, ``softbend_version``, ``created_at``,
        ``backend``, ``settings`` (as :attr:`settings`), ``space``,
        ``n_designs_planned`` (None if never run),
        ``n_pressures``, ``pmin_mpa``, ``pmax_mpa``, ``designs_recorded``,
        ``done``, ``failed``, ``samples``, ``converged_samples``,
        ``sweep_time_s_total``, ``sweep_time_s_mean`` (over done designs),
        ``max_angle_deg``, ``last_finished_at`` and ``failures`` (up to
        ``max_failures`` ``{"design_id", "design", "error"}`` entries); a
        campaign of another family than paper B's also ``family``, and
        ``parameters`` (the columns of ``design``).
        """
        meta = self.meta()
        grid = self.pressures_mpa
        counts = self._con.execute(
            "SELECT count(*) FILTER (WHERE status = 'done'), "
            "count(*) FILTER (WHERE status = 'failed'), "
            "sum(wall_time_s) FILTER (WHERE status = 'done'), "
            "avg(wall_time_s) FILTER (WHERE status = 'done'), "
            "max(max_angle_deg), max(finished_at) FROM designs"
        ).fetchone()
        sample_counts = self._con.execute(
            "SELECT count(*), count(*) FILTER (WHERE converged) FROM samples"
        ).fetchone()
        # Aggregate queries without GROUP BY always return one row.
        assert counts is not None and sample_counts is not None
        done, failed, wall_total, wall_mean, max_angle, last = counts
        n_samples, n_converged = sample_counts
        n_parameters = len(self.parameters)
        failures = self._con.execute(
            f"SELECT design_id, {', '.join(map(quoted, self.parameters))}, error FROM designs "
            "WHERE status = 'failed' ORDER BY finished_at, design_id LIMIT ?",
            [int(max_failures)],
        ).fetchall()
        planned = self._meta_int("n_designs_planned")
        recorded = self._family.actuator is not None
        return {
            "path": str(self.path),
            **({"family": self.family} if recorded else {}),
            "schema_version": int(meta["schema_version"]),
            "softbend_version": meta.get("softbend_version"),
            "created_at": meta.get("created_at"),
            "backend": meta.get("backend"),
            "settings": self.settings,
            "space": meta.get("space"),
            "n_designs_planned": planned,
            "n_pressures": None if grid is None else len(grid),
            "pmin_mpa": None if grid is None else float(grid[0]),
            "pmax_mpa": None if grid is None else float(grid[-1]),
            "designs_recorded": int(done + failed),
            "done": int(done),
            "failed": int(failed),
            "samples": int(n_samples),
            "converged_samples": int(n_converged),
            "sweep_time_s_total": float(wall_total or 0.0),
            "sweep_time_s_mean": None if wall_mean is None else float(wall_mean),
            "max_angle_deg": None if max_angle is None else float(max_angle),
            "last_finished_at": None if last is None else last.isoformat(timespec="seconds") + "Z",
            **({"parameters": list(self.parameters)} if recorded else {}),
            "failures": [
                {
                    "design_id": row[0],
                    # Formatted from the stored values, not rebuilt: a database of an
                    # older softbend may hold a design today's rules refuse (t >= r).
                    "design": ",".join(f"{float(v):g}" for v in row[1 : 1 + n_parameters]),
                    "error": row[1 + n_parameters],
                }
                for row in failures
            ],
        }

    def load_samples(self) -> pd.DataFrame:
        """Every stored sample joined with its design parameters.

        Returns
        -------
        pandas.DataFrame
            Columns ``design_id, l_mm, r_mm, t_mm, b_mm, phi_deg, lc_mm,
            pressure_mpa, angle_deg, tip_x_mm, tip_z_mm, converged`` (the
            family's parameters in place of paper B's ``l_mm`` ... ``lc_mm``
            in a campaign of another family), sorted by design and pressure.
            The last pressure of a truncated sweep has ``converged`` False and
            NaN angle and tip: filter on ``converged`` to get training data.
        """
        frame = self._con.execute(_samples_query(self.parameters)).df()
        frame["converged"] = frame["converged"].astype(bool)
        return frame

    def load_designs(self) -> pd.DataFrame:
        """The ``designs`` table (done and failed), sorted by ``design_id``."""
        return self._con.execute(
            f"SELECT {', '.join(map(quoted, self._design_columns))} FROM designs ORDER BY design_id"
        ).df()

    def export(
        self,
        path: str | os.PathLike[str],
        format: Literal["parquet", "csv"] = "parquet",
        *,
        table: Literal["samples", "designs"] = "samples",
    ) -> Path:
        """Write the samples (as :meth:`load_samples`) or the designs table to a file.

        The file appears atomically: it is written to a temporary file in the same
        folder and moved into place with :func:`os.replace`, so a reader never
        sees a half-written export and an interrupted export leaves any previous
        file intact.

        Parameters
        ----------
        path : str or os.PathLike
            Output file; its folder must exist.
        format : {"parquet", "csv"}
            Apache Parquet (typed, compressed) or CSV with a header (NULL as an
            empty field).
        table : {"samples", "designs"}
            What to export.

        Returns
        -------
        pathlib.Path
            The written file.

        Raises
        ------
        OSError
            The file could not be written (a full disk, a read-only folder); it
            names ``path``, and nothing is left of the export.
        """
        check_choice(format, "format", ("parquet", "csv"))
        check_choice(table, "table", ("samples", "designs"))
        target = Path(path)
        if not target.parent.is_dir():
            raise FileNotFoundError(
                f"The folder of the export file {str(target)!r} does not exist."
            )
        query = (
            _samples_query(self.parameters)
            if table == "samples"
            else f"SELECT {', '.join(map(quoted, self._design_columns))} FROM designs "
            "ORDER BY design_id"
        )
        tmp = target.with_name(f".{target.name}.{uuid.uuid4().hex}.tmp")
        try:
            with self._writing(target):
                relation = self._con.sql(query)
                if format == "parquet":
                    relation.write_parquet(str(tmp))
                else:
                    relation.write_csv(str(tmp), header=True)
            os.chmod(tmp, new_file_mode(target))
            os.replace(tmp, target)
        finally:
            tmp.unlink(missing_ok=True)
        logger.info("exported %s of %s to %s (%s)", table, self.path, target, format)
        return target


def merge_campaigns(
    target: str | os.PathLike[str], sources: Sequence[str | os.PathLike[str]]
) -> list[dict[str, Any]]:
    """Merge campaign databases (shards) into ``target``, all or nothing.

    Every source, and ``target`` if it exists, is checked before anything is written: each must
    be a readable campaign database (not damaged, of a schema this softbend reads), and all
    that hold a campaign must share one backend, one pressure grid and the same settings
    (where recorded). The merge is then written into a copy of ``target`` (or a new
    database) beside it, which replaces ``target`` only when every source is in: a merge
    that fails (a bad shard, a full disk) leaves ``target`` as it was, or absent. ``target``
    is held open read-only meanwhile, so no campaign can write to it between the copy and
    the replacement.

    Parameters
    ----------
    target : str or os.PathLike
        Campaign database to merge into; created if missing. Its folder must exist.
    sources : sequence of str or os.PathLike
        Campaign databases to copy designs from (not modified), at least one.

    Returns
    -------
    list of dict
        Per source, as :meth:`CampaignStore.merge`: ``{"added", "replaced_failed", "kept"}``.

    Raises
    ------
    FileNotFoundError
        A source does not exist, or the folder of ``target`` does not.
    ValueError
        No source, a source that is ``target``, or a backend, pressure grid or
        settings that differ from another database's.
    SchemaError
        A source or ``target`` is not a readable campaign database (or a folder).
    OSError
        The merged database could not be written (naming ``target``).
    """
    target = Path(target)
    paths = [Path(source) for source in sources]
    if not paths:
        raise ValueError("The 'sources' of merge_campaigns must name at least one database.")
    if not target.parent.is_dir():
        raise FileNotFoundError(
            f"The folder of the campaign database {str(target)!r} does not exist."
        )
    for source in paths:
        if not source.is_file():
            raise missing_database(source)
        if target.exists() and os.path.samefile(source, target):
            raise ValueError(f"A campaign cannot be merged into itself: {str(source)!r}.")
    if _has_log(target):
        # Fold the target's write-ahead log (left by a process that was killed or ran out
        # of disk) into it first: the copy merged into would not carry it.
        with CampaignStore(target) as own, own._writing():
            own._con.execute("FORCE CHECKPOINT")
        if _has_log(target):
            raise OSError(errno.EIO, "its write-ahead log could not be folded in", str(target))
    held = CampaignStore(target, read_only=True) if target.exists() else None
    try:
        reference = None
        family: tuple[FamilySchema, Path] | None = None
        if held is not None:
            family = (held.family_schema, target)
        recorded: tuple[dict[str, Any], Path] | None = None
        unchecked: list[Path] = []  # databases of an older softbend, without settings
        if held is not None and held.backend is not None:
            # bind() writes the backend and the pressure grid together.
            reference = (held.backend, cast(np.ndarray, held.pressures_mpa), target)
            recorded = None if held.settings is None else (held.settings, target)
            if held.settings is None:
                unchecked.append(target)
        for source in paths:
            with CampaignStore(source, read_only=True) as other:
                backend, grid, settings = other.backend, other.pressures_mpa, other.settings
                if family is None:
                    family = (other.family_schema, source)
                _check_same_family((family[0].name, family[1]), (other.family, source))
            if backend is None or grid is None:
                continue  # a shard that never ran: nothing to merge
            if reference is None:
                reference = (backend, grid, source)
            else:
                _check_same_campaign(reference, (backend, grid, source))
            if settings is None:
                unchecked.append(source)
            elif recorded is None:
                recorded = (settings, source)
            else:
                _check_same_settings(recorded, (settings, source))
        if recorded is not None and unchecked:
            warnings.warn(
                f"The campaign database(s) {', '.join(repr(str(p)) for p in unchecked)} record "
                "no backend settings (an older softbend's, or bound without them): their "
                f"designs could not be checked against the settings of {str(recorded[1])!r}.",
                UncheckedSettingsWarning,
                stacklevel=2,
            )
        with warnings.catch_warnings():  # said above, naming the databases given
            warnings.simplefilter("ignore", UncheckedSettingsWarning)
            return _merge_staged(target, paths, held, None if family is None else family[0])
    finally:
        if held is not None:
            held.close()


def _check_same_campaign(
    first: tuple[str, np.ndarray, Path], other: tuple[str, np.ndarray, Path]
) -> None:
    """Refuse ``other`` unless it has the backend and pressure grid of ``first``.

    Each is ``(backend, pressures_mpa, path)``.
    """
    (backend, grid, path), (other_backend, other_grid, other_path) = first, other
    if other_backend != backend:
        raise ValueError(
            f"The backend of the campaign in {str(other_path)!r} is {other_backend!r}, that of "
            f"{str(path)!r} is {backend!r}; only campaigns of one backend and one pressure "
            "grid merge. Nothing was merged."
        )
    if not np.array_equal(other_grid, grid):
        raise ValueError(
            f"The 'pressures_mpa' of the campaign in {str(other_path)!r} are "
            f"{_describe_grid(other_grid)}, those of {str(path)!r} {_describe_grid(grid)}; "
            "only campaigns of one backend and one pressure grid merge. Nothing was merged."
        )


def _check_same_family(first: tuple[str, Path], other: tuple[str, Path]) -> None:
    """Refuse ``other`` unless it holds the family of ``first``; each is ``(family, path)``."""
    (family, path), (other_family, other_path) = first, other
    if other_family != family:
        raise ValueError(
            f"The campaign in {str(other_path)!r} holds designs of the {other_family!r} family, "
            f"that in {str(path)!r} of the {family!r} family; only campaigns of one family "
            "merge. Nothing was merged."
        )


def _check_same_settings(
    first: tuple[dict[str, Any], Path], other: tuple[dict[str, Any], Path]
) -> None:
    """Refuse ``other`` unless it has the settings of ``first``; each is ``(settings, path)``."""
    (settings, path), (other_settings, other_path) = first, other
    differences = settings_differences(settings, other_settings)
    if differences:
        shown = describe_differences(
            differences, recorded=f"in {str(path)!r}", given=f"in {str(other_path)!r}"
        )
        raise ValueError(
            f"The settings of the campaign in {str(other_path)!r} differ from those of "
            f"{str(path)!r}: {shown}; only shards run with the same settings merge: re-run "
            "that shard with them into a new database. Nothing was merged."
        )


def _merge_staged(
    target: Path, sources: list[Path], held: CampaignStore | None, family: FamilySchema | None
) -> list[dict[str, Any]]:
    """Merge ``sources`` into a copy of ``target`` beside it, then move it into place.

    A new ``target`` is created for ``family`` (that of the sources; paper B's if None).
    """
    staging = target.with_name(f".{target.name}.{uuid.uuid4().hex}.tmp")
    try:
        if held is not None:
            shutil.copyfile(target, staging)
            os.chmod(staging, new_file_mode(target))
        store = CampaignStore(staging, family=family)
        try:
            with store._writing(target):
                counts = [store.merge(source) for source in sources]
                # Into the file itself: closing would not report a checkpoint that fails,
                # and the write-ahead log beside the copy does not move with it.
                store._con.execute("FORCE CHECKPOINT")
        finally:
            with store._writing(target):
                store.close()
        if _has_log(staging):
            raise OSError(
                errno.EIO, "the merged database could not be written in full", str(target)
            )
        os.replace(staging, target)
    except OSError as exc:
        names = [n for n in (exc.filename, exc.filename2) if isinstance(n, str)]
        if str(staging) in names:  # name the file the caller asked for, not the copy
            raise OSError(exc.errno, exc.strerror, str(target)) from None
        raise
    finally:
        _remove_database(staging)
    return counts


def _has_log(path: Path) -> bool:
    """Whether DuckDB's write-ahead log beside ``path`` holds anything."""
    wal = path.with_name(path.name + ".wal")
    try:
        return wal.stat().st_size > 0
    except OSError:
        return False


def _close_quietly(con: DuckDBPyConnection) -> None:
    """Close a DuckDB connection that is being given up; its own error is not the news."""
    try:
        con.close()
    except Exception:
        logger.debug("closing a DuckDB connection that failed failed too", exc_info=True)


def _remove_database(path: Path) -> None:
    """Remove a database file that was made here and is being given up, and its log."""
    for leftover in (path, path.with_name(path.name + ".wal")):
        try:
            leftover.unlink(missing_ok=True)
        except OSError:
            logger.warning("could not remove %s", leftover)


def _sql_text(path: Path) -> str:
    """A path as the body of a single-quoted SQL string literal."""
    return str(path).replace("'", "''")


def _describe_grid(grid: np.ndarray | None) -> str:
    if grid is None:
        return "no recorded pressure grid"
    if len(grid) == 0:
        return "an empty grid"
    return f"{len(grid)} pressures from {grid[0]:g} to {grid[-1]:g} MPa"


def load_samples(db_path: str | os.PathLike[str]) -> pd.DataFrame:
    """Samples of the campaign database at ``db_path`` (see :meth:`CampaignStore.load_samples`)."""
    with CampaignStore(db_path, read_only=True) as store:
        return store.load_samples()


def load_designs(db_path: str | os.PathLike[str]) -> pd.DataFrame:
    """Designs table of the campaign database at ``db_path`` (done and failed)."""
    with CampaignStore(db_path, read_only=True) as store:
        return store.load_designs()


def campaign_actuator(db: str | os.PathLike[str]) -> Actuator:
    """The actuator of the campaign database ``db``.

    The description recorded with the family is read back; a database that
    records none (written before families were recorded) takes the registered
    family's.
    """
    from softbend.actuators import Actuator

    with CampaignStore(db, read_only=True) as store:
        schema = store.family_schema
    if schema.actuator is not None:
        return Actuator.from_dict(json.loads(json.dumps(schema.actuator)))
    from softbend.fem.families import get_family

    return get_family(schema.name).actuator
