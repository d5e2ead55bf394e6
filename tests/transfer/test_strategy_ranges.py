"""Every numeric parameter of every transfer strategy has a declared range, held before work.

A value outside its range is one :class:`~softbend.parameters.ParameterValueError`
line naming the parameter, whether it is typed (``--set``), given from Python
(``make_strategy``) or set on a strategy built directly; a network whose training
diverges anyway is a :class:`~softbend.errors.ConvergenceError`, never a fitted
model. The property tests try random ``--set`` text and random data values on
every registered strategy (derandomized; the number of inputs is printed in the
test summary).
"""

from __future__ import annotations

import inspect
import math
import time

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from softbend.errors import ConvergenceError, LimitError
from softbend.parameters import (
    ParameterValueError,
    Range,
    UnknownParameterError,
    declare_ranges,
    declared_ranges,
)
from softbend.transfer.strategies import (
    BUILTIN_STRATEGIES,
    STRATEGIES,
    ExperimentalMLP,
    RefinedEnsemble,
    RefinedMLP,
    ResidualGP,
    describe_strategies,
    make_strategy,
)
from softbend.transfer.strategies.parameters import FILLED, check_parameters, item_count

from ..properties import NASTY_VALUES, property_settings


# ------------------------------------------------------------ every number has a range
def _numeric(parameter: inspect.Parameter) -> bool:
    """Whether a constructor parameter holds a number or numbers (read independently of
    softbend's own reading of kinds)."""
    default = parameter.default
    if isinstance(default, bool):
        return False
    if isinstance(default, int | float):
        return True
    if isinstance(default, tuple) and default and all(isinstance(v, int) for v in default):
        return True
    note = parameter.annotation
    text = note if isinstance(note, str) else getattr(note, "__name__", str(note))
    words = {
        w.strip() for w in text.replace("[", "|").replace("]", "|").replace(",", "|").split("|")
    }
    return bool(words & {"int", "float"}) and "bool" not in words


def unranged(cls: type) -> list[str]:
    """The numeric public parameters of ``cls`` that declare no range."""
    ranges = declared_ranges(cls)
    return [
        name
        for name, parameter in inspect.signature(cls).parameters.items()
        if name not in FILLED and _numeric(parameter) and name not in ranges
    ]


def test_the_check_finds_a_numeric_parameter_without_a_range():
    class Toy:
        def __init__(self, base=None, *, share: float = 1.0, n: int = 3, flag: bool = False):
            pass

    assert unranged(Toy) == ["share", "n"]
    declare_ranges(share=Range(0, 1, "fraction", "a share"))(Toy)
    assert unranged(Toy) == ["n"]


@pytest.mark.parametrize("name", STRATEGIES.names())
def test_every_numeric_parameter_of_every_strategy_declares_a_range(name):
    cls = STRATEGIES.get(name)
    assert unranged(cls) == [], f"{name}: declare a Range for {unranged(cls)}"
    defaults = {
        k: p.default for k, p in inspect.signature(cls).parameters.items() if k not in FILLED
    }
    for key, declared in declared_ranges(cls).items():
        assert declared.unit and declared.why, f"{name}.{key}: a Range needs a unit and a why"
        assert declared.contains(defaults[key]), f"{name}.{key}: the default is out of range"


def test_the_declared_ranges_are_the_documented_ones():
    table = {
        (name, key): (declared.low, declared.high, declared.max_items)
        for name in BUILTIN_STRATEGIES
        for key, declared in declared_ranges(STRATEGIES.get(name)).items()
    }
    assert table == {
        ("base-mean-residual", "n_bins"): (1, 100, None),
        ("experimental", "hidden_sizes"): (1, 1024, 2),
        ("experimental", "epochs"): (1, math.inf, None),
        ("experimental", "learning_rate"): (0, 1, None),
        ("experimental", "patience"): (1, 1_000_000, None),
        ("experimental", "min_delta"): (0, 1, None),
        ("experimental", "validation_share"): (0, 1, None),
        ("refined", "epochs"): (1, math.inf, None),
        ("refined", "learning_rate"): (0, 1, None),
        ("refined", "patience"): (1, 1_000_000, None),
        ("refined", "min_delta"): (0, 1, None),
        ("refined", "validation_share"): (0, 1, None),
        ("residual-gp", "n_restarts"): (0, 100, None),
        ("residual-gp", "hyper_points"): (10, 100000, None),
        ("refined-ensemble", "n_members"): (2, 100, None),
        ("refined-ensemble", "epochs"): (1, math.inf, None),
        ("refined-ensemble", "learning_rate"): (0, 1, None),
        ("refined-ensemble", "patience"): (1, 1_000_000, None),
        ("refined-ensemble", "min_delta"): (0, 1, None),
        ("refined-ensemble", "validation_share"): (0, 1, None),
        ("scaled-refined", "epochs"): (1, math.inf, None),
        ("scaled-refined", "learning_rate"): (0, 1, None),
        ("scaled-refined", "patience"): (1, 1_000_000, None),
        ("scaled-refined", "min_delta"): (0, 1, None),
        ("scaled-refined", "validation_share"): (0, 1, None),
    }
    assert not declared_ranges(RefinedMLP)["learning_rate"].low_inclusive
    assert item_count(ExperimentalMLP, "hidden_sizes") == 2


