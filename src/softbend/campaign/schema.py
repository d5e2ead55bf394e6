"""The layout of a campaign database and the checks of a file before it is used.

Tables (schema version :data:`SCHEMA_VERSION`):

``meta(key, value)``
    ``schema_version``, ``softbend_version`` and ``created_at`` (set on creation),
    ``backend`` and ``pressures_mpa`` (JSON list; set by the first run and checked
    by every later one, so a resumed campaign cannot mix models or grids),
    ``settings`` (JSON object: the backend's settings that change the numbers,
    mesh size, FEM options and material among them, see
    :mod:`softbend.campaign.settings`; set by the first run, checked by later
    ones, absent in databases of older softbend versions), ``runs`` (JSON list
    of each run's record), ``space`` and ``n_designs_planned`` (of the latest run),
    ``family`` (the FEM family's name) and ``actuator`` (its
    :meth:`~softbend.actuators.Actuator.to_dict` as JSON), set on creation
    (absent for a family that is not recorded: paper B's, whose databases
    predate families; see :mod:`softbend.campaign.family_schema`).
``designs``
    One row per attempted design: its parameters (those of its family, in its
    units: ``l_mm`` ... ``lc_mm`` for paper B's),
    ``status`` ``'done'`` or ``'failed'``, ``error`` (``"ExceptionType: message"``
    for failed designs), ``wall_time_s``, ``n_samples`` (rows in ``samples``,
    including the final non-converged pressure), ``max_pressure_mpa`` and
    ``max_angle_deg`` (over converged pressures), ``newton_iterations_total``,
    ``mesh_size``, ``backend``, ``softbend_version``, ``schema_version``,
    ``finished_at`` (UTC) and ``stats`` (backend details as JSON).
``samples``
    One row per applied pressure of a done design: ``pressure_mpa``,
    ``angle_deg``, ``tip_x_mm``, ``tip_z_mm`` (NULL where not converged),
    ``converged``, ``newton_iterations``; primary key ``(design_id, pressure_mpa)``.

:func:`ensure_schema` creates these tables in a new file and checks those of an
existing one (a softbend campaign, of a version this softbend reads);
:func:`check_duckdb_file` refuses an existing file that is no DuckDB database
(empty, a CSV) before DuckDB opens it; :func:`check_complete` reads every block
of an existing file once, so a truncated or damaged file is refused on opening
rather than on a later query; :func:`open_error`, :func:`missing_database`,
:func:`not_a_database` and :func:`unreadable` turn DuckDB's errors (and a file
that is not there) into one line naming the file, and :func:`write_error` a
failed write (a full disk) into the :class:`OSError` it is. The queries and
writes live in :mod:`softbend.campaign.store`.
"""

from __future__ import annotations

import errno
import json
import logging
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

from softbend._interrupts import interrupts_deferred
from softbend.campaign.family_schema import FamilySchema
from softbend.design import PARAMETERS
from softbend.errors import SchemaError, SoftbendError

if TYPE_CHECKING:
    from duckdb import DuckDBPyConnection

__all__ = [
    "DESIGN_COLUMNS",
    "SAMPLE_COLUMNS",
    "SCHEMA_VERSION",
    "check_complete",
    "check_duckdb_file",
    "design_columns",
    "ensure_schema",
    "first_line",
    "missing_database",
    "not_a_database",
    "open_error",
    "quoted",
    "read_family",
    "sample_columns",
    "softbend_version",
    "transaction",
    "unreadable",
    "utc_now",
    "write_error",
]

logger = logging.getLogger(__name__)

#: Version of the table layout written by this softbend. A database with a newer
#: version is refused with :class:`~softbend.errors.SchemaError`.
SCHEMA_VERSION = 1

#: Columns of :meth:`CampaignStore.load_samples`.
SAMPLE_COLUMNS: tuple[str, ...] = (
    "design_id",
    *PARAMETERS,
    "pressure_mpa",
    "angle_deg",
    "tip_x_mm",
    "tip_z_mm",
    "converged",
)

