"""The schema of a saved surrogate's ``params`` and ``state``: one rule per key.

Loading (:func:`softbend.surrogates.load_surrogate`) validates every value before
it reaches the estimator: each kind has a fixed set of parameter and state keys,
each with a rule (type, dtype, dimensions, finiteness, bounds), then rules
across keys (chained shapes, physical plausibility of the corrections'
parameters) and between the parameters and the state (an MLP's
``hidden_sizes`` and its weights, a polynomial's ``degree`` and its exponents).
Only a key of the schema is ever set on a model.

Each surrogate family names its :class:`Schema` in its
:class:`~softbend.surrogates.families.Storage` (:data:`POLYNOMIAL_SCHEMA`,
:data:`MLP_SCHEMA`, :data:`XGBOOST_SCHEMA`, :data:`TABLE_SCHEMA`); the composites' are
:data:`COMPOSITE_SCHEMAS`. A family added outside softbend builds its own from
the public rules :func:`real`, :func:`integer`, :func:`string`, :func:`array`,
:func:`boolean` and :func:`optional`.

A float that is NaN or infinite is stored as ``{"__float__": "nan"}`` (or
``"inf"``, ``"-inf"``) so that the file is strict JSON; the rules that allow
such a value (a loss curve, an unbounded memory limit) read that form and,
from files written before it, a bare ``NaN``/``Infinity``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from softbend._validation import interval_text, must_be, short_repr
from softbend.design import FEATURE_QUANTITIES
from softbend.errors import SchemaError
from softbend.plausibility import RANGES, implausible_index
from softbend.surrogates.features import TARGET

if TYPE_CHECKING:
    from softbend.actuators import Actuator

__all__ = [
    "COMPOSITE_SCHEMAS",
    "FLOAT_TAG",
    "MLP_SCHEMA",
    "POLYNOMIAL_SCHEMA",
    "QUANTITIES",
    "TABLE_SCHEMA",
    "XGBOOST_SCHEMA",
    "Rule",
    "RuleError",
    "Schema",
    "array",
    "boolean",
    "integer",
    "no_check",
    "no_inputs_check",
    "optional",
    "real",
    "string",
    "tag_float",
    "untag_float",
]

#: Key of the JSON object that stands for a NaN or infinite float.
FLOAT_TAG = "__float__"

_NON_FINITE = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}

#: The quantity of :data:`softbend.plausibility.RANGES` of each input and of the target.
QUANTITIES: dict[str, str] = {**FEATURE_QUANTITIES, TARGET: "angle_deg"}


class RuleError(SchemaError):
    """A value breaks its rule.

    The message is the predicate (``must be ...; got ...``). A rule of one value
    leaves ``key`` unset (the loader sets the value's field path, ``state.coef_``,
    and the file); a rule across keys names the field at fault itself.
    """


Rule = Callable[[object], Any]


def tag_float(value: float) -> Any:
    """``value`` if finite, else ``{"__float__": "nan" | "inf" | "-inf"}`` (strict JSON)."""
    if math.isfinite(value):
        return value
    return {FLOAT_TAG: "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")}


def untag_float(value: object) -> Any:
    """The float a :func:`tag_float` object stands for; any other value unchanged.

    Raises
    ------
    RuleError
        An object with the key ``"__float__"`` that is not one :func:`tag_float` writes.
    """
    if isinstance(value, dict) and FLOAT_TAG in value:
        text = value[FLOAT_TAG]
        if set(value) != {FLOAT_TAG} or not isinstance(text, str) or text not in _NON_FINITE:
            raise RuleError(
                must_be(f'{{"{FLOAT_TAG}": "nan" | "inf" | "-inf"}} for a non-finite number', value)
            )
        return _NON_FINITE[text]
    return value


_FLOAT = "float64"
_INT = "int64"


def _is_real(value: object) -> bool:
    return type(value) in (int, float)  # not bool


def _scalar(value: object, dtype: str, what: str) -> Any:
    """A plain JSON number, or a ``{"__scalar__", "dtype"}`` of ``dtype``, decoded."""
    ok = _is_real if dtype == _FLOAT else (lambda v: type(v) is int)
    if dtype == _FLOAT:
        value = untag_float(value)
    if ok(value):
        if dtype != _FLOAT:
            return value
        try:
            return float(cast(float, value))  # an int or a float: ok() checked
        except OverflowError:  # an integer beyond float64
            raise RuleError(must_be(f"{what} within {dtype}", value)) from None
    if isinstance(value, dict) and set(value) == {"__scalar__", "dtype"}:
        inner = untag_float(value["__scalar__"]) if dtype == _FLOAT else value["__scalar__"]
        if value["dtype"] == dtype and ok(inner):
            try:
                return np.dtype(dtype).type(inner)
            except OverflowError:
                raise RuleError(must_be(f"{what} within {dtype}", value)) from None
        raise RuleError(must_be(f"{what} of dtype {dtype}", value))
    raise RuleError(must_be(what, value))


def _bounds(low: float | None, strict: bool) -> str:
    """`` in (0, inf)`` for a lower bound (``strict``: exclusive), else nothing."""
    return "" if low is None else f" in {interval_text(low, math.inf, low_inclusive=not strict)}"


def real(*, low: float | None = None, strict: bool = False, finite: bool = True) -> Rule:
    """A number (a plain JSON one or a float64 ``__scalar__``), finite unless ``finite=False``.

    Parameters
    ----------
    low : float, optional
        Lower bound, in the value's unit.
    strict : bool
        The bound is exclusive (``> low``) rather than inclusive.
    finite : bool
        Refuse infinities (NaN is always refused).
    """
    what = ("a finite number" if finite else "a number") + _bounds(low, strict)
    if not finite:
        what += " or inf" if low is not None else ", inf or -inf"

    def rule(value: object) -> Any:
        decoded = _scalar(value, _FLOAT, what)
        x = float(decoded)
        if (finite and not math.isfinite(x)) or math.isnan(x):
            raise RuleError(must_be(what, x))
        if low is not None and not (x > low if strict else x >= low):
            raise RuleError(must_be(what, x))
        return decoded

    return rule


def integer(low: int = 0) -> Rule:
    """An integer (a plain JSON one, not a bool, or an int64 ``__scalar__``) >= ``low``."""
    what = f"an integer in {interval_text(low, math.inf, low_inclusive=True)}"

    def rule(value: object) -> Any:
        decoded = _scalar(value, _INT, what)
        if int(decoded) < low:
            raise RuleError(must_be(what, int(decoded)))
        return decoded

    return rule


def string(choices: tuple[str, ...] | None = None) -> Rule:
    """A string, one of ``choices`` if given."""
    what = "a string" if choices is None else f"one of {', '.join(map(repr, choices))}"

    def rule(value: object) -> Any:
        decoded = value
        if (
            isinstance(value, dict)
            and set(value) == {"__scalar__", "dtype"}
            and value["dtype"] == "str"
            and isinstance(value["__scalar__"], str)
        ):
            decoded = np.str_(value["__scalar__"])
        if not isinstance(decoded, str) or (choices is not None and decoded not in choices):
            raise RuleError(must_be(what, value))
        return decoded

    return rule


def boolean(value: object) -> bool:
    """The rule of a ``true`` or ``false`` (not a number)."""
    if not isinstance(value, bool):
        raise RuleError(must_be("true or false", value))
    return value


def optional(rule: Rule) -> Rule:
    """``null`` (None), or a value of ``rule``."""

    def either(value: object) -> Any:
        if value is None:
            return None
        try:
            return rule(value)
        except RuleError as err:
            detail = err.detail
            if detail.startswith("must be "):
                raise RuleError(f"must be null or {detail[len('must be ') :]}") from None
            raise RuleError(f"{detail} (or be null)") from None

    return either


def _leaves(nested: object, shape: list[int]) -> list[Any]:
    """The elements of a nested list of ``shape``, in order; raise if it has another shape."""
    items = [nested]
    for depth, size in enumerate(shape):
        deeper: list[Any] = []
        for item in items:
            if not isinstance(item, list) or len(item) != size:
                found = f"{len(item)} items" if isinstance(item, list) else short_repr(item)
                raise RuleError(
                    f"must hold nested lists of its shape {shape}; got {found} at depth {depth}"
                )
            deeper.extend(item)
        items = deeper
    return items


def array(dtype: str, ndim: int, *, low: float | None = None, strict: bool = False) -> Rule:
    """A ``{"__ndarray__", "dtype", "shape"}`` of ``dtype`` and ``ndim``; floats finite.

    Parameters
    ----------
    dtype : {"float64", "int64", "str"}
        The array's dtype.
    ndim : int
        Its number of dimensions.
    low : float, optional
        Lower bound of every element (``strict``: exclusive).
    """
    element = {_FLOAT: "finite numbers", _INT: "integers", "str": "strings"}[dtype]
    what = f"a {ndim}-D {dtype} array"

    def rule(value: object) -> np.ndarray:
        if not (isinstance(value, dict) and set(value) == {"__ndarray__", "dtype", "shape"}):
            raise RuleError(
                must_be(f"{what} ({{'__ndarray__': ..., 'dtype': ..., 'shape': ...}})", value)
            )
        if value["dtype"] != dtype:
            raise RuleError(f"must be {what}; got dtype {short_repr(value['dtype'])}")
        shape = value["shape"]
        if not (
            isinstance(shape, list)
            and len(shape) == ndim
            and all(type(n) is int and n >= 0 for n in shape)
        ):
            raise RuleError(f"must be {what}; got shape {short_repr(shape)}")
        leaves = _leaves(value["__ndarray__"], shape)
        ok = {_FLOAT: _is_real, _INT: lambda v: type(v) is int, "str": lambda v: type(v) is str}
        good = ok[dtype]
        bad = next((i for i, v in enumerate(leaves) if not good(v)), None)
        if bad is not None:
            raise RuleError(f"must hold only {element}; got {short_repr(leaves[bad])}")
        try:
            array = np.asarray(leaves, dtype=object if dtype == "str" else np.dtype(dtype))
        except OverflowError:
            raise RuleError(f"must hold integers within {dtype}") from None
        array = np.ascontiguousarray(array.reshape(shape))
        if dtype == _FLOAT:
            finite = np.isfinite(array)
            if not finite.all():
                where = tuple(int(i) for i in np.argwhere(~finite)[0])
                raise RuleError(f"must hold only finite numbers; got {array[where]} at {where}")
        if low is not None:
            above = array > low if strict else array >= low
            if not above.all():
                where = tuple(int(i) for i in np.argwhere(~above)[0])
                raise RuleError(
                    f"must hold only values{_bounds(low, strict)}; got {array[where]} at {where}"
                )
        return array

    return rule


def _arrays(count: int, ndim: int) -> Rule:
    """A list of ``count`` float64 arrays of ``ndim`` dimensions."""
    item = array(_FLOAT, ndim)

    def rule(value: object) -> list[np.ndarray]:
        if not isinstance(value, list) or len(value) != count:
            found = f"{len(value)} items" if isinstance(value, list) else short_repr(value)
            raise RuleError(f"must be a list of {count} {ndim}-D float64 arrays; got {found}")
        arrays = []
        for i, entry in enumerate(value):
            try:
                arrays.append(item(entry))
            except RuleError as err:
                raise RuleError(f"item {i} {err.detail}") from None
        return arrays

    return rule


def _numbers(value: object) -> list[float]:
    """A list of numbers (a diagnostic such as a loss curve: NaN and inf allowed)."""
    if isinstance(value, list):
        value = [untag_float(v) for v in value]
    if not isinstance(value, list) or not all(_is_real(v) for v in value):
        raise RuleError(must_be("a list of numbers", value))
    return [float(v) for v in value]


def _int_pair(value: object) -> Any:
    """Two integers >= 1, as a tuple (``{"__tuple__": [...]}``) or a list."""
    items = (
        value.get("__tuple__") if isinstance(value, dict) and set(value) == {"__tuple__"} else value
    )
    if not isinstance(items, list) or len(items) != 2:
        raise RuleError(must_be("two integers in [1, inf)", value))
    pair = [integer(1)(v) for v in items]
    return tuple(pair) if items is not value else pair


def _booster(value: object) -> str:
    """XGBoost's JSON model as text: an object with a ``learner``, finite numbers only."""

    def refuse(constant: str) -> None:
        raise RuleError(f"must hold only finite numbers; got {constant}")

    if not isinstance(value, str):
        raise RuleError(must_be("XGBoost's JSON model as a string", value))
    try:
        model = json.loads(value, parse_constant=refuse)
    except json.JSONDecodeError as err:
        raise RuleError(f"must be XGBoost's JSON model; not valid JSON ({err})") from None
    learner = model.get("learner") if isinstance(model, dict) else None
    if not isinstance(learner, dict):
        raise RuleError("must be XGBoost's JSON model; no 'learner' object")
    return value