def test_the_strategies_list_names_each_range():
    rows = {r["name"]: r for r in describe_strategies()}
    assert rows["refined"]["ranges"]["learning_rate"] == "(0, 1] standardized units"
    assert rows["experimental"]["ranges"]["hidden_sizes"].startswith(
        "2 integers separated by commas, each in [1, 1024]"
    )
    assert rows["residual-gp"]["ranges"] == {
        "n_restarts": "[0, 100] restarts",
        "hyper_points": "[10, 100000] readings",
    }
    assert rows["fem-only"]["ranges"] == {}


# ------------------------------------------------------------------ the reported values
@pytest.fixture(scope="module")
def tiny_base(quick_measurements):
    """A fitted MLP of 4 and 4 hidden units with seeded weights (no training: instant)."""
    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.mlp_core import init_parameters, model_rng, standardization

    X, y = quick_measurements.features, quick_measurements.angle_deg
    coefs, intercepts = init_parameters(model_rng(0, 4, 4, 0), X.shape[1], 4, 4)
    x_mean, x_scale = standardization(X)
    y_mean, y_scale = standardization(y)
    return NormalizedMLPRegressor.from_arrays(
        x_mean=x_mean,
        x_scale=x_scale,
        y_mean=float(y_mean),
        y_scale=float(y_scale),
        coefs=coefs,
        intercepts=intercepts,
    )


def _set(name: str, key: str, text: str):
    return check_parameters(STRATEGIES.get(name), {key: text}, from_text=True)


@pytest.mark.parametrize(
    ("text", "shown"),
    [
        ("0,0", "got '0,0' (2 values)"),  # was a ZeroDivisionError
        ("-3,4", "got '-3,4' (2 values)"),  # was "expected non-negative integer"
        ("100000,100000", "got '100000,100000' (2 values)"),  # was 80 GB of weights
        ("63", "got '63' (1 value)"),  # was a Python unpacking error
        ("63,65,67", "got '63,65,67' (3 values)"),
        ("1," + "9" * 400, "999... (2 values)"),  # was an OverflowError
    ],
)
def test_hidden_sizes_are_two_layers_of_1_to_1024_units(text, shown):
    with pytest.raises(ParameterValueError) as error:
        _set("experimental", "hidden_sizes", text)
    message = str(error.value)
    assert message.startswith(
        "hidden_sizes: must be 2 integers separated by commas, each in [1, 1024] units per "
        "layer; got "
    )
    assert shown in message and "\n" not in message
    assert _set("experimental", "hidden_sizes", "1,1024") == {"hidden_sizes": (1, 1024)}


def test_a_billion_gp_restarts_are_refused_at_once():
    start = time.perf_counter()
    with pytest.raises(ParameterValueError) as error:
        _set("residual-gp", "n_restarts", "1000000000")
    assert time.perf_counter() - start < 1.0
    assert error.value.key == "n_restarts"
    assert error.value.detail == "must be in [0, 100] restarts; got '1000000000'"
    with pytest.raises(ParameterValueError, match=r"^n_restarts: .*\(402 characters\)"):
        _set("residual-gp", "n_restarts", "9" * 400)


