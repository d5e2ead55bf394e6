"""Ways to correct a simulation-trained surrogate with a few measurements (paper B §4.2).

Every strategy is a scikit-learn regressor on the rows of
:data:`softbend.design.FEATURES` (mm, deg, MPa) → bending angle (degrees) that
starts from a fitted *base* surrogate (any estimator with ``predict``; the MLP
trained on the FEM dataset by default):

======================  ============================================================
``fem-only``            the base, unchanged (paper B's "NMLPR"), a baseline
``base-mean-residual``  the base frozen, plus the measured actuators' mean residual as
                        a function of pressure alone: the baseline every strategy is
                        judged against (it knows nothing of the design)
``analytical``          the analytical model of the actuator, a baseline (no base)
``refined``             paper B's refined MLP: every layer trained further from the
                        base's weights on the measurements, input scaling kept
``experimental``        paper B's experimental MLP: from scratch, measurements only
``residual-gp``         the base frozen, a Gaussian process on its error with a
                        noise term; gives prediction intervals
``scale-offset``        the base frozen, ``θ = a·θ_base + c`` by least squares
``pressure-scale``      the base frozen and asked at ``s·p``: one number for an
                        elastomer softer or stiffer than the simulated one
                        (:mod:`softbend.transfer.pressure_map`); gives intervals
``refined-ensemble``    refined MLPs on bootstrap draws of the measured
                        actuators; mean, and an interval from their spread
``scaled-refined``      the pressure scale fitted first and folded into the MLP,
                        then paper B's refinement from that start
======================  ============================================================

Strategies with intervals have ``predict_interval(X, level)``.

Every numeric parameter declares the range it accepts beside its class
(:func:`~softbend.parameters.declare_ranges`; the table of the guarantees page
lists them): ``--set``, a Python option or a strategy built directly is held to
it before any work. A network whose training diverges anyway (non-finite
losses, or angles no actuator reaches on its own training rows) is a
:class:`~softbend.errors.ConvergenceError`, never a saved model.

:data:`STRATEGIES` maps each name to its class; one call adds a strategy, from
inside softbend or outside it, and every command and report then knows it::

    STRATEGIES.register("my-strategy", MyStrategy)
    # softbend transfer refine BASE.json lab.csv --out m.json --strategy my-strategy

A strategy class is a scikit-learn regressor on the rows above. Its
constructor's ``base`` and ``seed``, if it takes them, are filled by the library;
its other parameters, with defaults, are the ones a user sets
(:mod:`softbend.transfer.strategies.parameters`: ``--set NAME=VALUE``). ``fit(X, y)`` sets
``model_``, the surrogate that ``softbend transfer refine`` saves; a class whose
``learns`` is False (a baseline) has nothing to save. A class method
``refusal(base, actuator)`` says why the strategy cannot start from a base (the
network strategies need an ``mlp``; ``analytical``, paper B's actuator), or None
when it can: the default runs leave such a strategy out and say why
(:func:`applicable_strategies`), and a run that names it is refused before any
work (:func:`check_applicable`). A class without one takes any base.

One module per family of strategies: :mod:`~softbend.transfer.strategies.baselines`
(nothing learned), :mod:`~softbend.transfer.strategies.corrections` (the base frozen
and corrected) and :mod:`~softbend.transfer.strategies.networks` (a network trained);
:mod:`~softbend.transfer.strategies.common` holds the registry and the base class,
:mod:`~softbend.transfer.strategies.choice` the registered strategies and how a run
chooses, builds and fits them. Every public name is importable from this package.
"""

from __future__ import annotations

from softbend.transfer.strategies.baselines import AnalyticalBaseline, BaseMeanResidual, BaseOnly
from softbend.transfer.strategies.choice import (
    BUILTIN_STRATEGIES,
    applicable_strategies,
    check_applicable,
    describe_strategies,
    fit_strategy,
    has_interval,
    learns,
    make_strategy,
    strategy_parameters,
    strategy_refusal,
)
from softbend.transfer.strategies.common import (
    FIT_ERRORS,
    NETWORK_STRATEGIES,
    STRATEGIES,
    base_family,
)
from softbend.transfer.strategies.corrections import PressureScale, ResidualGP, ScaleOffset
from softbend.transfer.strategies.networks import (
    ExperimentalMLP,
    RefinedEnsemble,
    RefinedMLP,
    ScaledRefinedMLP,
)

__all__ = [
    "BUILTIN_STRATEGIES",
    "FIT_ERRORS",
    "NETWORK_STRATEGIES",
    "STRATEGIES",
    "AnalyticalBaseline",
    "BaseMeanResidual",
    "BaseOnly",
    "ExperimentalMLP",
    "PressureScale",
    "RefinedEnsemble",
    "RefinedMLP",
    "ResidualGP",
    "ScaleOffset",
    "ScaledRefinedMLP",
    "applicable_strategies",
    "base_family",
    "check_applicable",
    "describe_strategies",
    "fit_strategy",
    "has_interval",
    "learns",
    "make_strategy",
    "strategy_parameters",
    "strategy_refusal",
]