def _check_booster_inputs(state: dict[str, Any], actuator: Actuator) -> None:
    """The booster takes the inputs of ``actuator``, in order (its recorded names, if any)."""
    features = actuator.features
    learner = json.loads(state["booster"])["learner"]  # checked by _booster
    param = learner.get("learner_model_param")
    n_features = param.get("num_feature") if isinstance(param, dict) else None
    if n_features is not None and str(n_features) != str(len(features)):
        raise RuleError(
            f"must take the {len(features)} surrogate inputs; got {n_features} features",
            key="state.booster",
        )
    names = learner.get("feature_names", [])
    if names and names != list(features):  # empty: fitted on an array, no names recorded
        raise RuleError(
            f"must be fitted on the columns {', '.join(features)} in this order (or record no "
            f"feature names); got feature_names {short_repr(names)}",
            key="state.booster",
        )


def _check_inputs(state: dict[str, Any], actuator: Actuator) -> None:
    """The inputs of the polynomial and the MLP are those of ``actuator``, in order."""
    features = actuator.features
    d = len(features)
    if int(state["n_features_in_"]) != d:
        raise RuleError(
            f"must be {d} (the inputs {', '.join(features)}); got {state['n_features_in_']}",
            key="state.n_features_in_",
        )
    names = state.get("feature_names_in_")
    if names is not None and [str(n) for n in names] != list(features):
        raise RuleError(
            f"must be {', '.join(features)}; got {', '.join(map(str, names))}",
            key="state.feature_names_in_",
        )