#: Columns of the ``designs`` table, in the order of its definition.
DESIGN_COLUMNS: tuple[str, ...] = (
    "design_id",
    *PARAMETERS,
    "status",
    "error",
    "wall_time_s",
    "n_samples",
    "max_pressure_mpa",
    "max_angle_deg",
    "newton_iterations_total",
    "mesh_size",
    "backend",
    "softbend_version",
    "schema_version",
    "finished_at",
    "stats",
)


def design_columns(parameters: tuple[str, ...] = tuple(PARAMETERS)) -> tuple[str, ...]:
    """Columns of the ``designs`` table of a campaign whose designs have ``parameters``."""
    return ("design_id", *parameters, *DESIGN_COLUMNS[1 + len(PARAMETERS) :])


def sample_columns(parameters: tuple[str, ...] = tuple(PARAMETERS)) -> tuple[str, ...]:
    """Columns of the samples (joined with the designs) of a campaign of ``parameters``."""
    return ("design_id", *parameters, *SAMPLE_COLUMNS[1 + len(PARAMETERS) :])


def quoted(name: str) -> str:
    """A column name as a quoted SQL identifier."""
    return '"{}"'.format(name.replace('"', '""'))


_DDL = (
    """
    CREATE TABLE IF NOT EXISTS meta (
        key VARCHAR PRIMARY KEY,
        value VARCHAR NOT NULL
    )
    """,
    """
    CREATE TABLE IF NOT EXISTS designs (
        design_id VARCHAR PRIMARY KEY,
        l_mm DOUBLE NOT NULL,
        r_mm DOUBLE NOT NULL,
        t_mm DOUBLE NOT NULL,
        b_mm DOUBLE NOT NULL,
        phi_deg DOUBLE NOT NULL,
        lc_mm DOUBLE NOT NULL,
        status VARCHAR NOT NULL CHECK (status IN ('done', 'failed')),
        error VARCHAR,
        wall_time_s DOUBLE,
        n_samples INTEGER NOT NULL,
        max_pressure_mpa DOUBLE,
        max_angle_deg DOUBLE,
        newton_iterations_total BIGINT,
        mesh_size BIGINT,
        backend VARCHAR NOT NULL,
        softbend_version VARCHAR NOT NULL,
        schema_version INTEGER NOT NULL,
        finished_at TIMESTAMP NOT NULL,
        stats VARCHAR
    )
    """,
    """
    CREATE TABLE IF NOT EXISTS samples (
        design_id VARCHAR NOT NULL,
        pressure_mpa DOUBLE NOT NULL,
        angle_deg DOUBLE,
        tip_x_mm DOUBLE,
        tip_z_mm DOUBLE,
        converged BOOLEAN NOT NULL,
        newton_iterations INTEGER,
        PRIMARY KEY (design_id, pressure_mpa)
    )
    """,
)

#: Bytes before the first block of a DuckDB file: its main header and two database headers.
_DUCKDB_HEADER_BYTES = 3 * 4096

#: Where a DuckDB file's main header holds its magic bytes (after an 8-byte checksum).
_DUCKDB_MAGIC_OFFSET, _DUCKDB_MAGIC = 8, b"DUCK"

#: What a campaign database is, said after a file that is none.
_WHAT_A_CAMPAIGN_IS = (
    "a campaign database is the DuckDB file that 'softbend campaign run' or "
    "'softbend campaign merge' writes"
)


def softbend_version() -> str:
    """The version of softbend stamped on the database and on every design row."""
    from softbend import __version__

    return __version__


def utc_now() -> datetime:
    """The current UTC time without a time zone, as DuckDB's ``TIMESTAMP`` stores it."""
    return datetime.now(UTC).replace(tzinfo=None)