@pytest.mark.parametrize("name", ["refined", "experimental", "refined-ensemble", "scaled-refined"])
@pytest.mark.parametrize("text", ["1e6", "0", "-0.001", "1.0000001"])
def test_a_learning_rate_outside_0_1_is_refused(name, text):
    with pytest.raises(ParameterValueError) as error:
        _set(name, "learning_rate", text)
    assert error.value.key == "learning_rate"
    assert error.value.detail == f"must be in (0, 1] standardized units; got '{text}'"
    assert _set(name, "learning_rate", "1") == {"learning_rate": 1.0}


def test_python_values_are_held_to_the_same_ranges(tiny_base):
    with pytest.raises(ParameterValueError, match=r"^options: learning_rate: must be in \(0, 1\]"):
        make_strategy("refined", tiny_base, learning_rate=1e6)
    with pytest.raises(
        ParameterValueError, match=r"^options: n_members: must be in \[2, 100\] networks; got 1$"
    ):
        make_strategy("refined-ensemble", tiny_base, n_members=1)
    with pytest.raises(
        ParameterValueError, match=r"^options: hidden_sizes: .*got \(0, 0\) \(2 values\)$"
    ):
        make_strategy("experimental", hidden_sizes=(0, 0))
    with pytest.raises(ParameterValueError, match=r"^options: n_restarts: .*\(401 characters\)"):
        make_strategy("residual-gp", tiny_base, n_restarts=10**400)
    with pytest.raises(LimitError, match=r"^options: epochs: "):
        make_strategy("refined", tiny_base, epochs=10**9)
    with pytest.raises(ValueError, match=r"^seed: must be an integer in \[0, inf\); got -1"):
        make_strategy("residual-gp", tiny_base, seed=-1)


@pytest.fixture
def no_training(monkeypatch):
    """Training that fails the test if it starts: a check must come first."""
    import softbend.transfer.strategies.networks as strategies

    def started(*args, **kwargs):
        raise AssertionError("training started before the parameters were checked")

    monkeypatch.setattr(strategies, "fine_tune_many", started)


@pytest.mark.parametrize(
    ("strategy", "bad"),
    [
        (RefinedMLP, {"learning_rate": 1e6}),
        (RefinedMLP, {"epochs": 0}),
        (ExperimentalMLP, {"hidden_sizes": (0, 0)}),
        (ExperimentalMLP, {"hidden_sizes": (63,)}),
        (RefinedEnsemble, {"n_members": 1000}),
        (ResidualGP, {"n_restarts": 10**9}),
    ],
)
def test_a_strategy_built_directly_is_checked_when_fitted(
    tiny_base, quick_measurements, no_training, strategy, bad
):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    takes_base = "base" in inspect.signature(strategy).parameters
    model = strategy(tiny_base, **bad) if takes_base else strategy(**bad)
    (key,) = bad
    start = time.perf_counter()
    with pytest.raises(ParameterValueError) as error:
        model.fit(X, y)
    assert time.perf_counter() - start < 2.0
    assert error.value.key == key
    assert str(error.value).startswith(f"{key}: must be ")
    assert not hasattr(model, "model_")


def test_the_analytical_baseline_refuses_a_model_it_cannot_ask(quick_measurements):
    model = make_strategy("analytical", model="stiff")  # as --set model=stiff would give
    with pytest.raises(ValueError, match=r"^model: must be a bending model with a 'sweep' method"):
        model.fit(quick_measurements.features, quick_measurements.angle_deg)


# ------------------------------------------------------------------ diverged training
@pytest.mark.parametrize("damage", ["huge", "nan-loss"])
@pytest.mark.parametrize("name", ["refined", "experimental", "refined-ensemble"])
def test_a_diverged_network_is_an_error_not_a_model(
    tiny_base, quick_measurements, monkeypatch, name, damage
):
    import softbend.transfer.strategies.networks as strategies

    train = strategies.fine_tune_many

    def diverged(*args, **kwargs):
        models = train(*args, **kwargs)
        for model in models:
            if damage == "huge":
                model.coefs_[-1] = model.coefs_[-1] * 1e12
            else:
                model.loss_curve_[-1] = float("nan")
        return models

    monkeypatch.setattr(strategies, "fine_tune_many", diverged)
    X, y = quick_measurements.features, quick_measurements.angle_deg
    model = make_strategy(name, tiny_base, epochs=3, **({"n_members": 2} if "ens" in name else {}))
    with pytest.raises(ConvergenceError) as error:
        model.fit(X, y)
    message = str(error.value)
    assert message.startswith(f"The '{name}' strategy's training diverged at learning_rate 0.0006")
    assert ("(plausible: -3600 to 3600°)" if damage == "huge" else "loss is not finite") in message
    assert message.endswith("Lower the learning_rate (--set learning_rate=...)")
    assert not hasattr(model, "model_")