def _check_standardization(state: dict[str, Any]) -> None:
    """Rules across keys shared by the polynomial and the MLP: one mean and scale per input."""
    d = int(state["n_features_in_"])
    for key in ("x_mean_", "x_scale_"):
        if state[key].shape != (d,):
            raise RuleError(f"must have shape ({d},); got {state[key].shape}", key=f"state.{key}")
    names = state.get("feature_names_in_")
    if names is not None and len(names) != d:
        raise RuleError(
            f"must name the {d} inputs; got {', '.join(map(str, names))}",
            key="state.feature_names_in_",
        )


def _check_polynomial(state: dict[str, Any]) -> None:
    _check_standardization(state)
    powers, coef = state["powers_"], state["coef_"]
    d = int(state["n_features_in_"])
    if powers.shape[0] < 1 or powers.shape[1] != d:
        raise RuleError(
            f"must have shape (n_terms >= 1, {d}); got {powers.shape}", key="state.powers_"
        )
    if coef.shape != (powers.shape[0],):
        raise RuleError(
            f"must have shape ({powers.shape[0]},) (one per row of 'powers_'); got {coef.shape}",
            key="state.coef_",
        )
    from softbend.surrogates.polynomial_core import plan as _plan

    try:
        _plan(powers)
    except ValueError:
        raise RuleError(
            "must be a complete exponent table (one constant row and, "
            "with every monomial, the monomial with one factor fewer)",
            key="state.powers_",
        ) from None