@contextmanager
def transaction(con: DuckDBPyConnection) -> Iterator[None]:
    """Run the body in one transaction of the DuckDB connection ``con``.

    Committed when the body returns, rolled back when it raises. A Ctrl-C
    meanwhile is held back until the commit (it would otherwise interrupt the
    query and roll back finished work), then raised as ``KeyboardInterrupt``.
    """
    with interrupts_deferred():
        con.execute("BEGIN TRANSACTION")
        try:
            yield
        except BaseException:
            try:
                con.execute("ROLLBACK")
            except Exception:  # a failed write may have ended the transaction: report it
                logger.debug("ROLLBACK after a failed transaction failed too", exc_info=True)
            raise
        con.execute("COMMIT")


# -- creating a database or checking an existing one -------------------------------


def ensure_schema(
    con: DuckDBPyConnection, path: Path, *, read_only: bool, family: FamilySchema | None = None
) -> None:
    """Create the tables of a new campaign database, or check those of an existing one.

    Parameters
    ----------
    con : duckdb.DuckDBPyConnection
        Open connection to the file.
    path : pathlib.Path
        The file, for messages.
    read_only : bool
        The connection is read-only: a file without tables is refused rather
        than created.
    family : FamilySchema, optional
        The family of a new database's designs (default
        :data:`~softbend.fem.families.FIRST_FAMILY`); its
        ``designs`` table gets the family's parameter columns and its ``meta``
        table the family's name and actuator.

    Raises
    ------
    SchemaError
        Tables but no ``meta`` table (not a softbend campaign), no tables and
        ``read_only``, an unknown or newer schema version, or a missing
        ``designs`` or ``samples`` table.
    """
    tables = {
        row[0]
        for row in con.execute(
            "SELECT table_name FROM information_schema.tables WHERE table_schema = 'main'"
        ).fetchall()
    }
    if "meta" not in tables:
        if tables or read_only:
            found = ", ".join(sorted(tables)) or "no tables"
            raise SchemaError(
                f"{str(path)!r} is not a softbend campaign database "
                f"(no 'meta' table; found {found}; {_WHAT_A_CAMPAIGN_IS})."
            )
        _create(con, path, family or FamilySchema.of(None))
        return
    meta = dict(con.execute("SELECT key, value FROM meta").fetchall())
    version_text = meta.get("schema_version")
    try:
        version = int(version_text) if version_text is not None else None
    except ValueError:
        version = None
    if version is None or version < 1:
        raise SchemaError(
            f"The campaign database {str(path)!r} has an unknown schema version "
            f"{version_text!r}; this softbend reads version {SCHEMA_VERSION}."
        )
    if version > SCHEMA_VERSION:
        raise SchemaError(
            f"The campaign database {str(path)!r} has schema version {version}, newer "
            f"than this softbend supports ({SCHEMA_VERSION}); upgrade softbend to read it."
        )
    missing = {"designs", "samples"} - tables
    if missing:
        raise SchemaError(
            f"The campaign database {str(path)!r} lacks the table(s) {', '.join(sorted(missing))}."
        )


def _create(con: DuckDBPyConnection, path: Path, family: FamilySchema) -> None:
    with transaction(con):
        for statement in _DDL:
            con.execute(_family_ddl(statement, family.parameters))
        for key, value in (
            ("schema_version", str(SCHEMA_VERSION)),
            ("softbend_version", softbend_version()),
            ("created_at", utc_now().isoformat(timespec="seconds") + "Z"),
        ):
            con.execute("INSERT INTO meta VALUES (?, ?)", [key, value])
        if family.actuator is not None:  # recorded with its description
            con.execute("INSERT INTO meta VALUES ('family', ?)", [family.name])
            actuator = json.dumps(family.actuator, sort_keys=True)
            con.execute("INSERT INTO meta VALUES ('actuator', ?)", [actuator])
    logger.info("created campaign database %s (schema %d)", path, SCHEMA_VERSION)