# ------------------------------------------------------------------ property-based tests
#: Random inputs per property test (over every built-in strategy together).
EXAMPLES = 400
SETTINGS = property_settings(EXAMPLES)
NASTY = NASTY_VALUES

_ALLOWED = (ParameterValueError, UnknownParameterError, LimitError, ValueError)


def _text_values() -> st.SearchStrategy[str]:
    number = st.one_of(
        st.integers(min_value=-(10**30), max_value=10**30),
        st.floats(allow_nan=True, allow_infinity=True),
    ).map(str)
    int_list = st.lists(
        st.integers(min_value=-(10**12), max_value=10**12), min_size=0, max_size=60
    ).map(lambda items: ",".join(map(str, items)))
    return st.one_of(st.sampled_from(NASTY), number, int_list, st.text(max_size=40))


def _data_values() -> st.SearchStrategy[object]:
    scalar = st.one_of(
        st.none(),
        st.booleans(),
        st.integers(min_value=-(10**400), max_value=10**400),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=20),
    )
    return st.one_of(
        scalar,
        st.lists(st.integers(min_value=-(10**400), max_value=10**400), max_size=60),
        st.lists(scalar, max_size=5).map(tuple),
        st.dictionaries(st.text(max_size=3), scalar, max_size=2),
    )


def _check_outcome(name: str, key: str, value: object, from_text: bool) -> None:
    """Checked values inside the declared ranges, or one allowed error naming ``key``."""
    cls = STRATEGIES.get(name)
    try:
        checked = check_parameters(cls, {key: value}, from_text=from_text)
    except _ALLOWED as error:
        message = str(error)
        assert "\n" not in message and message.startswith(f"{key}: "), message
        return
    assert list(checked) == [key]
    declared = declared_ranges(cls).get(key)
    if declared is not None:
        assert declared.contains(checked[key]), (key, checked[key])
        result = checked[key]
        if isinstance(result, int | float) and not isinstance(result, bool):
            assert math.isfinite(result)
        count = item_count(cls, key)
        if count is not None:
            assert isinstance(result, tuple) and len(result) == count


def _keys(name: str) -> st.SearchStrategy[str]:
    known = [k for k in inspect.signature(STRATEGIES.get(name)).parameters if k != "self"]
    return st.one_of(st.sampled_from(known), st.sampled_from(["seed", "base", "epoch", "x"]))


@SETTINGS
@given(data=st.data())
def test_random_set_text_is_checked_or_one_line(fuzz_counter, data):
    name = data.draw(st.sampled_from(BUILTIN_STRATEGIES))
    key = data.draw(_keys(name))
    text = data.draw(_text_values())
    fuzz_counter["transfer strategy --set text"] += 1
    _check_outcome(name, key, text, from_text=True)


@SETTINGS
@given(data=st.data())
def test_random_python_values_are_checked_or_one_line(fuzz_counter, data):
    name = data.draw(st.sampled_from(BUILTIN_STRATEGIES))
    key = data.draw(_keys(name))
    value = data.draw(_data_values())
    fuzz_counter["transfer strategy options"] += 1
    _check_outcome(name, key, value, from_text=False)


def test_the_nasty_values_of_every_parameter_of_every_strategy():
    """Every nasty value on every parameter: the exhaustive companion of the random ones."""
    for name in BUILTIN_STRATEGIES:
        for key in inspect.signature(STRATEGIES.get(name)).parameters:
            for text in NASTY:
                _check_outcome(name, key, text, from_text=True)


def test_the_random_inputs_reach_every_outcome():
    """The values above do exercise both ends: accepted values and each kind of refusal."""
    assert _set("refined", "epochs", "5") == {"epochs": 5}
    for text, error in [("1e309", ParameterValueError), ("9" * 5000, ParameterValueError)]:
        with pytest.raises(error):
            _set("refined", "learning_rate", text)
    with pytest.raises(LimitError):
        _set("refined", "epochs", "99999999999999999999999999")
    with pytest.raises(UnknownParameterError):
        _set("refined", "seed", "3")
    assert np.isclose(_set("refined", "learning_rate", "1e-320")["learning_rate"], 1e-320)