def _check_kernel_theta(theta: np.ndarray, names: Sequence[str] = ()) -> None:
    """Check a GP kernel's log hyperparameters (constant, length scales, noise) are plausible.

    ``names`` (one per entry) name the offending hyperparameter in the error.
    """
    width = RANGES["kernel_width"]
    with np.errstate(over="ignore", under="ignore"):
        hyper = np.exp(theta)
    bad = implausible_index(hyper, "kernel_width")
    if bad is not None:
        name = f"{names[bad]} " if names else ""
        raise RuleError(
            f"must hold the logarithms of the kernel's constant, "
            f"length scales and noise, each within {width.low:g} to {width.high:g} "
            f"(log {math.log(width.low):.4g} to {math.log(width.high):.4g}); got "
            f"{name}{hyper[bad]:g} (log {theta[bad]:g}) at index {bad}",
            key="state.kernel_theta_",
        )


def _check_table(state: dict[str, Any]) -> None:
    """The table base's curves and GP fit together (:mod:`softbend.surrogates.table`)."""
    d = int(state["n_features_in_"])
    if d < 2:
        raise RuleError(f"must be >= 2 (design parameters and pressure); got {d}",
                        key="state.n_features_in_")  # fmt: skip
    for key in ("x_mean_", "x_scale_"):
        if state[key].shape != (d,):
            raise RuleError(f"must have shape ({d},); got {state[key].shape}", key=f"state.{key}")
    designs, offsets = state["designs_"], state["curve_offsets_"]
    if designs.ndim != 2 or designs.shape[1] != d - 1 or designs.shape[0] < 1:
        raise RuleError(
            f"must have shape (n_designs >= 1, {d - 1}); got {designs.shape}", key="state.designs_"
        )
    n_points = state["curve_pressures_"].shape[0]
    if (
        offsets.shape != (designs.shape[0] + 1,)
        or offsets[0] != 0
        or offsets[-1] != n_points
        or np.any(np.diff(offsets) < 1)
    ):
        raise RuleError(
            f"must rise from 0 to {n_points} (the points) by >= 1 per design, "
            f"{designs.shape[0] + 1} values; got {short_repr(offsets.tolist())}",
            key="state.curve_offsets_",
        )
    if state["curve_angles_"].shape != (n_points,):
        raise RuleError(
            f"must have shape ({n_points},) (one per pressure); got {state['curve_angles_'].shape}",
            key="state.curve_angles_",
        )
    pressures = state["curve_pressures_"]
    for k in range(designs.shape[0]):
        if np.any(np.diff(pressures[offsets[k] : offsets[k + 1]]) <= 0):
            raise RuleError(
                f"must rise strictly along each design's curve; design {k} does not",
                key="state.curve_pressures_",
            )
    inputs, targets = state["gp_inputs_"], state["gp_targets_"]
    if inputs.ndim != 2 or inputs.shape[1] != d or inputs.shape[0] < 1:
        raise RuleError(f"must have shape (n >= 1, {d}); got {inputs.shape}",
                        key="state.gp_inputs_")  # fmt: skip
    if targets.shape != (inputs.shape[0],):
        raise RuleError(
            f"must have shape ({inputs.shape[0]},) (one per row of 'gp_inputs_'); got "
            f"{targets.shape}",
            key="state.gp_targets_",
        )
    if state["kernel_theta_"].shape != (d + 2,):
        raise RuleError(
            f"must have shape ({d + 2},) (constant, {d} length scales, noise); got "
            f"{state['kernel_theta_'].shape}",
            key="state.kernel_theta_",
        )
    _check_kernel_theta(state["kernel_theta_"])
    for key in ("curve_angles_", "gp_targets_"):
        bad = implausible_index(state[key], "angle_deg")
        if bad is not None:
            bounds = RANGES["angle_deg"]
            raise RuleError(
                f"must hold plausible angles from {bounds.low:g} to {bounds.high:g} degrees; "
                f"got {state[key][bad]:g} at index {bad}",
                key=f"state.{key}",
            )