def _family_ddl(statement: str, parameters: tuple[str, ...]) -> str:
    """A table's definition with the family's ``parameters`` as the ``designs`` table's
    design columns (in place of those written in :data:`_DDL`); other tables as written."""
    if "designs (" not in statement:
        return statement
    own = "".join(f"{quoted(name)} DOUBLE NOT NULL,\n        " for name in parameters)
    start = statement.index("l_mm DOUBLE")
    end = statement.index("status VARCHAR")
    return statement[:start] + own + statement[end:]


def read_family(con: DuckDBPyConnection, path: Path) -> FamilySchema:
    """The family of an open campaign database: paper B's where its ``meta`` names none.

    The parameter columns are read from the ``designs`` table itself (those
    between ``design_id`` and ``status``).

    Raises
    ------
    SchemaError
        A damaged ``actuator`` entry (not a JSON object) or a ``designs`` table
        without ``design_id`` and ``status``.
    """
    meta = dict(
        con.execute("SELECT key, value FROM meta WHERE key IN ('family', 'actuator')").fetchall()
    )
    columns = [
        row[0]
        for row in con.execute(
            "SELECT column_name FROM information_schema.columns WHERE table_schema = 'main' "
            "AND table_name = 'designs' ORDER BY ordinal_position"
        ).fetchall()
    ]
    if "design_id" not in columns or "status" not in columns:
        raise SchemaError(
            f"The campaign database {str(path)!r} has a damaged 'designs' table (no design_id "
            "or status column)."
        )
    parameters = tuple(columns[columns.index("design_id") + 1 : columns.index("status")])
    from softbend.fem.families import FIRST_FAMILY

    name = meta.get("family", FIRST_FAMILY)
    actuator = None
    if "actuator" in meta:
        try:
            actuator = json.loads(meta["actuator"])
        except (ValueError, RecursionError):
            actuator = None
        if not isinstance(actuator, dict):
            raise SchemaError(
                f"The campaign database {str(path)!r} has a damaged 'actuator' in its 'meta' "
                f"table: it must be a JSON object. Got {meta['actuator'][:80]!r}."
            )
    return FamilySchema(name, parameters, actuator)


def check_complete(con: DuckDBPyConnection, path: Path) -> None:
    """Raise unless the file holds every block of the database, each one readable.

    DuckDB reads a block only when a query needs it, so a truncated or partly
    overwritten file opens and then fails on some later query. Here the file must
    be long enough for its headers and all blocks in use (DuckDB cuts trailing
    free blocks off), and every table is read once in full, which loads and
    checksums each of its blocks (a fraction of a second for millions of samples).
    A DuckDB error raised here is turned into one line by the caller.
    """
    size = path.stat().st_size
    row = con.execute(
        "SELECT block_size, total_blocks, free_blocks FROM pragma_database_size()"
    ).fetchone()
    assert row is not None  # the pragma answers one row for the open database
    block_size, total, free = row
    needed = _DUCKDB_HEADER_BYTES + block_size * (total - free)
    if size < needed:
        raise unreadable(path, f"truncated: {size} bytes, its blocks in use need {needed}")
    tables = con.execute(
        "SELECT schema_name, table_name FROM duckdb_tables() "
        "WHERE database_name = current_database() AND NOT temporary"
    ).fetchall()
    for schema, table in tables:
        name = '"{}"."{}"'.format(schema.replace('"', '""'), table.replace('"', '""'))
        con.execute(f"SELECT max(hash(COLUMNS(*))) FROM {name}").fetchall()


def check_duckdb_file(path: Path) -> None:
    """Raise unless the existing file ``path`` begins as a DuckDB database file does.

    Checked before DuckDB opens it: DuckDB would open a file that is not one of
    its databases, but has a suffix it reads (``.csv``, ``.parquet``, ``.json``),
    as an empty in-memory database, and then fail with an error about that
    database rather than the file.

    Raises
    ------
    SchemaError
        The file is empty or not a DuckDB database file; one line naming the
        file and what a campaign database is.
    """
    with open(path, "rb") as handle:
        head = handle.read(_DUCKDB_MAGIC_OFFSET + len(_DUCKDB_MAGIC))
    if not head:
        raise not_a_database(path, "an empty file")
    if head[_DUCKDB_MAGIC_OFFSET:] != _DUCKDB_MAGIC:
        raise not_a_database(path)


