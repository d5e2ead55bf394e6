"""The one place where the command line names the option behind a library key.

Library errors carry the key of the input at fault (the library parameter's name,
see :mod:`softbend.errors`); the command line prints the option the user typed
instead. A key names the option of the running command whose parameter has the
same name (``design`` → ``--design``, ``table`` → ``TABLE``); :data:`ALIASES`
lists the keys whose library name differs from the command's parameter, in
general or for one command.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import typer

from softbend.errors import SoftbendError

__all__ = ["ALIASES", "error_text", "option_for"]

#: Library key -> command-line parameter name, where they differ. A key may be
#: given for one command only as ``"command path:key"`` (``"design find:fixes"``).
ALIASES: dict[str, str] = {
    "design find:fixes": "fix",
    "design find:steps": "resolution",
    "design find:step": "resolution",
    "reproduce:out_dir": "out",
    "campaign run:connect_timeout_s": "connect_timeout",
    "maxh_mm": "maxh",
    "pmax_mpa": "pmax",
    "step_mpa": "pstep",
    "lab measure:actuators": "designs",
    "lab measure:fabrication_error_mm": "fabrication_error",
    "lab measure:camera_noise_deg": "camera_noise",
    "lab measure:pmax_mpa": "pmax",
    "lab measure:pressure_step_mpa": "pstep",
    "lab measure:max_angle_deg": "max_angle",
    "transfer refine:X": "measurements",
    "transfer loco:X": "measurements",
    "transfer loco:calibrated": "calibrate",
    "analyze:mape_threshold": "mape_threshold_deg",
    "analyze:samples": "db",
    "curling simulate:n_samples": "samples",
    "curling simulate:dt_s": "dt",
    "curling simulate:n_experiments": "experiments",
    "curling identify:C": "c",
}


def _command(app: typer.Typer, argv: Sequence[str]) -> tuple[Any, str] | None:
    """The command that ``argv`` runs and its path (``"campaign run"``), if one resolves.

    Typer's click commands are duck-typed: a group is what has ``commands``.
    """
    command: Any = typer.main.get_command(app)
    path: list[str] = []
    words = iter(argv)
    while hasattr(command, "commands"):
        word = next((w for w in words if not w.startswith("-")), None)
        found = command.commands.get(word) if word is not None else None
        if found is None:
            return None
        command = found
        path.append(str(word))
    return command, " ".join(path)


def option_for(app: typer.Typer, argv: Sequence[str], key: str) -> str | None:
    """The option (``--design``) or argument (``TABLE``) of the command that ``key`` names."""
    resolved = _command(app, argv)
    if resolved is None:
        return None
    command, path = resolved
    name = ALIASES.get(f"{path}:{key}", ALIASES.get(key, key)).replace("-", "_")
    for parameter in command.params:
        if parameter.name != name:
            continue
        if parameter.param_type_name == "argument":
            return str(parameter.metavar or parameter.name).upper()
        longs = [o for o in parameter.opts if o.startswith("--")]
        return (longs or parameter.opts)[0]
    return None


def error_text(app: typer.Typer, argv: Sequence[str], error: BaseException) -> str:
    """The one line printed for ``error``: its key replaced by the option the user typed.

    An error located in a file keeps its key: there it names the file's field.
    """
    if not isinstance(error, SoftbendError) or error.key is None or error.file is not None:
        return str(error)  # a key inside a file is the file's own name for the field
    option = option_for(app, argv, error.key)
    return error.described(option) if option is not None else str(error)
