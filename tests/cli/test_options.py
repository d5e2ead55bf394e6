"""The command line names the option behind a library error's key (softbend.cli._options)."""

from __future__ import annotations

import typer

from softbend.cli._options import ALIASES, error_text, option_for
from softbend.errors import InputError, keyed

app = typer.Typer()
group = typer.Typer()
app.add_typer(group, name="campaign")


@group.command("run")
def _run(
    table: str = typer.Argument(...),
    design: str = typer.Option("", "--design", "-d"),
    range_: list[str] = typer.Option([], "--range"),
) -> None:
    """A command with an argument and two options."""


@app.command("other")
def _other(seed: int = typer.Option(0, "--seed")) -> None:
    """Another command."""


def test_a_key_names_the_option_of_the_running_command() -> None:
    argv = ["campaign", "run", "t.csv", "--design", "x"]
    assert option_for(app, argv, "design") == "--design"
    assert option_for(app, argv, "table") == "TABLE"
    assert option_for(app, ["other"], "design") is None  # that command has no --design


def test_an_alias_maps_a_library_key_to_the_parameter_name() -> None:
    ALIASES["campaign run:ranges"] = "range_"
    try:
        assert option_for(app, ["campaign", "run", "t"], "ranges") == "--range"
    finally:
        del ALIASES["campaign run:ranges"]


def test_the_printed_line_leads_with_the_option_and_keeps_the_place() -> None:
    error = InputError("must be a number in (0, inf); got -2.0", key="design")
    argv = ["campaign", "run", "t.csv"]
    assert error_text(app, argv, error) == "--design: must be a number in (0, inf); got -2.0"
    located = InputError("must be a number", key="gain", file="rig.toml", line=3, column=7)
    assert error_text(app, argv, located) == "rig.toml:3:7: gain: must be a number"
    assert str(located) == "rig.toml:3:7: gain: must be a number"
    assert error_text(app, ["nothing"], error) == str(error) == "design: " + error.detail


def test_keyed_names_the_callers_parameter_outermost_first() -> None:
    try:
        with keyed("fix"), keyed("design"):
            raise InputError("must be in [100, 160]; got 200", key="l_mm")
    except InputError as error:
        assert error.key == "fix" and error.inner_key == "l_mm"
        assert str(error) == "fix: l_mm: must be in [100, 160]; got 200"
        assert error_text(app, ["campaign", "run", "t"], error) == str(error)
    try:
        with keyed("design"):
            raise InputError("must be a number", key="design")
    except InputError as error:  # the same key: nothing moves
        assert str(error) == "design: must be a number"