# -- one line per error of opening -------------------------------------------------


def first_line(exc: Exception, limit: int = 200) -> str:
    """The first line of an error's message, at most ``limit`` characters."""
    lines = str(exc).strip().splitlines()
    text = lines[0] if lines else type(exc).__name__
    return text if len(text) <= limit else text[: limit - 3] + "..."


def unreadable(path: Path, reason: str) -> SchemaError:
    """The error of a file that is not a readable campaign database, and why."""
    return SchemaError(
        f"{str(path)!r} is not a readable softbend campaign database ({reason.rstrip('.!')})."
    )


def not_a_database(path: Path, what: str = "not a DuckDB database file") -> SchemaError:
    """The error of a file that is no DuckDB database at all (``what`` it is), and what to give."""
    return unreadable(path, f"{what}; {_WHAT_A_CAMPAIGN_IS}")


def missing_database(path: Path) -> SchemaError | FileNotFoundError:
    """The error of a campaign database that is not there: a folder in its place, or nothing."""
    if path.is_dir():
        return SchemaError(
            f"{str(path)!r} is a folder, not a softbend campaign database ({_WHAT_A_CAMPAIGN_IS})."
        )
    return FileNotFoundError(f"No campaign database at {str(path)!r}.")


def open_error(path: Path, exc: Exception) -> SoftbendError:
    """The one-line error for a DuckDB error raised while connecting to ``path``."""
    text = str(exc)
    if re.search(r"\block\b", text, re.IGNORECASE):  # a lock, not a "block"
        return SoftbendError(
            f"The campaign database {str(path)!r} is in use by another process (a running "
            "campaign?); DuckDB allows one writer and no reader meanwhile."
        )
    if "different configuration" in text:
        return SoftbendError(
            f"The campaign database {str(path)!r} is already open in this process in another "
            "mode; close that CampaignStore first."
        )
    if "not a valid DuckDB database" in text or "in-memory database" in text:
        # The second: a file DuckDB took for data to read into a database of its own.
        return not_a_database(path)
    return unreadable(path, first_line(exc))


#: OS errors of a write that failed for lack of room or of permission, by their text.
_WRITE_ERRNOS = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM)
_COULD_NOT_WRITE = re.compile(
    r'Could not write(?: to)? file "(?P<file>[^"]*)": (?P<reason>[^"\n]*)'
)


def write_error(exc: Exception, path: str | os.PathLike[str]) -> OSError | None:
    """The :class:`OSError` of a DuckDB error raised by a failed write to ``path``, or None.

    DuckDB reports a full disk (or a file-size limit, a read-only folder) as its
    own ``IOException`` or, on commit, ``TransactionException``, whose text holds
    the OS error (``Could not write file "…": No space left on device``,
    sometimes with ``"errno":"28"``). The result names ``path`` (the file the
    caller writes, not DuckDB's write-ahead log beside it), so a command's
    :func:`~softbend.cli._common.output_errors` turns it into one line.
    """
    text = str(exc)
    number = None
    found = re.search(r'"errno"\s*:\s*"?(\d+)', text)
    if found is not None:
        number = int(found[1])
    written = _COULD_NOT_WRITE.search(text.replace('\\"', '"'))
    if number is None and written is not None:
        reason = written["reason"].strip().rstrip(".")
        number = next((n for n in _WRITE_ERRNOS if os.strerror(n) == reason), None)
        if number is None:
            return OSError(errno.EIO, reason or "write failed", os.fspath(path))
    if number is None or (written is None and number not in _WRITE_ERRNOS):
        return None
    return OSError(number, os.strerror(number), os.fspath(path))
