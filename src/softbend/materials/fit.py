"""Least-squares fits of the hyperelastic models to uniaxial tension data (paper B §3.1).

Each model's nominal stress in incompressible uniaxial tension,
:meth:`~softbend.materials.models.HyperelasticModel.uniaxial_nominal_stress_mpa`,
is fitted to measured nominal (engineering) stress by ordinary least squares in
MPa, with :func:`scipy.optimize.least_squares` (trust-region reflective, bounds
below). With ``g = 2(λ − λ⁻²)`` and ``d = I1 − 3 = λ² + 2/λ − 3``:

* neo-Hookean ``P = C10·g`` and Yeoh ``P = C10·g + C20·2gd + C30·3gd²`` are linear
  in their constants. The unconstrained optimum comes from a linear least-squares
  solve (columns scaled to unit norm: at λ ≈ 8 the ``d²`` column is ~10⁴ times
  the ``g`` column) and starts ``least_squares``, which only has work to do if the
  bound ``C10 > 0`` is active.
* Arruda–Boyce ``P = μ·g·Σ i·Ci·λm^(2−2i)·I1^(i−1)`` is linear in ``μ`` for a
  fixed locking stretch ``λm``. The start is the best ``(μ, λm)`` of a log-spaced
  ``λm`` grid with ``μ`` solved in closed form at each node; then both are
  refined with the bounds ``μ > 0`` and ``1 < λm ≤ 1000``. At ``λm = 1000`` the
  model is neo-Hookean to within ~10⁻⁶ relative; a fit that ends there means the
  data show no chain locking (logged as a warning).

Metrics over the points used: ``R² = 1 − Σ(P − P̂)² / Σ(P − P̄)²`` and
``RMSE = sqrt(mean((P − P̂)²))`` in MPa. Being unweighted in MPa, the fit is
dominated by the high-stress points near failure; ``max_stretch`` restricts it to
the working range of an actuator instead.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from softbend import metrics
from softbend._jsontext import check_nesting
from softbend._validation import (
    check_finite_array,
    check_object_keys,
    check_range,
    must_be,
)
from softbend.errors import (
    ConvergenceError,
    DatasetError,
    InputError,
    SchemaError,
    keyed,
)
from softbend.limits import check_file_size
from softbend.materials.models import (
    _AB_COEFFS,
    MODELS,
    ArrudaBoyce,
    HyperelasticModel,
    NeoHookean,
    Yeoh,
)
from softbend.materials.tensile import TensileTest
from softbend.plausibility import RANGES, implausible_index
from softbend.registry import Registry

__all__ = [
    "DEFAULT_MODELS",
    "FIT_FILE_KEYS",
    "LAMBDA_M_MAX",
    "MIN_FIT_POINTS",
    "FitResult",
    "fit_file_payload",
    "fit_model",
    "fit_models",
    "load_fit_json",
]

logger = logging.getLogger(__name__)

#: The three models of paper B §3.1, in the order they are fitted by default.
DEFAULT_MODELS: tuple[str, ...] = ("neo-hookean", "yeoh", "arruda-boyce")
#: Fewest points a fit may use.
MIN_FIT_POINTS = 5
#: Upper bound of the Arruda–Boyce locking stretch in the fit (neo-Hookean limit).
LAMBDA_M_MAX = 1e3
#: Lower bounds of the strictly positive moduli (C10, μ) in MPa.
_MODULUS_FLOOR_MPA = 1e-12
#: Lower bound of λm (the model requires λm > 1).
_LAMBDA_M_FLOOR = 1.0 + 1e-6
_TOL = 1e-12


@dataclass(frozen=True)
class FitResult:
    """A hyperelastic model fitted to uniaxial tension data, with its goodness of fit.

    Parameters
    ----------
    model : HyperelasticModel
        The fitted model (constants in MPa).
    r2 : float
        Coefficient of determination over the points used, ``1 − SS_res/SS_tot``;
        NaN if the stresses are all equal.
    rmse_mpa : float
        Root-mean-square error of the nominal stress over the points used, MPa.
    n_points : int
        Number of points used.
    stretch_range : tuple of float
        Smallest and largest stretch used, dimensionless.
    at_bound : tuple of str, optional
        Parameters that ended on a bound of the fit (e.g. ``("lambda_m",)``).
    """

    model: HyperelasticModel
    r2: float
    rmse_mpa: float
    n_points: int
    stretch_range: tuple[float, float]
    at_bound: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.model, HyperelasticModel):
            raise InputError(f"must be a HyperelasticModel; got {self.model!r}", key="model")
        object.__setattr__(self, "r2", float(self.r2))
        object.__setattr__(
            self,
            "rmse_mpa",
            check_range(self.rmse_mpa, "rmse_mpa", low=0.0, low_inclusive=True),
        )
        object.__setattr__(self, "stretch_range", tuple(float(s) for s in self.stretch_range))
        object.__setattr__(self, "at_bound", tuple(self.at_bound))

    @property
    def name(self) -> str:
        """Registry name of the fitted model (``"yeoh"`` ...)."""
        return self.model.name

    @property
    def parameters(self) -> dict[str, float]:
        """Fitted constants by field name (``c10_mpa`` ... in MPa, ``lambda_m`` dimensionless)."""
        params = self.model.to_dict()
        params.pop("model")
        return {k: float(v) for k, v in params.items()}

    def predict(self, stretch: ArrayLike) -> np.ndarray:
        """Nominal stress of the fitted model at ``stretch``, MPa."""
        return self.model.uniaxial_nominal_stress_mpa(stretch)

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly summary: model name, parameters, metrics and the range used."""
        return {
            "model": self.name,
            "parameters": self.parameters,
            "initial_shear_modulus_mpa": self.model.initial_shear_modulus_mpa,
            "r2": self.r2,
            "rmse_mpa": self.rmse_mpa,
            "n_points": self.n_points,
            "stretch_min": self.stretch_range[0],
            "stretch_max": self.stretch_range[1],
            "at_bound": list(self.at_bound),
        }

    @classmethod
    def from_dict(cls, data: object) -> FitResult:
        """Rebuild a result written by :meth:`to_dict` (an entry of ``fit.json``).

        Every key and value is checked first: the keys of :meth:`to_dict` and no
        other, a registered model, its constants as
        :meth:`HyperelasticModel.from_dict` checks them (finite; in MPa, a
        plausible material constant), ``initial_shear_modulus_mpa`` equal to the
        model's, ``r2`` a number ≤ 1 or null (JSON's NaN), ``rmse_mpa`` a plausible
        stress ≥ 0, ``n_points`` an integer ≥ :data:`MIN_FIT_POINTS`, the
        stretch range finite, positive and ordered, ``at_bound`` among the
        constants' names.

        Parameters
        ----------
        data : mapping
            One fit, as :meth:`to_dict` writes it.

        Raises
        ------
        SchemaError
            Keyed by the entry at fault (``"r2"``, ``"parameters.c10_mpa"``): what
            is allowed and the value.
        """
        try:
            return _fit_from_dict(data)
        except InputError as exc:  # a constant out of its model's range
            key = f"parameters.{exc.key}" if exc.key else "parameters"
            raise SchemaError(exc.detail, key=key) from None