def _check_mlp(state: dict[str, Any]) -> None:
    _check_standardization(state)
    coefs, intercepts = state["coefs_"], state["intercepts_"]
    d, h1, h2 = int(state["n_features_in_"]), coefs[0].shape[1], coefs[1].shape[1]
    expected = [(d, h1), (h1, h2), (h2, 1)]
    if [c.shape for c in coefs] != expected or 0 in (h1, h2):
        raise RuleError(
            f"must have the chained shapes (d, h1), (h1, h2), (h2, 1) with "
            f"d = {d}, h1, h2 >= 1; got {', '.join(str(c.shape) for c in coefs)}",
            key="state.coefs_",
        )
    if [b.shape for b in intercepts] != [(h1,), (h2,), (1,)]:
        raise RuleError(
            f"must have the shapes ({h1},), ({h2},), (1,) of the "
            f"layers of 'coefs_'; got {', '.join(str(b.shape) for b in intercepts)}",
            key="state.intercepts_",
        )


def no_check(state: dict[str, Any]) -> None:
    """A :attr:`Schema.check` that checks nothing across keys."""
    return None


def no_inputs_check(state: dict[str, Any], actuator: Actuator) -> None:
    """A :attr:`Schema.inputs` that checks nothing against the actuator's inputs."""
    return None


