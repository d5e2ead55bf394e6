"""The extension examples of docs/extending.md run as written and register what they say."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[1] / "docs" / "extending.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S)


@pytest.mark.parametrize(
    ("registry", "name"),
    [
        ("softbend.control:CONTROLLERS", "hold"),
        ("softbend.transfer:STRATEGIES", "shifted"),
        ("softbend.surrogates.families:FAMILIES", "toy-linear"),
        ("softbend.actuators:ACTUATORS", "bellows"),
    ],
)
def test_each_example_is_one_class_and_one_register_line(registry, name):
    import importlib

    module, attribute = registry.split(":")
    table = getattr(importlib.import_module(module), attribute)
    (block,) = [b for b in _blocks() if f'"{name}"' in b]
    assert block.count(".register(") == 1
    try:
        exec(compile(block, str(PAGE), "exec"), {"__name__": "extending_example"})
        assert name in table
    finally:
        if name in table:
            table.unregister(name)


def test_the_declared_range_of_the_controller_example_is_checked_once_before_any_work():
    from softbend.control import CONTROLLERS
    from softbend.control.factory import controller_parameters

    (block,) = [b for b in _blocks() if '"hold"' in b]
    exec(compile(block, str(PAGE), "exec"), {"__name__": "extending_example"})
    try:
        assert controller_parameters("hold", {"limit": "0.05"}, from_text=True)["limit"] == 0.05
        with pytest.raises(ValueError, match=r"limit: must be in \[0, 0.5\] MPa; got '5'"):
            controller_parameters("hold", {"limit": "5"}, from_text=True)
    finally:
        CONTROLLERS.unregister("hold")
