"""Public parameters by name: one set of rules for controllers and transfer strategies."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.errors import LimitError
from softbend.parameters import (
    ParameterValueError,
    UnknownParameterError,
    check_parameters,
    effective_parameters,
    parameter_defaults,
    parse_assignments,
)


def factory(
    model,
    *,
    gain: float = 1.0,
    steps: int = 3,
    on: bool = True,
    tag: str = "a",
    preview: float | None = None,
    sizes: tuple[int, int] = (8, 8),
    epochs: int = 10,
):
    return model


class Strategy:
    def __init__(self, base=None, epochs: int = 1000, seed: int = 0) -> None:
        self.base, self.epochs, self.seed = base, epochs, seed


def test_text_is_read_by_each_parameters_kind():
    given = {
        "gain": "2",
        "steps": "5",
        "on": "off",
        "tag": " b ",
        "preview": "0.5",
        "sizes": "63,65",
    }
    checked = check_parameters(factory, given, from_text=True)
    assert checked == {
        "gain": 2.0,
        "steps": 5,
        "on": False,
        "tag": "b",
        "preview": 0.5,
        "sizes": (63, 65),
    }
    assert isinstance(checked["gain"], float) and isinstance(checked["steps"], int)


def test_data_values_are_checked_and_normalised():
    checked = check_parameters(factory, {"gain": 2, "steps": np.int64(4), "sizes": [3, 4]})
    assert checked == {"gain": 2.0, "steps": 4, "sizes": (3, 4)}
    assert type(checked["steps"]) is int
    with pytest.raises(ParameterValueError, match=r"^steps: must be an integer; got 2.5$"):
        check_parameters(factory, {"steps": 2.5})
    with pytest.raises(ParameterValueError, match="must be true or false"):
        check_parameters(factory, {"on": 1})


@pytest.mark.parametrize(
    ("key", "text"),
    [("gain", "fast"), ("gain", "nan"), ("steps", "1.5"), ("on", "maybe"), ("sizes", "63;65")],
)
def test_bad_text_is_one_line_naming_the_parameter(key, text):
    with pytest.raises(ParameterValueError, match=f"^{key}: must be ") as info:
        check_parameters(factory, {key: text}, from_text=True)
    assert info.value.key == key and "\n" not in str(info.value)


def test_unknown_name_lists_the_known_ones_and_hints_at_filled_ones():
    with pytest.raises(
        UnknownParameterError, match="known: gain, steps, on, tag, preview, sizes, epochs"
    ):
        check_parameters(factory, {"gian": "1"}, from_text=True)
    with pytest.raises(
        UnknownParameterError,
        match=r"^seed: is not a parameter \(set once per run\); known: epochs$",
    ):
        check_parameters(
            Strategy,
            {"seed": 1},
            skip=("base", "seed"),
            keyword_only=False,
            hints={"seed": "set once per run"},
        )


def test_epochs_are_held_to_the_limit():
    with pytest.raises(LimitError, match=r"^epochs: the value is 1,000,000,000 epochs"):
        check_parameters(factory, {"epochs": "1000000000"}, from_text=True)


def test_defaults_and_the_record_of_a_run():
    assert parameter_defaults(Strategy, skip=("base", "seed"), keyword_only=False) == {
        "epochs": 1000
    }
    assert effective_parameters(factory, {"gain": 3.0})["gain"] == 3.0
    assert effective_parameters(factory)["preview"] is None


def test_assignments():
    assert parse_assignments(["a=1", " b = x "]) == {"a": "1", "b": "x"}
    with pytest.raises(ValueError, match=r"^an assignment must be NAME=VALUE"):
        parse_assignments(["a"])
    with pytest.raises(ValueError, match=r"^the parameter .a. is given twice"):
        parse_assignments(["a=1", "a=2"])


# --- declared ranges -----------------------------------------------------------------------


def _ranged():
    from softbend.parameters import Range, declare_ranges

    @declare_ranges(
        period=Range(1e-4, 10.0, "s", "a tick"),
        gain=Range(0.0, 1.0, low_inclusive=False),
        hidden_sizes=Range(1, 1024, "units", max_items=8),
    )
    def factory(
        model, *, period: float = 0.01, gain: float = 0.5, hidden_sizes=(8, 8), name: str = "a"
    ):
        return None

    return factory


@pytest.mark.parametrize(
    ("text", "shown"),
    [
        ({"period": "1e-12"}, "must be in [0.0001, 10] s; got '1e-12'"),
        ({"period": "11"}, "[0.0001, 10] s"),
        ({"gain": "0"}, "must be in (0, 1]; got '0'"),
        ({"hidden_sizes": "0,0"}, "1 to 8 values, each in [1, 1024] units; got 0,0"),
        ({"hidden_sizes": "100000,100000"}, "got 100000,100000"),
        ({"hidden_sizes": "-3,4"}, "got -3,4"),
        ({"hidden_sizes": ",".join(["4"] * 9)}, "1 to 8 values"),
    ],
)
def test_a_value_outside_its_declared_range_is_refused(text, shown):
    with pytest.raises(ParameterValueError) as info:
        check_parameters(_ranged(), text, from_text=True)
    message = str(info.value)
    assert shown in message
    assert message.startswith(f"{next(iter(text))}: must be ")
    assert info.value.key == next(iter(text))


def test_values_inside_their_ranges_pass_and_undeclared_ones_are_not_bounded():
    checked = check_parameters(
        _ranged(),
        {"period": "10", "gain": "1", "hidden_sizes": "1024,1", "name": "b"},
        from_text=True,
    )
    assert checked == {"period": 10.0, "gain": 1.0, "hidden_sizes": (1024, 1), "name": "b"}
    data = check_parameters(_ranged(), {"period": 1e-4})
    assert data == {"period": 1e-4}


def test_ranges_are_declared_only_for_parameters_that_exist():
    from softbend.parameters import Range, declare_ranges

    with pytest.raises(TypeError, match="no parameter"):

        @declare_ranges(nope=Range(0, 1))
        def factory(model, *, period: float = 0.01):
            return None


def test_a_subclass_inherits_and_overrides_the_declarations():
    from softbend.parameters import Range, declare_ranges, declared_ranges

    @declare_ranges(a=Range(0, 1), b=Range(0, 2))
    class Base:
        def __init__(self, *, a: float = 0.5, b: float = 1.0):
            pass

    @declare_ranges(b=Range(0, 3))
    class Child(Base):
        pass

    assert declared_ranges(Child) == {"a": Range(0, 1), "b": Range(0, 3)}
    assert declared_ranges(Base)["b"] == Range(0, 2)
    assert Range(0, 1).describe() == "[0, 1]"
    assert Range(0.0, unit="s", low_inclusive=False).describe() == "(0, inf) s"


def test_an_integer_of_any_size_is_compared_without_overflow():
    from softbend.parameters import Range

    assert not Range(0, 100).contains(10**400)
    assert not Range(0, 100).contains(-(10**400))
    assert Range(0, 100).contains(100)
    with pytest.raises(ParameterValueError, match="characters"):
        check_parameters(_ranged(), {"period": 10**400})
