"""The ``softbend`` command line.

One module per subcommand; each parses its arguments, calls one library
function and prints. :func:`main` runs the app in-process and returns the exit
code, so tests call ``main([...])`` directly.

Exit codes: 0 success, 1 unexpected failure, 2 bad input (usage errors and any
:class:`softbend.errors.SoftbendError` or ``ValueError``), printed as one line,
130 interrupted (Ctrl-C): one line, naming where the finished work is kept and the
command that resumes from it (:func:`resume_path`).
"""

from __future__ import annotations

import functools
import glob
import os
import shlex
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import typer

from softbend.cli import _common, _options, _outputs

app = typer.Typer(
    name="softbend",
    help="Design, simulate, learn and control soft pneumatic bending actuators.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


def _register() -> None:
    # Imported here so that ``import softbend.cli`` stays cheap and each
    # subcommand module owns its own imports.
    from softbend.cli import (
        analyze,
        campaign,
        control,
        curling,
        design,
        fem,
        identify,
        materials,
        reproduce,
        train,
        transfer,
    )

    app.add_typer(curling.app, name="curling")
    app.add_typer(campaign.app, name="campaign")
    app.add_typer(materials.app, name="materials")
    app.add_typer(fem.app, name="fem")
    app.add_typer(transfer.lab_app, name="lab")
    app.add_typer(transfer.app, name="transfer")
    app.add_typer(control.app, name="control")
    app.add_typer(design.app, name="design")
    app.command("analyze")(analyze.analyze)
    app.command("train")(train.train)
    app.command("predict")(train.predict)
    app.command("reproduce")(reproduce.reproduce)
    app.command("identify")(identify.identify)


_register()


@app.callback()
def _root(
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Log progress details to stderr."),
) -> None:
    """Design, simulate, learn and control soft pneumatic bending actuators."""
    _common.configure_logging(verbose)


#: Exit code of a command stopped by Ctrl-C (128 + SIGINT, as a shell reports it).
INTERRUPTED = 130


def _option(args: Sequence[str], *names: str) -> str | None:
    """The value of the last of the options ``names`` in ``args`` (``--out X``, ``--out=X``)."""
    value = None
    for i, arg in enumerate(args):
        for name in names:
            if arg == name and i + 1 < len(args):
                value = args[i + 1]
            elif name.startswith("--") and arg.startswith(name + "="):
                value = arg[len(name) + 1 :]
    return value


def _positionals(args: Sequence[str]) -> list[str]:
    """The words of ``args`` that are not options (nor, roughly, their values)."""
    return [a for a in args if not a.startswith("-")]


def resume_path(args: Sequence[str]) -> Path | None:
    """Where a resumable command keeps its finished work, if it exists, else None.

    ``softbend train`` keeps every finished configuration-fold in a checkpoint
    beside ``--out``; ``softbend campaign run`` records every finished design in its
    database; ``softbend reproduce`` keeps its campaign database beside ``--out``,
    and ``softbend design find --verify`` the campaign of its verification
    (the latest one, :func:`softbend.cli.design.verification_db`). Each resumes
    when the same command is run again.
    """
    words = _positionals(args)
    path: Path | None = None
    if words[:1] == ["train"]:
        out = _option(args, "--out", "-o")
        if out is not None:
            path = Path(os.path.abspath(out))
            path = path.with_name(f".{path.name}.train-checkpoint.jsonl")
    elif words[:2] == ["campaign", "run"] and len(words) > 2:
        path = Path(words[2])
    elif words[:2] == ["design", "find"] and _option(args, "--out", "-o") is not None:
        folder = Path(os.path.abspath(_option(args, "--out", "-o") or ""))
        pattern = f".{glob.escape(folder.name)}.verify-*.duckdb"
        kept = sorted(folder.parent.glob(pattern), key=lambda p: p.stat().st_mtime)
        path = kept[-1] if kept else None
    elif words[:1] == ["reproduce"]:
        folder = Path(_option(args, "--out", "-o") or "results/reproduce")
        path = folder.with_name(f".{folder.name}.resume")
        if not path.exists():
            path = folder / "paper_b" / "campaign.duckdb" if folder.is_dir() else None
    return path if path is not None and path.exists() else None


def interrupted_line(args: Sequence[str]) -> str:
    """The one line printed when Ctrl-C stops the command ``args``.

    Where finished work is kept, the line names it and the command that resumes
    from it (``args`` as typed, quoted for a shell).
    """
    kept = resume_path(args)
    if kept is None:
        return "softbend: interrupted"
    return (
        f"softbend: interrupted; finished work is kept in {kept}; resume with: "
        f"softbend {shlex.join(args)}"
    )


#: Whether Ctrl-C reached :func:`main` through a command (set by :func:`_noting_interrupts`).
_CTRL_C = {"seen": False}

#: What DuckDB raises (a ``RuntimeError``) when a Ctrl-C reaches it inside a query.
_DUCKDB_INTERRUPTED = "Query interrupted"


def _noting_interrupts(callback: Callable[..., Any]) -> Callable[..., Any]:
    """``callback`` noting a Ctrl-C it lets through (typer turns it into exit code 130).

    A command that handles Ctrl-C itself (says what it kept, exits 130) lets none
    through, so :func:`main` adds no second line.
    """

    @functools.wraps(callback)
    def run(*args: Any, **kwargs: Any) -> Any:
        try:
            return callback(*args, **kwargs)
        except KeyboardInterrupt:
            _CTRL_C["seen"] = True
            raise
        except RuntimeError as exc:
            if str(exc) != _DUCKDB_INTERRUPTED:
                raise
            _CTRL_C["seen"] = True  # a Ctrl-C inside a DuckDB query (a read: writes defer it)
            raise KeyboardInterrupt from exc

    run._softbend_noting = True  # type: ignore[attr-defined]
    return run


def _commands(typer_app: typer.Typer, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """Every registered command of ``typer_app`` and its sub-apps, with its name (``fem run``)."""
    for command in typer_app.registered_commands:
        callback = command.callback
        name = command.name or (callback.__name__.replace("_", "-") if callback else "")
        yield f"{prefix}{name}", command
    for group in typer_app.registered_groups:
        if group.typer_instance is not None:
            yield from _commands(group.typer_instance, f"{prefix}{group.name} ")


def _note_interrupts() -> None:
    for name, command in _commands(app):
        callback = command.callback
        if callback is not None and not getattr(callback, "_softbend_noting", False):
            command.callback = _noting_interrupts(_outputs.running_as(name, callback))


def _interrupted(args: Sequence[str]) -> int:
    _common.err_console.print(interrupted_line(args), markup=False, highlight=False, soft_wrap=True)
    return INTERRUPTED


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``) and return the exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    _note_interrupts()
    _CTRL_C["seen"] = False
    try:
        with _common.warnings_as_lines():
            result = app(args=args, prog_name="softbend", standalone_mode=False)
    except KeyboardInterrupt:
        return _interrupted(args)
    except typer.Exit as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # typer's word for Ctrl-C
            return _interrupted(args)
        return int(exc.exit_code)
    except typer.Abort as exc:
        if isinstance(exc.__context__, KeyboardInterrupt):  # click's word for Ctrl-C
            return _interrupted(args)
        _common.error_line("aborted")
        return 1
    except typer.TyperException as exc:  # usage errors: unknown option, bad value
        ctx = getattr(exc, "ctx", None)
        where = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
        message = exc.format_message() if hasattr(exc, "format_message") else str(exc)
        _common.error_line(message + where)
        return int(getattr(exc, "exit_code", 2))
    except (ValueError, FileNotFoundError, NotADirectoryError, PermissionError) as exc:
        # SoftbendError input errors derive from ValueError; their key names the option.
        if isinstance(exc, OSError) and not isinstance(exc, _common.SoftbendError):
            _common.error_line(_common.os_error_message(exc))
        else:
            _common.error_line(_options.error_text(app, args, exc))
        return 2
    except _common.SoftbendError as exc:
        _common.error_line(_options.error_text(app, args, exc))
        return 2
    except OSError as exc:  # last resort: an OS error no command named an option for
        _common.error_line(_common.os_error_message(exc))
        return 1
    if result == INTERRUPTED and _CTRL_C["seen"]:  # typer returns Ctrl-C as exit code 130
        return _interrupted(args)
    return int(result) if isinstance(result, int) else 0


def run() -> None:  # pragma: no cover - console-script shim
    """Console-script entry point.

    Once Ctrl-C has stopped the command, a second one while the process exits
    (its worker processes ended, its staging folder removed) is ignored: the one
    line stays the only output.
    """
    try:
        code = main()
    except KeyboardInterrupt:  # a second Ctrl-C while the first one was being reported
        code = INTERRUPTED
    if code == INTERRUPTED:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.exit(code)
