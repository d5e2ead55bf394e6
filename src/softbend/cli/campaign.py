"""``softbend campaign``: run, inspect and export design campaigns."""

from __future__ import annotations

import typer

app = typer.Typer(help="Run FEM or analytical sweeps over a design space.", no_args_is_help=True)
