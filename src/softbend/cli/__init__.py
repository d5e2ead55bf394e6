"""The ``softbend`` command line.

One module per subcommand; each parses its arguments, calls one library
function and prints. :func:`main` runs the app in-process and returns the exit
code, so tests call ``main([...])`` directly.

Exit codes: 0 success, 1 unexpected failure, 2 bad input (usage errors and any
:class:`softbend.errors.SoftbendError` or ``ValueError``), printed as one line.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

import typer

from softbend.cli import _common, _options

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


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``) and return the exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    try:
        with _common.warnings_as_lines():
            result = app(args=args, prog_name="softbend", standalone_mode=False)
    except typer.Exit as exc:
        return int(exc.exit_code)
    except typer.Abort:
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
    return int(result) if isinstance(result, int) else 0


def run() -> None:  # pragma: no cover - console-script shim
    """Console-script entry point."""
    sys.exit(main())