def _document(value: object) -> Any:
    """An inner surrogate: a JSON object (its own header and schema are checked on restore)."""
    if not isinstance(value, dict):
        raise RuleError(must_be("a saved surrogate (a JSON object)", value))
    return value


def _documents(value: object) -> Any:
    """Two or more inner surrogates."""
    if not isinstance(value, list) or len(value) < 2:
        raise RuleError(must_be("a list of 2 or more saved surrogates", value))
    return [_document(v) for v in value]


def _check_angle(state: dict[str, Any], key: str, what: str, *, spread: bool = False) -> None:
    """``state[key]`` (degrees) a plausible angle, or with ``spread`` a plausible deviation.

    A deviation (a residual standard deviation, >= 0 by its rule) of angles that lie
    within ``RANGES["angle_deg"]`` is at most the range's upper end.
    """
    bounds = RANGES["angle_deg"]
    value = float(state[key])
    low = 0.0 if spread else bounds.low
    if not low <= value <= bounds.high:
        raise RuleError(
            f"must be {what} from {low:g} to {bounds.high:g} degrees "
            f"(plausible {bounds.label}s); got {value:g}",
            key=f"state.{key}",
        )


def _check_residual_std(state: dict[str, Any]) -> None:
    _check_angle(state, "residual_std_", "a residual standard deviation", spread=True)


def _check_affine(state: dict[str, Any]) -> None:
    _check_angle(state, "offset_", "an angle offset")
    _check_residual_std(state)


def _gp_inputs(actuator: Actuator) -> tuple[str, ...]:
    """The GP correction's inputs: the model's inputs and the base's angle."""
    return (*actuator.features, f"the base's {TARGET}")


def _gp_hyperparameters(actuator: Actuator) -> tuple[str, ...]:
    """Names of the GP kernel's hyperparameters, in the order of ``kernel_theta_``."""
    return ("constant", *(f"length scale of {name}" for name in _gp_inputs(actuator)), "noise")