#: Keys of the ``fit.json`` file that ``softbend materials fit`` writes.
FIT_FILE_KEYS: tuple[str, ...] = ("test", "max_stretch", "fits", "best_model", "files")
_FIT_KEYS: tuple[str, ...] = (
    "model",
    "parameters",
    "initial_shear_modulus_mpa",
    "r2",
    "rmse_mpa",
    "n_points",
    "stretch_min",
    "stretch_max",
    "at_bound",
)


def _number(value: object, key: str, quantity: str | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SchemaError(must_be("a finite number", value), key=key)
    if quantity is not None and implausible_index([value], quantity) is not None:
        bounds = RANGES[quantity]
        raise SchemaError(
            must_be(
                f"a plausible {bounds.label} ({bounds.low:g} to {bounds.high:g} {bounds.unit})",
                value,
            ),
            key=key,
        )
    return float(value)


def _stretch(value: object, key: str) -> float:
    """A stretch ``1 + strain``: finite, with a plausible engineering strain."""
    stretch = _number(value, key)
    if implausible_index([stretch - 1.0], "strain") is not None:
        bounds = RANGES["strain"]
        raise SchemaError(
            must_be(
                f"a stretch whose strain (stretch - 1) is plausible "
                f"({bounds.low:g} to {bounds.high:g})",
                value,
            ),
            key=key,
        )
    return stretch


def _fit_from_dict(data: object) -> FitResult:
    entry = check_object_keys(data, "fit", _FIT_KEYS, _FIT_KEYS, SchemaError)
    name = entry["model"]
    if not isinstance(name, str) or name not in MODELS:
        raise SchemaError(must_be(f"one of {', '.join(map(repr, MODELS))}", name), key="model")
    parameters = entry["parameters"]
    if not isinstance(parameters, Mapping):
        raise SchemaError(must_be("a JSON object", parameters), key="parameters")
    try:
        model = MODELS.get(name).from_dict({"model": name, **parameters})
    except SchemaError as error:
        error.key = f"parameters.{error.key}" if error.key else "parameters"
        raise error
    shear = _number(entry["initial_shear_modulus_mpa"], "initial_shear_modulus_mpa", "modulus_mpa")
    if not math.isclose(shear, model.initial_shear_modulus_mpa, rel_tol=1e-9, abs_tol=1e-15):
        raise SchemaError(
            must_be(
                f"{model.initial_shear_modulus_mpa!r}, the initial shear modulus of its parameters",
                shear,
            ),
            key="initial_shear_modulus_mpa",
        )
    r2 = entry["r2"]
    r2 = math.nan if r2 is None else _number(r2, "r2")
    if r2 > 1.0:
        raise SchemaError(must_be("a number <= 1 or null", r2), key="r2")
    rmse = _number(entry["rmse_mpa"], "rmse_mpa", "stress_mpa")
    if rmse < 0.0:
        raise SchemaError(must_be(">= 0", rmse), key="rmse_mpa")
    n_points = entry["n_points"]
    if type(n_points) is not int or n_points < MIN_FIT_POINTS:
        raise SchemaError(must_be(f"an integer >= {MIN_FIT_POINTS}", n_points), key="n_points")
    low = _stretch(entry["stretch_min"], "stretch_min")
    high = _stretch(entry["stretch_max"], "stretch_max")
    if not 0.0 < low <= high:
        raise SchemaError(
            f"must satisfy 0 < stretch_min <= stretch_max; got {low!r} and {high!r}",
            key="stretch_max",
        )
    names = [f.name for f in fields(model)]
    at_bound = entry["at_bound"]
    if not isinstance(at_bound, list) or any(item not in names for item in at_bound):
        raise SchemaError(
            must_be(f"a list of names among {', '.join(names)}", at_bound), key="at_bound"
        )
    return FitResult(
        model=model,
        r2=r2,
        rmse_mpa=rmse,
        n_points=n_points,
        stretch_range=(low, high),
        at_bound=tuple(at_bound),
    )


def fit_file_payload(
    test: TensileTest, results: Mapping[str, FitResult], max_stretch: float | None = None
) -> dict[str, Any]:
    """The content of ``fit.json`` (:data:`FIT_FILE_KEYS` but ``files``) for fits of one test.

    Parameters
    ----------
    test : TensileTest
        The test fitted (its summary is kept).
    results : mapping of str to FitResult
        The fits, by model name (:func:`fit_models`).
    max_stretch : float, optional
        The largest stretch fitted, as given (None: all points).

    Returns
    -------
    dict
        ``test``, ``max_stretch``, ``fits`` and ``best_model``: the model with
        the highest R² (a fit whose R² is NaN never ranks; None if none ranks).
    """
    ranked = [r for r in results.values() if r.r2 == r.r2]
    return {
        "test": test.summary(),
        "max_stretch": max_stretch,
        "fits": [r.to_dict() for r in results.values()],
        "best_model": max(ranked, key=lambda r: r.r2).name if ranked else None,
    }


def load_fit_json(path: str | os.PathLike[str]) -> dict[str, FitResult]:
    """Read the ``fit.json`` that ``softbend materials fit`` writes, checked.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    dict of str to FitResult
        One result per model, in the file's order.

    Raises
    ------
    FileNotFoundError
        If ``path`` is not a file.
    LimitError
        If the file is over the ``file_mib`` limit of :mod:`softbend.limits`.
    SchemaError
        If the file is not strict JSON (a bare ``NaN`` or ``Infinity`` included),
        is nested deeper than the ``nesting`` limit of :mod:`softbend.limits`,
        has a key other than :data:`FIT_FILE_KEYS`, or a fit fails
        :meth:`FitResult.from_dict`; the one-line message names the file (its
        ``file``) and the entry at fault (``fits[0].r2 must be ...``), so that it
        survives a caller's :func:`~softbend.errors.keyed`.
    """
    file = Path(path)
    if not file.is_file():
        raise FileNotFoundError(f"No fit file at {file}.")
    check_file_size(file)

    def refuse(constant: str) -> None:
        raise SchemaError(f"{file} is not strict JSON: it holds {constant}, which JSON lacks.")

    try:
        text = file.read_text(encoding="utf-8")
        check_nesting(text, str(file), SchemaError)
        data = json.loads(text, parse_constant=refuse)
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SchemaError(f"{file} is not valid JSON: {exc}.") from None
    except RecursionError:
        raise SchemaError(f"{file} is nested too deeply to read.") from None
    with _naming_the_entry(file):
        top = check_object_keys(data, "(top level)", FIT_FILE_KEYS, ("fits",), SchemaError)
        fits = top["fits"]
        if not isinstance(fits, list) or not fits:
            raise SchemaError(must_be("a non-empty list", fits), key="fits")
        for key in ("test", "files"):
            if top.get(key) is not None and not isinstance(top[key], dict):
                raise SchemaError(must_be("a JSON object or null", top[key]), key=key)
        max_stretch = top.get("max_stretch")
        if max_stretch is not None and _stretch(max_stretch, "max_stretch") <= 1.0:
            raise SchemaError(must_be("null or > 1", max_stretch), key="max_stretch")
    results: dict[str, FitResult] = {}
    for i, entry in enumerate(fits):
        with _naming_the_entry(file, f"fits[{i}]"):
            result = FitResult.from_dict(entry)
            if result.name in results:
                raise SchemaError(f"the model {result.name!r} is fitted twice")
        results[result.name] = result
    best = top.get("best_model")
    if best is not None and (not isinstance(best, str) or best not in results):
        with _naming_the_entry(file):
            raise SchemaError(
                must_be(
                    f"null or one of the fitted models ({', '.join(map(repr, results))})", best
                ),
                key="best_model",
            )
    return results


@contextmanager
def _naming_the_entry(file: Path, entry: str = "") -> Iterator[None]:
    """Re-raise a :class:`SchemaError` of ``file`` with its entry in the message.

    The entry inside the file (``fits[0].r2``) leads the message, so that a
    caller's :func:`~softbend.errors.keyed` keeps it; the error keeps no key.
    """
    try:
        yield
    except SchemaError as error:
        where = ".".join(part for part in (entry, error.key) if part)
        raise SchemaError(
            f"{where}: {error.detail}" if where else error.detail, file=str(file)
        ) from None


def _g(lam: np.ndarray) -> np.ndarray:
    """``2(λ − λ⁻²)``: nominal stress per unit ``∂W/∂I1`` in uniaxial tension."""
    return 2.0 * (lam - lam**-2)


def _i1(lam: np.ndarray) -> np.ndarray:
    return lam**2 + 2.0 / lam


def _linear_design(model_name: str, lam: np.ndarray) -> np.ndarray:
    """Columns of the linear models: ``P = A @ constants``."""
    g = _g(lam)
    if model_name == NeoHookean.name:
        return g[:, None]
    d = _i1(lam) - 3.0
    return np.column_stack([g, 2.0 * g * d, 3.0 * g * d**2])


def _scaled_lstsq(A: np.ndarray, y: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0.0] = 1.0
    solution, *_ = np.linalg.lstsq(A / norms, y, rcond=None)
    return solution / norms


def _ab_series(lam: np.ndarray, lambda_m: float) -> tuple[np.ndarray, np.ndarray]:
    """``Σ i·Ci·λm^(2−2i)·I1^(i−1)`` and its derivative with respect to ``λm``."""
    I1 = _i1(lam)
    value = np.zeros_like(lam)
    d_value = np.zeros_like(lam)
    for i, c in enumerate(_AB_COEFFS, start=1):
        term = i * c * I1 ** (i - 1)
        value = value + term * lambda_m ** (2 - 2 * i)
        d_value = d_value + term * (2 - 2 * i) * lambda_m ** (1 - 2 * i)
    return value, d_value


def _ab_start(lam: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Best ``(μ, λm)`` on a log-spaced ``λm`` grid, ``μ`` by linear least squares."""
    g = _g(lam)
    best_cost, best = math.inf, np.array([max(float(y @ g / (g @ g)), 1.0) * 2.0, 10.0])
    for lambda_m in np.geomspace(1.01, LAMBDA_M_MAX, 241):
        basis = g * _ab_series(lam, float(lambda_m))[0]
        mu = float(basis @ y / (basis @ basis))
        if mu <= 0.0:
            continue
        residual = mu * basis - y
        cost = float(residual @ residual)
        if cost < best_cost:
            best_cost, best = cost, np.array([mu, float(lambda_m)])
    return best


@dataclass(frozen=True)
class _Problem:
    """What ``least_squares`` needs for one model."""

    names: tuple[str, ...]
    build: Callable[[np.ndarray], HyperelasticModel]
    jac: Callable[[np.ndarray], np.ndarray]
    x0: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


def _linear_problem(model_name: str, lam: np.ndarray, y: np.ndarray) -> _Problem:
    """Neo-Hookean and Yeoh: linear in their constants, started from least squares."""
    A = _linear_design(model_name, lam)
    n = A.shape[1]
    names = ("c10_mpa", "c20_mpa", "c30_mpa")[:n]
    return _Problem(
        names=names,
        build=(lambda p: NeoHookean(p[0])) if n == 1 else (lambda p: Yeoh(*p)),
        jac=lambda p: A,
        x0=_scaled_lstsq(A, y),
        lower=np.array([_MODULUS_FLOOR_MPA] + [-np.inf] * (n - 1)),
        upper=np.full(n, np.inf),
    )


def _arruda_boyce_problem(model_name: str, lam: np.ndarray, y: np.ndarray) -> _Problem:
    """Arruda–Boyce: nonlinear in the locking stretch, started from a grid (see the module)."""
    g = _g(lam)

    def jac(p: np.ndarray) -> np.ndarray:
        series, d_series = _ab_series(lam, float(p[1]))
        return np.column_stack([g * series, p[0] * g * d_series])

    return _Problem(
        names=("mu_mpa", "lambda_m"),
        build=lambda p: ArrudaBoyce(mu_mpa=p[0], lambda_m=p[1]),
        jac=jac,
        x0=_ab_start(lam, y),
        lower=np.array([_MODULUS_FLOOR_MPA, _LAMBDA_M_FLOOR]),
        upper=np.array([np.inf, LAMBDA_M_MAX]),
    )


#: How each model of :data:`~softbend.materials.models.MODELS` is fitted, by name.
_PROBLEMS: Registry[Callable[[str, np.ndarray, np.ndarray], _Problem]] = Registry("material model")
_PROBLEMS.register(NeoHookean.name, _linear_problem)
_PROBLEMS.register(Yeoh.name, _linear_problem)
_PROBLEMS.register(ArrudaBoyce.name, _arruda_boyce_problem)


def _problem(model_name: str, lam: np.ndarray, y: np.ndarray) -> _Problem:
    with keyed("model_name"):
        return _PROBLEMS.get(model_name)(model_name, lam, y)


def _check_data(stretch: ArrayLike, stress: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    lam = check_finite_array(stretch, "stretch")
    y = check_finite_array(stress, "nominal_stress_mpa")
    if lam.ndim != 1 or y.shape != lam.shape:
        raise DatasetError(
            f"must be a 1-D array of the length of 'stretch'; got shapes {lam.shape} "
            f"(stretch) and {y.shape}",
            key="nominal_stress_mpa",
        )
    bad = np.flatnonzero(lam <= 0.0)
    if bad.size:
        raise DatasetError(
            f"must be in (0, inf); got {float(lam[bad[0]])!r} at position {int(bad[0])}",
            key="stretch",
        )
    return lam, y


def _select(
    lam: np.ndarray, y: np.ndarray, max_stretch: float | None
) -> tuple[np.ndarray, np.ndarray]:
    if max_stretch is None:
        if lam.size < MIN_FIT_POINTS:
            raise DatasetError(
                must_be(f"at least {MIN_FIT_POINTS} points", lam.size), key="stretch"
            )
        return lam, y
    limit = check_range(max_stretch, "max_stretch", low=1.0)
    keep = lam <= limit
    if int(keep.sum()) < MIN_FIT_POINTS:
        raise InputError(
            f"must keep at least {MIN_FIT_POINTS} points of the data (stretch "
            f"{lam.min():.4g} to {lam.max():.4g}); got {max_stretch!r} "
            f"({int(keep.sum())} points)",
            key="max_stretch",
        )
    return lam[keep], y[keep]


def fit_model(
    model_name: str,
    stretch: ArrayLike,
    nominal_stress_mpa: ArrayLike,
    *,
    max_stretch: float | None = None,
) -> FitResult:
    """Fit one hyperelastic model to uniaxial tension data by least squares.

    Parameters
    ----------
    model_name : str
        ``"neo-hookean"``, ``"yeoh"`` (three terms) or ``"arruda-boyce"``.
    stretch : array_like
        Axial stretch ``λ = 1 + engineering strain``, dimensionless, > 0.
    nominal_stress_mpa : array_like
        Measured nominal (engineering) stress, force per undeformed area, MPa;
        same length as ``stretch``.
    max_stretch : float, optional
        Fit only the points with ``λ ≤ max_stretch`` (> 1), e.g. the working range
        of an actuator; default: all points (to failure for a pull-to-failure test).

    Returns
    -------
    FitResult
        The fitted model with R² and RMSE (MPa) over the points used.

    Raises
    ------
    ValueError
        If ``model_name`` is unknown (the message lists the allowed names) or
        ``max_stretch`` keeps fewer than :data:`MIN_FIT_POINTS` points.
    DatasetError
        If the data are not finite, not 1-D of one length, have a stretch ≤ 0 or
        fewer than :data:`MIN_FIT_POINTS` points.
    ConvergenceError
        If ``least_squares`` stops without converging or returns non-finite values.

    Notes
    -----
    Bounds: ``C10 > 0`` (neo-Hookean, Yeoh), ``μ > 0`` and ``1 < λm ≤ 1000``
    (Arruda–Boyce); ``C20`` and ``C30`` are free. See the module docstring for the
    starting points.
    """
    with keyed("model_name"):
        _PROBLEMS.check(model_name)
    lam, y = _check_data(stretch, nominal_stress_mpa)
    lam, y = _select(lam, y, max_stretch)
    problem = _problem(model_name, lam, y)
    span = problem.upper - problem.lower
    margin = np.where(np.isfinite(span), 1e-9 * span, 0.0)
    x0 = np.clip(problem.x0, problem.lower + margin, problem.upper - margin)

    def residual(p: np.ndarray) -> np.ndarray:
        return problem.build(p).uniaxial_nominal_stress_mpa(lam) - y

    solution = least_squares(
        residual,
        x0,
        jac=problem.jac,
        bounds=(problem.lower, problem.upper),
        method="trf",
        x_scale="jac",
        ftol=_TOL,
        xtol=_TOL,
        gtol=_TOL,
        max_nfev=2000,
    )
    if solution.status <= 0 or not np.all(np.isfinite(solution.x)):
        raise ConvergenceError(
            f"least_squares did not converge fitting the {model_name} model "
            f"(status {solution.status}: {solution.message}; x = {solution.x.tolist()})."
        )
    model = problem.build(solution.x)
    predicted = model.uniaxial_nominal_stress_mpa(lam)
    r2, rmse = metrics.r2(y, predicted), metrics.rmse(y, predicted)
    # trf keeps its iterates strictly feasible, so its active_mask can miss a bound
    # approached to within its step tolerance: check the distance as well.
    near = np.minimum(
        np.abs(solution.x - problem.lower), np.abs(problem.upper - solution.x)
    ) <= 1e-8 * np.maximum(1.0, np.abs(solution.x))
    at_bound = tuple(
        n
        for n, active, close in zip(problem.names, solution.active_mask, near, strict=True)
        if active or close
    )
    if at_bound:
        logger.warning(
            "%s fit: %s ended on a bound of the fit (%s)",
            model_name,
            ", ".join(at_bound),
            ", ".join(f"{n} = {v:.6g}" for n, v in zip(problem.names, solution.x, strict=True)),
        )
    logger.info(
        "%s fit over %d points: %s, R2 %.6f, RMSE %.4g MPa", model_name, lam.size, model, r2, rmse
    )
    return FitResult(
        model=model,
        r2=r2,
        rmse_mpa=rmse,
        n_points=int(lam.size),
        stretch_range=(float(lam.min()), float(lam.max())),
        at_bound=at_bound,
    )


def _stretch_and_stress(
    data: TensileTest | tuple[ArrayLike, ArrayLike],
) -> tuple[ArrayLike, ArrayLike]:
    if isinstance(data, TensileTest):
        return data.stretch, data.engineering_stress_mpa
    if isinstance(data, tuple | list) and len(data) == 2:
        return data[0], data[1]
    raise InputError(
        f"must be a TensileTest or a (stretch, nominal_stress_mpa) pair; got {type(data).__name__}",
        key="data",
    )


def fit_models(
    data: TensileTest | tuple[ArrayLike, ArrayLike],
    models: Sequence[str] | str = DEFAULT_MODELS,
    *,
    max_stretch: float | None = None,
) -> dict[str, FitResult]:
    """Fit several hyperelastic models to one uniaxial tension test.

    Parameters
    ----------
    data : TensileTest or (array_like, array_like)
        A test (its stretch ``1 + engineering strain`` and its engineering stress
        are used) or a pair ``(stretch, nominal_stress_mpa)`` (dimensionless, MPa).
    models : sequence of str or str, default ``DEFAULT_MODELS``
        Names among ``"neo-hookean"``, ``"yeoh"``, ``"arruda-boyce"``, distinct;
        a single string is one name. All are checked before any fit runs.
    max_stretch : float, optional
        Fit only the points with stretch ≤ ``max_stretch``; see :func:`fit_model`.

    Returns
    -------
    dict of str to FitResult
        One result per model, in the order of ``models``.

    Raises
    ------
    ValueError
        If ``models`` is empty, repeats a name or names an unknown model (the
        message lists the allowed names); see also :func:`fit_model`.

    Notes
    -----
    On the shipped Dragon Skin 30 test (Marechal et al. 2021, 311 points, strain
    to 7.09) Yeoh fits best, as in paper B, but not with paper B's numbers (R²
    0.9982, RMSE 0.0204 MPa, C10 0.11, C20 0.003 MPa): over the full range to
    failure it gives R² ≈ 0.9986, RMSE ≈ 0.045 MPa, C10 ≈ 0.141, C20 ≈ 0.0020,
    C30 ≈ −1.2e-5 MPa; with ``max_stretch=5`` C10 ≈ 0.111, C20 ≈ 0.0045 MPa,
    RMSE ≈ 0.018 MPa. Neo-Hookean (R² ≈ 0.95) and Arruda–Boyce (R² ≈ 0.988)
    follow.
    """
    names = (models,) if isinstance(models, str) else tuple(models)
    if not names:
        raise InputError(
            must_be(f"at least one of {', '.join(repr(m) for m in _PROBLEMS)}", models),
            key="models",
        )
    with keyed("models"):
        for name in names:
            _PROBLEMS.check(name)
    if len(set(names)) != len(names):
        raise InputError(must_be("distinct names", list(names)), key="models")
    stretch, stress = _stretch_and_stress(data)
    return {name: fit_model(name, stretch, stress, max_stretch=max_stretch) for name in names}
