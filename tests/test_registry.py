"""The registry behind every named extension point."""

from __future__ import annotations

import pytest

from softbend.errors import SoftbendError
from softbend.registry import Registry, UnknownNameError


def test_register_get_and_order():
    reg: Registry[int] = Registry("controller")
    reg.register("b", 2)
    reg.register("a", 1)
    assert reg.get("a") == 1
    assert reg.names() == ("b", "a")
    assert "a" in reg and "c" not in reg
    assert list(reg) == ["b", "a"] and len(reg) == 2


def test_unknown_name_lists_known_names_and_the_caller_keys_it():
    from softbend.errors import keyed

    reg: Registry[int] = Registry("controller")
    reg.register("bang-bang", 1)
    reg.register("pressure-pi", 2)
    with pytest.raises(UnknownNameError) as info, keyed("controller"):
        reg.get("bangbang")
    message = str(info.value)
    assert message.startswith("controller: Unknown controller 'bangbang'; known: ")
    assert info.value.key == "controller"
    assert "bang-bang, pressure-pi" in message
    assert isinstance(info.value, ValueError) and isinstance(info.value, SoftbendError)
    assert "\n" not in message


def test_duplicate_refused_unless_replace():
    reg: Registry[int] = Registry("plant")
    reg.register("fem", 1)
    with pytest.raises(ValueError, match="already registered"):
        reg.register("fem", 2)
    reg.register("fem", 3, replace=True)
    assert reg.get("fem") == 3
    reg.unregister("fem")
    assert "fem" not in reg
    with pytest.raises(UnknownNameError, match="known: none"):
        reg.get("fem")


@pytest.mark.parametrize("name", ["", "Bang", "two words", " x", None, 3])
def test_bad_names_refused(name):
    with pytest.raises(ValueError, match="lower-case"):
        Registry("plant").register(name, 1)