def _check_gp(state: dict[str, Any], actuator: Actuator) -> None:
    """Shapes, then the plausibility of every number of a GP correction.

    The hyperparameters ``exp(kernel_theta_)`` are dimensionless: length scales of
    standardized inputs, and a constant and noise that are variances in units of
    the targets' variance (the GP normalizes its targets). All lie within
    ``RANGES["kernel_width"]`` (a fit keeps them within the far narrower bounds of
    :func:`softbend.surrogates.corrected.gp_kernel`); outside, the kernel matrix
    degenerates and the GP predicts NaN. The standardization ``z_mean_`` holds means
    of the inputs and of the base's angle, each a plausible value of its quantity;
    ``z_scale_`` their standard deviations (or 1 for a constant column), at most the
    width of that quantity's range; the standardized ``inputs_`` lie within the
    kernel-width range in magnitude and the ``targets_`` (the base's errors,
    degrees) are plausible angles. The inputs checked for plausibility are those
    ``actuator.quantities`` names, and the base's angle.
    """
    gp_inputs = _gp_inputs(actuator)
    d = len(gp_inputs)  # the inputs and the base's angle
    for key in ("z_mean_", "z_scale_"):
        if state[key].shape != (d,):
            raise RuleError(f"must have shape ({d},); got {state[key].shape}", key=f"state.{key}")
    if state["kernel_theta_"].shape != (d + 2,):
        raise RuleError(
            f"must have shape ({d + 2},) (constant, {d} length "
            f"scales, noise); got {state['kernel_theta_'].shape}",
            key="state.kernel_theta_",
        )
    inputs, targets = state["inputs_"], state["targets_"]
    if inputs.ndim != 2 or inputs.shape[1] != d or inputs.shape[0] < 1:
        raise RuleError(f"must have shape (n >= 1, {d}); got {inputs.shape}", key="state.inputs_")
    if targets.shape != (inputs.shape[0],):
        raise RuleError(
            f"must have shape ({inputs.shape[0]},) (one per row of 'inputs_'); got {targets.shape}",
            key="state.targets_",
        )
    _check_kernel_theta(state["kernel_theta_"], _gp_hyperparameters(actuator))
    # the inputs with a plausible range (the actuator's quantities), and the base's angle
    quantities = {**actuator.quantities, gp_inputs[-1]: QUANTITIES[TARGET]}
    for j, name in enumerate(gp_inputs):
        if name not in quantities:
            continue
        bounds = RANGES[quantities[name]]
        mean, scale = float(state["z_mean_"][j]), float(state["z_scale_"][j])
        unit = f" {bounds.unit}" if bounds.unit else ""
        if not bounds.low <= mean <= bounds.high:
            raise RuleError(
                f"must hold plausible means of the GP's inputs; got "
                f"{mean:g} for {name} at index {j} (allowed {bounds.low:g} to "
                f"{bounds.high:g}{unit})",
                key="state.z_mean_",
            )
        if scale > bounds.high - bounds.low:
            raise RuleError(
                f"must hold plausible standard deviations of the GP's "
                f"inputs; got {scale:g} for {name} at index {j} (allowed up to "
                f"{bounds.high - bounds.low:g}{unit}, the width of its range)",
                key="state.z_scale_",
            )
    width = RANGES["kernel_width"]
    outside = np.abs(inputs) > width.high
    if outside.any():
        row, col = (int(i) for i in np.argwhere(outside)[0])
        raise RuleError(
            f"must hold standardized values of magnitude at most "
            f"{width.high:g}; got {inputs[row, col]:g} at ({row}, {col})",
            key="state.inputs_",
        )
    bad = implausible_index(targets, "angle_deg")
    if bad is not None:
        bounds = RANGES["angle_deg"]
        raise RuleError(
            f"must hold the base's errors, plausible angles from "
            f"{bounds.low:g} to {bounds.high:g} degrees; got {targets[bad]:g} at index {bad}",
            key="state.targets_",
        )


def _check_mlp_sizes(params: dict[str, Any], state: dict[str, Any]) -> None:
    """The declared ``hidden_sizes`` are the sizes of the weights' layers."""
    declared = tuple(params["hidden_sizes"])
    actual = (state["coefs_"][0].shape[1], state["coefs_"][1].shape[1])
    if tuple(int(h) for h in declared) != actual:
        raise RuleError(
            f"must be the layer sizes of 'coefs_', {list(actual)}; "
            f"got {short_repr(list(declared))}",
            key="params.hidden_sizes",
        )


def _check_polynomial_degree(params: dict[str, Any], state: dict[str, Any]) -> None:
    """The declared ``degree`` is the highest total degree of ``powers_``; ``rank_`` fits."""
    powers = state["powers_"]
    highest = int(powers.sum(axis=1).max())
    if int(params["degree"]) != highest:
        raise RuleError(
            f"must be the highest total degree of 'powers_', {highest}; got {params['degree']}",
            key="params.degree",
        )
    if "rank_" in state and int(state["rank_"]) > powers.shape[0]:
        raise RuleError(
            f"must be at most the number of terms, {powers.shape[0]}; got {state['rank_']}",
            key="state.rank_",
        )


def _no_params_check(params: dict[str, Any], state: dict[str, Any]) -> None:
    return None


@dataclass(frozen=True)
class Schema:
    """What a saved surrogate of one kind may hold, and the rule of each value.

    Attributes
    ----------
    params : dict or None
        A rule per constructor parameter (a key without one is refused); None for a
        family whose codec reads its parameters itself (XGBoost's).
    state : dict
        A rule per fitted attribute.
    check : callable
        Rules across keys: takes the decoded state, raises :class:`RuleError`.
    against : callable
        Rules between the parameters of the model built (its ``get_params``,
        defaults included) and the decoded state.
    inputs : callable
        Rules between the decoded state and the actuator the model is of
        (:class:`~softbend.actuators.Actuator`: its inputs in order, their plausible
        quantities); checked before ``check``. A family's ``n_features_in_`` is
        checked against the actuator's inputs by the loader in any case.
    """

    params: dict[str, Rule] | None
    state: dict[str, Rule]
    check: Callable[[dict[str, Any]], None] = no_check
    against: Callable[[dict[str, Any], dict[str, Any]], None] = _no_params_check
    inputs: Callable[[dict[str, Any], Actuator], None] = no_inputs_check


