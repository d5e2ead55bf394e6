"""``softbend curling``: the curling actuator of paper A (simulate, identify)."""

from __future__ import annotations

import typer

app = typer.Typer(help="Curling actuator (paper A): synthetic data and NARX identification.", no_args_is_help=True)
