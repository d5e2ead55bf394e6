"""Leave-one-experiment-out identification of the curling actuator (paper A §4).

For each pressure sign (positive, negative) and each output (bending grade ρ,
arc length L in mm) a :class:`~softbend.identification.narx.NARXRegressor` with
the generalized-Gaussian SVR is fitted. Its honesty comes from the evaluation:
every experiment is predicted by a model that never saw it (trained on the
other experiments of the same sign), one step ahead (measured past outputs) and
in free run (the model's own past outputs). The final models, saved for use,
are then fitted on all experiments of a sign.

The initial conditions (the first ``max_lag`` samples of each experiment) are
measured values in both prediction modes, so they are excluded from the metrics.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import pandas as pd

from softbend._validation import check_choice
from softbend.errors import ConvergenceError, DatasetError
from softbend.identification.data import Experiment
from softbend.identification.kernels import MOMENTS_OF, ShapeClippedWarning
from softbend.identification.narx import NARXRegressor
from softbend.identification.ranges import check_lags_fit, check_settings
from softbend.metrics import regression_metrics

if TYPE_CHECKING:
    from softbend.identification.svr import GeneralizedGaussianSVR

logger = logging.getLogger(__name__)

#: The identified outputs: bending grade ρ (dimensionless) and arc length L (mm).
OUTPUTS: tuple[str, ...] = ("rho", "length_mm")
SIGNS: tuple[str, ...] = ("positive", "negative")
MODES: tuple[str, ...] = ("one-step", "free-run")
#: Samples each experiment must hold after its initial conditions: the kernel's width
#: and shape are estimated from at least 4 regressor rows.
MIN_PREDICTED = 4


@dataclass(frozen=True)
class IdentificationConfig:
    """Settings of the NARX/GG-SVR identification (defaults: paper A).

    Parameters
    ----------
    C : float
        SVR penalty (paper A calls it γ), in (0, 1e4]. Default 100.
    epsilon : float
        Width of the ε-insensitive tube in units of the standardized target, in
        [0, 10]. Default 0.1.
    output_lags, input_lags : int
        Number of past outputs and of inputs in the regressor, each in [1, 50];
        the defaults give φ(t) = [y(t−1), y(t−2), u(t), u(t−1)] (paper A eq. 27).
        The ranges are those of :mod:`softbend.identification.ranges`.
    kernel : {"moments", "cv"}
        How σ and the shape γ of the kernel are chosen: ``"moments"`` estimates
        them from the standardized regressors by the fourth-moment method (paper
        A); ``"cv"`` picks them by grouped cross-validation of the one-step error
        over a small grid (experiments never split across folds).
    moments_of : {"differences", "regressors", "components"}
        What the fourth-moment method measures with ``kernel="moments"``: the
        kernel's argument x − z over all pairs of training rows (default), the
        centred regressor vectors, or the pooled standardized components (the
        earlier behaviour); see :mod:`softbend.identification.kernels`.
    """

    C: float = 100.0
    epsilon: float = 0.1
    output_lags: int = 2
    input_lags: int = 2
    kernel: Literal["moments", "cv"] = "moments"
    moments_of: Literal["differences", "regressors", "components"] = "differences"

    def __post_init__(self) -> None:
        check_settings(
            C=self.C, epsilon=self.epsilon, output_lags=self.output_lags, input_lags=self.input_lags
        )
        check_choice(self.kernel, "kernel", ("moments", "cv"))
        check_choice(self.moments_of, "moments_of", MOMENTS_OF)


@dataclass
class IdentificationResult:
    """Everything the identification produced.

    Attributes
    ----------
    metrics : pandas.DataFrame
        One row per (sign, output, held-out experiment, mode) with ``rmse``,
        ``nrmse`` (RMSE / range of the measured output), ``r2`` and ``fit_percent``.
    predictions : dict
        ``{(sign, output, experiment): {"one-step": array, "free-run": array}}``:
        held-out predictions, full length (initial conditions measured).
    models : dict
        ``{(sign, output): NARXRegressor}`` fitted on all experiments of the sign.
    experiments : dict
        ``{sign: [Experiment, ...]}`` as used.
    config : IdentificationConfig
    kernel_params : dict
        ``{(sign, output): {...}}`` of the final models: ``sigma``, ``shape``,
        ``n_support``; ``shape_source`` ("moments" or "cv"); ``shape_clipped``
        (True when the moment estimate asked for a shape above 2, regressors
        flatter than Gaussian, and 2 was used); ``moments_of``, ``kurtosis`` and
        ``gaussian_kurtosis`` (the measured fourth-moment ratio and its value for
        Gaussian data; None with "cv"); and ``shape_reason``, one sentence saying
        why the shape is what it is.
    """

    metrics: pd.DataFrame
    predictions: dict[tuple[str, str, str], dict[str, np.ndarray]]
    models: dict[tuple[str, str], NARXRegressor]
    experiments: dict[str, list[Experiment]]
    config: IdentificationConfig
    kernel_params: dict[tuple[str, str], dict[str, Any]] = field(default_factory=dict)

    def summary(self) -> pd.DataFrame:
        """Mean and worst metrics over held-out experiments per sign, output and mode."""
        grouped = self.metrics.groupby(["sign", "output", "mode"], sort=False)
        summary = grouped.agg(
            nrmse_mean=("nrmse", "mean"),
            nrmse_max=("nrmse", "max"),
            rmse_mean=("rmse", "mean"),
            r2_mean=("r2", "mean"),
            fit_percent_mean=("fit_percent", "mean"),
            n_experiments=("experiment", "count"),
        )
        return summary.reset_index()


def output_values(experiment: Experiment, output: str) -> np.ndarray:
    """The measured output series ``output`` ("rho" or "length_mm") of an experiment."""
    check_choice(output, "output", OUTPUTS)
    return np.asarray(getattr(experiment, output), dtype=float)


def split_by_sign(experiments: Sequence[Experiment]) -> dict[str, list[Experiment]]:
    """Group experiments by the sign of their pressure (positive / negative)."""
    groups: dict[str, list[Experiment]] = {}
    for experiment in experiments:
        groups.setdefault(experiment.sign, []).append(experiment)
    return {sign: groups[sign] for sign in SIGNS if sign in groups}


def _stack(experiments: Sequence[Experiment], output: str):
    u = np.concatenate([e.pressure_kpa for e in experiments])
    y = np.concatenate([output_values(e, output) for e in experiments])
    groups = np.concatenate([np.full(e.n_samples, i) for i, e in enumerate(experiments)])
    return u.reshape(-1, 1), y, groups


def _make_model(config: IdentificationConfig, sigma: float | None, shape: float | None):
    from softbend.identification.svr import GeneralizedGaussianSVR

    svr = GeneralizedGaussianSVR(
        C=config.C,
        epsilon=config.epsilon,
        sigma=sigma,
        shape=shape,
        moments_of=config.moments_of,
    )
    return NARXRegressor(
        estimator=svr, output_lags=config.output_lags, input_lags=config.input_lags
    )


#: Grid of the cross-validated kernel choice (standardized regressors, so σ is in std units).
CV_GRID: dict[str, tuple[float, ...]] = {
    "sigma": (0.5, 1.0, 2.0, 4.0),
    "shape": (1.0, 1.5, 2.0),
}


def select_kernel_by_cv(
    experiments: Sequence[Experiment], output: str, config: IdentificationConfig
) -> dict[str, float]:
    """Choose (σ, γ) on :data:`CV_GRID` by leave-one-experiment-out one-step RMSE."""
    best: tuple[float, dict[str, float]] | None = None
    for sigma in CV_GRID["sigma"]:
        for shape in CV_GRID["shape"]:
            errors = []
            for k in range(len(experiments)):
                train = [e for i, e in enumerate(experiments) if i != k]
                u_train, y_train, g_train = _stack(train, output)
                model = _make_model(config, sigma, shape).fit(u_train, y_train, groups=g_train)
                u, y, groups = _stack([experiments[k]], output)
                y_hat = model.predict_one_step(u, y, groups=groups)
                errors.append(np.sqrt(np.mean((y_hat - y)[model.max_lag_ :] ** 2)))
            score = float(np.mean(errors))
            if best is None or score < best[0]:
                best = (score, {"sigma": sigma, "shape": shape})
    return best[1] if best is not None else {"sigma": 1.0, "shape": 2.0}


def _kernel_report(svr: GeneralizedGaussianSVR, config: IdentificationConfig) -> dict[str, Any]:
    """Kernel of a fitted final model and why it has its shape (``kernel_params`` entry)."""
    estimate = svr.shape_estimate_ if config.kernel == "moments" else None
    if estimate is not None:
        reason = estimate.reason
    else:
        grid = ", ".join(
            f"{k} in {{{', '.join(f'{v:g}' for v in vs)}}}" for k, vs in CV_GRID.items()
        )
        reason = (
            f"chosen by leave-one-experiment-out cross-validation of the one-step RMSE over {grid}"
        )
    return {
        "sigma": float(svr.sigma_),
        "shape": float(svr.shape_),
        "shape_source": config.kernel,
        "shape_clipped": bool(estimate is not None and estimate.clipped),
        "moments_of": None if estimate is None else estimate.moments_of,
        "kurtosis": None if estimate is None else float(estimate.kurtosis),
        "gaussian_kurtosis": None if estimate is None else float(estimate.gaussian_kurtosis),
        "shape_reason": reason,
        "n_support": len(svr.dual_coef_),
    }


def check_experiments(
    experiments: Sequence[Experiment],
    config: IdentificationConfig,
) -> None:
    """Refuse, before any fit, experiments :func:`identify` cannot score.

    Parameters
    ----------
    experiments : sequence of Experiment
        The experiments.
    config : IdentificationConfig
        The settings.

    Raises
    ------
    DatasetError
        No experiments, a pressure sign with a single experiment (nothing to
        hold out), or an experiment whose ρ or L is constant: each experiment is
        held out and scored by its error over its range (NRMSE) and by R², which
        a constant output leaves undefined.
    ValueError
        Lags that leave the shortest experiment fewer than :data:`MIN_PREDICTED`
        samples to predict (naming the setting, its range for these experiments
        and the experiment).
    """
    by_sign = split_by_sign(experiments)
    if not by_sign:
        raise DatasetError("No experiments to identify from.")
    for sign, group in by_sign.items():
        if len(group) < 2:
            raise DatasetError(
                f"Leave-one-experiment-out needs at least 2 {sign}-pressure experiments. "
                f"Got {len(group)}."
            )
    shortest = min(experiments, key=lambda e: e.n_samples)
    check_lags_fit(
        config.output_lags,
        config.input_lags,
        (shortest.name, shortest.n_samples),
        predicted=MIN_PREDICTED,
    )
    for experiment in experiments:
        for output in OUTPUTS:
            values = output_values(experiment, output)
            if np.ptp(values) == 0:
                raise DatasetError(
                    f"Experiment {experiment.name!r} has a constant {output} (every "
                    f"sample {float(values[0]):g}): held out, its error over its range (NRMSE) "
                    "and its R² are undefined; leave it out or record it moving."
                )


def identify(
    experiments: Sequence[Experiment],
    config: IdentificationConfig | None = None,
    *,
    progress: Callable[[str], None] | None = None,
) -> IdentificationResult:
    """Identify ρ and L models per pressure sign with leave-one-experiment-out evaluation.

    Parameters
    ----------
    experiments : sequence of Experiment
        Measured (or synthetic) experiments; each sign present needs at least two.
    config : IdentificationConfig, optional
        Defaults to paper A's settings.
    progress : callable, optional
        Called with a short label after each model fit.

    Returns
    -------
    IdentificationResult
        Every figure of its metrics finite.

    Raises
    ------
    DatasetError, ValueError
        Experiments :func:`check_experiments` refuses (before any fit).
    ConvergenceError
        A held-out free run that diverged (its figures would not be finite).
    """
    config = config or IdentificationConfig()
    check_experiments(experiments, config)
    by_sign = split_by_sign(experiments)
    rows: list[dict[str, object]] = []
    predictions: dict[tuple[str, str, str], dict[str, np.ndarray]] = {}
    models: dict[tuple[str, str], NARXRegressor] = {}
    kernel_params: dict[tuple[str, str], dict[str, Any]] = {}
    for sign, group in by_sign.items():
        for output in OUTPUTS:
            sigma: float | None
            shape: float | None
            if config.kernel == "cv":
                chosen = select_kernel_by_cv(group, output, config)
                sigma, shape = chosen["sigma"], chosen["shape"]
            else:
                sigma = shape = None
            for k, held_out in enumerate(group):
                train = [e for i, e in enumerate(group) if i != k]
                u_train, y_train, g_train = _stack(train, output)
                with warnings.catch_warnings():
                    # Reported once, for the final model, in kernel_params.
                    warnings.simplefilter("ignore", ShapeClippedWarning)
                    model = _make_model(config, sigma, shape).fit(u_train, y_train, groups=g_train)
                u, y, groups = _stack([held_out], output)
                one_step = model.predict_one_step(u, y, groups=groups)
                with warnings.catch_warnings():
                    # A diverged run is the error below, not a warning besides.
                    warnings.simplefilter("ignore", RuntimeWarning)
                    free_run = model.simulate(u, y, groups=groups)
                predictions[(sign, output, held_out.name)] = {
                    "one-step": one_step,
                    "free-run": free_run,
                }
                start = model.max_lag_
                for mode, y_hat in (("one-step", one_step), ("free-run", free_run)):
                    scores = regression_metrics(y[start:], y_hat[start:])
                    if not all(np.isfinite(v) for v in scores.values()):
                        raise ConvergenceError(
                            f"The {mode} prediction of {output} of the {sign}-pressure "
                            f"experiment {held_out.name!r} (held out) is not finite: the "
                            "model diverged and its figures would be NaN. A smaller C or "
                            "fewer lags may keep it stable."
                        )
                    rows.append(
                        {
                            "sign": sign,
                            "output": output,
                            "experiment": held_out.name,
                            "mode": mode,
                            **scores,
                        }
                    )
                if progress is not None:
                    progress(f"{sign} {output} held-out {held_out.name}")
            u_all, y_all, g_all = _stack(group, output)
            with warnings.catch_warnings():
                # Reported once, in kernel_params, with the reason.
                warnings.simplefilter("ignore", ShapeClippedWarning)
                final = _make_model(config, sigma, shape).fit(u_all, y_all, groups=g_all)
            models[(sign, output)] = final
            report = _kernel_report(final.estimator_, config)
            kernel_params[(sign, output)] = report
            logger.info("fitted %s %s: %s", sign, output, report)
            if progress is not None:
                progress(f"{sign} {output} final model")
    metrics = pd.DataFrame(rows)
    return IdentificationResult(
        metrics=metrics,
        predictions=predictions,
        models=models,
        experiments=by_sign,
        config=config,
        kernel_params=kernel_params,
    )


def n_fits(experiments: Sequence[Experiment], config: IdentificationConfig | None = None) -> int:
    """Number of ``progress`` calls :func:`identify` will make (for progress bars)."""
    by_sign = split_by_sign(experiments)
    return sum(len(OUTPUTS) * (len(group) + 1) for group in by_sign.values())