_INPUT_STATE: dict[str, Rule] = {
    "n_features_in_": integer(1),
    "feature_names_in_": array("str", 1),
    "x_mean_": array(_FLOAT, 1),
    "x_scale_": array(_FLOAT, 1, low=0.0, strict=True),
    "y_mean_": real(),
    "y_scale_": real(low=0.0, strict=True),
}

#: The schema of the polynomial family (``plr``).
POLYNOMIAL_SCHEMA = Schema(
    params={
        "degree": integer(1),
        "alpha": real(low=0.0),
        "chunk_rows": integer(1),
        "max_memory_mb": real(low=0.0, strict=True, finite=False),
    },
    state={
        **_INPUT_STATE,
        "powers_": array(_INT, 2, low=0),
        "coef_": array(_FLOAT, 1),
        "solver_": string(),
        "rank_": integer(0),
    },
    check=_check_polynomial,
    against=_check_polynomial_degree,
    inputs=_check_inputs,
)

#: The schema of the MLP family (``mlp``).
MLP_SCHEMA = Schema(
    params={
        "hidden_sizes": _int_pair,
        "epochs": integer(1),
        "batch_size": integer(1),
        "learning_rate": real(low=0.0, strict=True),
        "seed": integer(0),
        "device": string(("auto", "cpu", "cuda")),
    },
    state={
        **_INPUT_STATE,
        "coefs_": _arrays(3, 2),
        "intercepts_": _arrays(3, 1),
        "loss_curve_": _numbers,
        "device_": string(("cpu", "cuda")),
    },
    check=_check_mlp,
    against=_check_mlp_sizes,
    inputs=_check_inputs,
)

#: The schema of the table base (``table``).
TABLE_SCHEMA = Schema(
    params={
        "extrapolation": string(("linear", "clamp")),
        "max_gp_points": integer(3),
        "n_restarts": integer(0),
        "seed": integer(0),
    },
    state={
        "n_features_in_": integer(2),
        "feature_names_in_": array("str", 1),
        "designs_": array(_FLOAT, 2),
        "curve_offsets_": array(_INT, 1, low=0),
        "curve_pressures_": array(_FLOAT, 1),
        "curve_angles_": array(_FLOAT, 1),
        "x_mean_": array(_FLOAT, 1),
        "x_scale_": array(_FLOAT, 1, low=0.0, strict=True),
        "kernel_theta_": array(_FLOAT, 1),
        "gp_inputs_": array(_FLOAT, 2),
        "gp_targets_": array(_FLOAT, 1),
    },
    check=_check_table,
    inputs=_check_inputs,
)

#: The schema of the XGBoost family (``xgb``): its codec reads the parameters.
XGBOOST_SCHEMA = Schema(params=None, state={"booster": _booster}, inputs=_check_booster_inputs)

#: The schemas of the surrogates built on other surrogates, by kind.
COMPOSITE_SCHEMAS: dict[str, Schema] = {
    "affine-corrected": Schema(
        params={},
        state={
            "base": _document,
            "scale_": real(),
            "offset_": real(),
            "residual_std_": real(low=0.0),
        },
        check=_check_affine,
    ),
    "gp-corrected": Schema(
        params={},
        state={
            "base": _document,
            "z_mean_": array(_FLOAT, 1),
            "z_scale_": array(_FLOAT, 1, low=0.0, strict=True),
            "kernel_theta_": array(_FLOAT, 1),
            "inputs_": array(_FLOAT, 2),
            "targets_": array(_FLOAT, 1),
        },
        inputs=_check_gp,
    ),
    "ensemble": Schema(
        params={},
        state={"members": _documents, "residual_std_": real(low=0.0)},
        check=_check_residual_std,
    ),
    "pressure-scaled": Schema(
        params={},
        state={
            "base": _document,
            "scale_": real(low=0.0, strict=True),
            "residual_std_": real(low=0.0),
        },
        check=_check_residual_std,
    ),
}
