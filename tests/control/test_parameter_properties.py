"""Property-based tests of ``--set`` and ``--rig-param`` values, for every name.

Whatever text is typed for a controller parameter or a rig setting (huge, tiny,
negative, NaN, garbage, empty), the check gives either a value of the right kind
inside the declared range, or one ``ParameterValueError`` /
``UnknownParameterError`` / ``ValueError`` whose one-line message names the
parameter: never another exception. A value the check accepts is accepted by
the controller or RigParams too. The examples are derandomized and bounded; the
number of inputs tried is printed in the test summary.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from softbend.control.factory import (
    CONTROLLERS,
    ControllerModel,
    build_controller,
    controller_parameters,
)
from softbend.control.rig import RigParams
from softbend.control.rigconfig import simulation_settings_entry
from softbend.control.rigs import rig_params_for, rig_settings
from softbend.design import sfrba_design
from softbend.parameters import (
    ParameterValueError,
    UnknownParameterError,
    declared_ranges,
    parse_assignments,
)

from ..properties import NASTY_VALUES, property_settings

EXAMPLES = 40
SETTINGS = property_settings(EXAMPLES)
BUILT_IN = ("bang-bang", "bang-bang-closed", "pressure-pi", "pressure-relay", "predictive")
DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)

#: Text that breaks naive parsers.
NASTY = NASTY_VALUES


def _values(declared) -> st.SearchStrategy[str]:
    """Text: nasty words, numbers around and far from the range, random text."""
    numbers = st.floats(allow_nan=True, allow_infinity=True) | st.integers(-(10**30), 10**30)
    near = st.floats(
        min_value=declared.low - abs(declared.high - declared.low),
        max_value=declared.high + abs(declared.high - declared.low),
    )
    return st.one_of(
        st.sampled_from(NASTY),
        numbers.map(repr),
        near.map(repr),
        near.map(lambda v: f"{v:.3e}"),
        st.text(max_size=12),
    )


@pytest.fixture(scope="module")
def curves():
    """The default rig's fill and vent curves, built once (PredictivePulse builds its own)."""
    from softbend.control.predictive import PneumaticCurves

    return PneumaticCurves(RigParams())


def _one_line_naming(exc: BaseException, name: str) -> None:
    message = str(exc)
    assert "\n" not in message and message.strip() == message, message
    assert message.startswith(f"{name}: ") or f" {name}: " in message, message


def _controller_names() -> list[tuple[str, str]]:
    return [
        (controller, name)
        for controller in BUILT_IN
        for name in declared_ranges(CONTROLLERS.get(controller))
    ]


@pytest.mark.parametrize(("controller", "name"), _controller_names())
@SETTINGS
@given(data=st.data())
def test_set_values_are_checked_or_refused_in_one_line(
    table, curves, monkeypatch, fuzz_counter, controller, name, data
):
    declared = declared_ranges(CONTROLLERS.get(controller))[name]
    text = data.draw(_values(declared))
    fuzz_counter["--set values"] += 1
    try:
        texts = parse_assignments([f"{name}={text}"])
        typed = controller_parameters(controller, texts, from_text=True)
    except (ParameterValueError, UnknownParameterError) as exc:
        _one_line_naming(exc, name)
        assert exc.key == name
        return
    except ValueError as exc:  # parse_assignments: not NAME=VALUE
        _one_line_naming(exc, "items")
        return
    value = typed[name]
    assert isinstance(value, float) and math.isfinite(value) and declared.contains(value)
    model = ControllerModel(table, table, RigParams())
    monkeypatch.setattr("softbend.control.predictive.PneumaticCurves", lambda params: curves)
    build_controller(controller, model, {name: value})  # the class takes it


def test_a_text_value_is_read_by_kind_then_held_to_its_range(table):
    for controller, name in _controller_names():
        declared = declared_ranges(CONTROLLERS.get(controller))[name]
        inside = declared.low if declared.low_inclusive else (declared.low + declared.high) / 2
        got = controller_parameters(controller, {name: repr(inside)}, from_text=True)[name]
        assert got == inside and declared.contains(got)
        for outside in (declared.low - 1.0, declared.high * 10 + 1.0, math.nan, math.inf):
            with pytest.raises(ParameterValueError) as info:
                controller_parameters(controller, {name: repr(outside)}, from_text=True)
            _one_line_naming(info.value, name)


@pytest.mark.parametrize("name", list(declared_ranges(simulation_settings_entry)))
@SETTINGS
@given(data=st.data())
def test_rig_param_values_are_checked_or_refused_in_one_line(fuzz_counter, name, data):
    declared = declared_ranges(simulation_settings_entry)[name]
    text = data.draw(_values(declared))
    fuzz_counter["--rig-param values"] += 1
    try:
        checked = rig_settings([f"{name}={text}"])
    except (ParameterValueError, UnknownParameterError) as exc:
        _one_line_naming(exc, name)
        assert exc.key == "rig_assignments"
        return
    except ValueError as exc:  # not NAME=VALUE
        _one_line_naming(exc, "rig_assignments")
        return
    value = checked[name]
    assert declared.contains(value) and math.isfinite(value)
    assert isinstance(value, int if name == "sensor_bits" else float)
    params = rig_params_for(DESIGN, checked)  # RigParams takes every checked value
    if name != "tubing_mm3":
        assert getattr(params, name) == value


@pytest.mark.parametrize("name", list(declared_ranges(simulation_settings_entry)))
@SETTINGS
@given(value=st.one_of(st.floats(), st.integers(-(10**30), 10**30), st.booleans(), st.text()))
def test_rig_toml_values_are_checked_or_refused_in_one_line(fuzz_counter, name, value):
    fuzz_counter["[simulation] values"] += 1
    try:
        checked = rig_settings(values={name: value})
    except ParameterValueError as exc:
        _one_line_naming(exc, name)
        return
    assert declared_ranges(simulation_settings_entry)[name].contains(checked[name])
