"""The registered strategies and how a run chooses, builds and fits them."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from softbend._validation import check_int
from softbend.errors import InputError, keyed
from softbend.parameters import declared_ranges
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.strategies.baselines import AnalyticalBaseline, BaseMeanResidual, BaseOnly
from softbend.transfer.strategies.common import (
    STRATEGIES,
    _Strategy,
    base_family,
)
from softbend.transfer.strategies.corrections import PressureScale, ResidualGP, ScaleOffset
from softbend.transfer.strategies.networks import (
    ExperimentalMLP,
    RefinedEnsemble,
    RefinedMLP,
    ScaledRefinedMLP,
)
from softbend.transfer.strategies.parameters import (
    check_parameters,
    describe_range,
    parameter_defaults,
    takes,
)

if TYPE_CHECKING:
    from softbend.actuators import Actuator
    from softbend.transfer.measurements import ActuatorMeasurements, Measurements


for _name, _cls in (
    ("fem-only", BaseOnly),
    ("base-mean-residual", BaseMeanResidual),
    ("analytical", AnalyticalBaseline),
    ("experimental", ExperimentalMLP),
    ("refined", RefinedMLP),
    ("scale-offset", ScaleOffset),
    ("pressure-scale", PressureScale),
    ("residual-gp", ResidualGP),
    ("refined-ensemble", RefinedEnsemble),
    ("scaled-refined", ScaledRefinedMLP),
):
    STRATEGIES.register(_name, _cls)
del _name, _cls

#: softbend's own strategies, in the order of the tables (those registered later are not).
BUILTIN_STRATEGIES: tuple[str, ...] = STRATEGIES.names()


def strategy_parameters(name: str) -> dict[str, Any]:
    """The parameters a user may set on strategy ``name``, with their defaults.

    Raises
    ------
    UnknownNameError
        An unknown name (listing :data:`STRATEGIES`).
    """
    with keyed("name"):
        return parameter_defaults(STRATEGIES.get(name))


def learns(name: str) -> bool:
    """Whether strategy ``name`` learns a model from the measurements (a baseline does not)."""
    with keyed("name"):
        return bool(getattr(STRATEGIES.get(name), "learns", True))


def strategy_refusal(name: str, base: object, actuator: Actuator | None = None) -> str | None:
    """Why strategy ``name`` cannot start from ``base`` (a model of ``actuator``); None if it can.

    Asks the strategy's class (its ``refusal(base, actuator)`` class method; a
    registered class without one takes any base). ``actuator`` defaults to
    paper B's.
    """
    from softbend.actuators import SFRBA

    with keyed("name"):
        cls = STRATEGIES.get(name)
    refusal = getattr(cls, "refusal", None)
    return refusal(base, actuator or SFRBA) if callable(refusal) else None


def applicable_strategies(
    names: Sequence[str], base: object, actuator: Actuator | None = None
) -> tuple[list[str], dict[str, str]]:
    """The strategies of ``names`` that can start from ``base``, and why the others cannot.

    Returns
    -------
    list of str
        The names that apply, in the order given.
    dict of str to str
        Each name left out → its reason (:func:`strategy_refusal`).
    """
    kept, left_out = [], {}
    for name in names:
        reason = strategy_refusal(name, base, actuator)
        if reason is None:
            kept.append(name)
        else:
            left_out[name] = reason
    return kept, left_out


def check_applicable(
    names: Sequence[str],
    base: object,
    actuator: Actuator | None = None,
    *,
    among: Sequence[str] | None = None,
    key: str = "strategies",
) -> None:
    """Refuse, before any work, a strategy of ``names`` that cannot start from ``base``.

    Parameters
    ----------
    names : sequence of str
        The strategies asked for.
    base : estimator or None
        The base surrogate.
    actuator : Actuator, optional
        What ``base`` is a model of (paper B's actuator by default).
    among : sequence of str, optional
        The strategies the message offers instead, those of them that apply
        (default: every registered strategy).
    key : str, default "strategies"
        The parameter the error names.

    Raises
    ------
    InputError
        Keyed ``key``: the first strategy that cannot, with its reason, the
        base's family and the strategies that apply to it.
    """
    for name in names:
        reason = strategy_refusal(name, base, actuator)
        if reason is None:
            continue
        fits, _ = applicable_strategies(
            STRATEGIES.names() if among is None else among, base, actuator
        )
        raise InputError(
            f"{name!r} {reason}; the strategies that apply to this {base_family(base)} base: "
            f"{', '.join(fits) or 'none'}",
            key=key,
        )


def describe_strategies() -> list[dict[str, Any]]:
    """Every registered strategy, in order: what it is and what a user may set.

    Returns
    -------
    list of dict
        ``name``; ``summary`` (the first line of its class's docstring, as text);
        ``parameters`` (``{name: default}``, see :func:`strategy_parameters`);
        ``ranges`` (``{name: range}`` of the parameters that declare one, as
        text, e.g. ``"(0, 1] ..."``); ``uses_base`` (starts from the base
        surrogate); ``learns`` (fits a model that ``softbend transfer refine``
        saves); ``interval`` (gives prediction intervals).
    """
    rows = []
    for name, cls in STRATEGIES.items():
        doc = (cls.__doc__ or "").strip()
        defaults = parameter_defaults(cls)
        rows.append(
            {
                "name": name,
                "summary": doc.splitlines()[0].replace("``", "") if doc else cls.__name__,
                "parameters": defaults,
                "ranges": {
                    key: describe_range(cls, key) for key in declared_ranges(cls) if key in defaults
                },
                "uses_base": takes(cls, "base"),
                "learns": learns(name),
                "interval": callable(getattr(cls, "predict_interval", None)),
            }
        )
    return rows


def make_strategy(
    name: str,
    base: Surrogate | None = None,
    *,
    seed: int = 0,
    actuator: Actuator | None = None,
    **options: object,
) -> Any:
    """A fresh, unfitted strategy by name.

    Parameters
    ----------
    name : str
        One of :data:`STRATEGIES`.
    base : estimator, optional
        The simulation-trained surrogate (not used by ``analytical`` and
        ``experimental``).
    seed : int, default 0
        Seed of the strategy's random choices, >= 0.
    actuator : Actuator, optional
        The actuator of the readings it will fit (their inputs, the plausible range
        of their pressure); default paper B's.
    **options
        Parameters of the strategy (e.g. ``epochs``; see :func:`strategy_parameters`),
        each held to its declared range.

    Raises
    ------
    UnknownNameError
        An unknown name (key ``name``, listing :data:`STRATEGIES`), or a
        parameter the strategy does not take (key ``options``, listing those it takes).
    ValueError
        A value of the wrong kind or outside its declared range (key
        ``options``: :class:`~softbend.parameters.ParameterValueError`), or a
        negative seed (key ``seed``).
    """
    with keyed("name"):
        cls = STRATEGIES.get(name)
    with keyed("options"):
        options = check_parameters(cls, options)
    if takes(cls, "seed"):
        seed = check_int(seed, "seed", low=0)
    filled = {"base": base, "seed": seed, "actuator": actuator}
    return cls(**{k: v for k, v in filled.items() if takes(cls, k)}, **options)


def fit_strategy(
    name: str,
    base: Surrogate | None,
    measurements: Measurements | ActuatorMeasurements,
    *,
    seed: int = 0,
    epochs: int | None = None,
    **options: object,
) -> _Strategy:
    """:func:`make_strategy` fitted on all of ``measurements`` (a :class:`Measurements`).

    ``epochs`` (None: the strategy's default) is passed on with the other options.
    """
    if epochs is not None:
        options["epochs"] = epochs
    actuator = getattr(measurements, "actuator", None)  # paper B's Measurements: None
    strategy: _Strategy = make_strategy(name, base, seed=seed, actuator=actuator, **options)
    strategy.fit(measurements.features, measurements.angle_deg)
    return strategy


def has_interval(estimator: object) -> bool:
    """Whether the strategy gives prediction intervals."""
    return callable(getattr(estimator, "predict_interval", None))
