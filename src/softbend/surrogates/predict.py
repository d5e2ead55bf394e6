"""One call from a saved surrogate, a design and pressures to angles, extrapolation flagged."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import must_be
from softbend.actuators import SFRBA, Actuator, Design
from softbend.errors import InputError, SchemaError, keyed
from softbend.surrogates.support import pressures_text, trained_pressure_range

__all__ = [
    "INTERVAL_LEVEL",
    "Prediction",
    "calibrated_interval",
    "load_predictor",
    "parse_pressures",
    "predict_angles",
    "predict_text",
]

#: Probability of the prediction intervals reported by :func:`predict_angles`.
INTERVAL_LEVEL = 0.9


@dataclass(frozen=True)
class Prediction:
    """Angles predicted by a saved surrogate for one design.

    Attributes
    ----------
    kind : str
        The surrogate's kind: its family's name (``"plr"``, ``"xgb"``, ``"mlp"``, ...)
        or a composite kind (``"affine-corrected"``, ...).
    design : Design or ndarray
        Paper B's design, or another actuator's design codes (in the order of
        ``actuator.names``; a categorical level as its index).
    pressure_mpa, angle_deg : ndarray
        The pressures asked for, in the model's pressure unit (MPa for paper
        B's actuator; ``actuator.pressure_unit``), and the predicted angles (degrees).
    outside_training_ranges : list of str
        One phrase per input outside the ranges the model was trained on
        (empty inside them, or when the file records none).
    has_training_ranges : bool
        Whether the file records its training ranges.
    beyond_support : list of str
        One phrase per way the predictions leave the training data's support
        (:mod:`softbend.surrogates.support`: a pressure past what the training
        designs nearest to ``design`` were swept to, an angle past the largest
        trained on); empty inside it, or when the file records none.
    supported : ndarray of bool or None
        Per pressure, whether the prediction lies in the support; None when the
        file records none.
    interval_deg : tuple of ndarray or None
        ``(low, high)``: the 90 % interval for a new reading, degrees: the
        calibrated one a refined model records (``softbend transfer refine``:
        conformal over its actuators), else the model's own (the Gaussian
        interval of the corrections); None otherwise.
    source : str
        The model file.
    actuator : Actuator
        The description the model was trained with.
    pressure_range : (float, float) or None
        The pressures the model was trained on, in its pressure unit
        (:func:`softbend.surrogates.support.trained_pressure_range`); None if unrecorded.
    """

    kind: str
    design: Design
    pressure_mpa: np.ndarray
    angle_deg: np.ndarray
    outside_training_ranges: list[str] = field(default_factory=list)
    has_training_ranges: bool = False
    interval_deg: tuple[np.ndarray, np.ndarray] | None = None
    source: str = ""
    beyond_support: list[str] = field(default_factory=list)
    supported: np.ndarray | None = None
    actuator: Actuator = SFRBA
    pressure_range: tuple[float, float] | None = None

    @property
    def outside_pressures(self) -> list[float]:
        """The pressures asked for outside :attr:`pressure_range`, in the order asked."""
        from softbend.units import outside

        return outside(self.pressure_mpa, self.pressure_range)

    def pressure_warning(self) -> str | None:
        """The pressures outside the trained range and the range, in words; else None."""
        outside = self.outside_pressures
        if not outside or self.pressure_range is None:
            return None
        unit = self.actuator.pressure_unit
        low, high = self.pressure_range
        return (
            f"{pressures_text(outside, unit)}: outside the pressures {self.source} was "
            f"trained on ({low:.4g}–{high:.4g} {unit}); the angles there are extrapolations"
        )

    @property
    def design_codes(self) -> np.ndarray:
        """The design as model inputs, in the order of ``actuator.names``."""
        return self.design.as_array()

    @property
    def design_text(self) -> str:
        """The design by name, in its units."""
        return str(self.design)

    @property
    def extrapolated(self) -> list[str]:
        """Every phrase saying where the prediction leaves the training data."""
        return [*self.outside_training_ranges, *self.beyond_support]

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form: model, kind, design (mm, deg), pressures (MPa), angles (deg),
        the inputs outside the training ranges, the ways the predictions leave the
        training data's support and, per pressure, whether each lies in it (null
        when the model records no support), the pressures outside the trained pressure
        range with the range and its unit (``outside_pressure_range``, null when all
        lie inside or the model records none), and the interval's level and ends if any."""
        payload: dict[str, Any] = {
            "model": self.source,
            "kind": self.kind,
            **({"actuator": self.actuator.name} if self.actuator.named_in_outputs else {}),
            "design": self.actuator.design_record(self.design_codes),
            self.actuator.pressure_column: self.pressure_mpa.tolist(),
            "angle_deg": self.angle_deg.tolist(),
            "outside_training_ranges": list(self.outside_training_ranges),
            "beyond_training_support": list(self.beyond_support),
            "supported": None if self.supported is None else self.supported.tolist(),
            "outside_pressure_range": None
            if not self.outside_pressures or self.pressure_range is None
            else {
                "pressures": self.outside_pressures,
                "trained_range": list(self.pressure_range),
                "unit": self.actuator.pressure_unit,
            },
        }
        if self.interval_deg is not None:
            payload["interval_level"] = INTERVAL_LEVEL
            payload["interval_low_deg"] = self.interval_deg[0].tolist()
            payload["interval_high_deg"] = self.interval_deg[1].tolist()
        return payload


def calibrated_interval(record: object, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The calibrated 90 % interval a refined model records (``transfer refine``), if any.

    The record is the ``interval`` metadata of :mod:`softbend.transfer.conformal`:
    ``angle ± half_width_deg``, the low end raised to ``floor_deg`` but never above
    the angle. It replaces a model's own interval, which is not calibrated.
    """
    if not isinstance(record, dict) or record.get("method") != "conformal":
        return None
    if record.get("level") != INTERVAL_LEVEL:
        return None
    half = float(record["half_width_deg"])
    floor = float(record.get("floor_deg", -np.inf))
    return np.minimum(np.maximum(angles - half, floor), angles), angles + half


def parse_pressures(text: str, unit: str | None = None) -> list[float]:
    """Pressures from comma-separated text such as ``"0.05,0.1"`` (in the model's unit).

    With the model's ``unit``, a value may carry its own unit (``"20psi,138kPa"``,
    :func:`softbend.units.parse_pressure`) and is converted to ``unit``.

    Raises
    ------
    softbend.errors.InputError
        Text that is not comma-separated numbers (with units, given ``unit``), or
        holds none (no key: the caller names the input, :func:`~softbend.errors.keyed`).
    """
    from softbend.units import PRESSURE_UNITS, parse_pressure

    items = [v for v in text.split(",") if v.strip()]
    try:
        if unit is None:
            values = [float(v) for v in items]
        else:
            values = [parse_pressure(v, unit, "pressures") for v in items]
    except ValueError:
        units = ", ".join(PRESSURE_UNITS)
        form = f"comma-separated numbers, each optionally with a unit ({units}), e.g. 0.05,0.1"
        raise InputError(must_be(f"{form} or 20psi", text)) from None
    if not values:
        raise InputError(must_be("at least one number", text))
    return values


def predict_text(
    path: str | os.PathLike[str],
    design: str,
    pressures: str,
    *,
    strict: bool = False,
) -> Prediction:
    """:func:`predict_angles` of a design and pressures given as text (as on a command line).

    Parameters
    ----------
    path : path
        A file written by :func:`softbend.surrogates.save_surrogate`.
    design : str
        ``"A=1,B=2,..."`` by the model's parameter names, or the values in the
        model's column order (paper B's: ``"l,r,t,b,phi,lc"`` in mm and degrees).
    pressures : str
        Comma-separated gauge pressures in the model's pressure unit, or each with
        its own unit (:func:`parse_pressures`; MPa for paper B's actuator).
    strict : bool
        As :func:`predict_angles`.

    Raises
    ------
    softbend.errors.InputError
        As :func:`predict_angles`; pressures that are not numbers, negative or
        not finite are keyed ``pressures``.
    """
    with keyed("pressures"):
        try:
            values = parse_pressures(pressures)
        except InputError:  # values with units (20psi): in the model's unit
            _, saved = load_predictor(path)
            values = parse_pressures(pressures, saved.actuator.pressure_unit)
    _check_pressures(values, key="pressures")
    return predict_angles(path, design, values, strict=strict)


def _check_pressures(
    pressures_mpa: ArrayLike, unit: str = "", *, key: str = "pressures_mpa"
) -> np.ndarray:
    """The pressures as a flat float array if non-empty, finite and >= 0 (in ``unit``), else
    an :class:`~softbend.errors.InputError` keyed ``key``."""
    pressures = np.asarray(pressures_mpa, dtype=float).ravel()
    if pressures.size == 0 or not np.all(np.isfinite(pressures)) or np.any(pressures < 0):
        requirement = f"finite and >= 0 {unit}".rstrip()
        raise InputError(must_be(requirement, np.asarray(pressures_mpa).tolist()), key=key)
    return pressures


def predict_angles(
    path: str | os.PathLike[str],
    design: Design | str | ArrayLike,
    pressures_mpa: ArrayLike,
    *,
    strict: bool = False,
) -> Prediction:
    """Load a saved surrogate and predict ``design``'s angle at each pressure.

    Parameters
    ----------
    path : path
        A file written by :func:`softbend.surrogates.save_surrogate`.
    design : Design, str or array_like
        Paper B's design; or, for any model, ``"A=1,B=2,..."`` by its
        parameter names, the values in its column order as text, or the
        design codes as numbers (checked against the model's actuator
        description: ranges, kinds, constraints).
    pressures_mpa : array_like
        Gauge pressures in the model's pressure unit (MPa for paper B's
        actuator), finite and >= 0 (any order).
    strict : bool, default False
        Refuse inputs outside the model's training ranges, and predictions
        beyond its training data's support (:mod:`softbend.surrogates.support`),
        instead of flagging them; refuse models that record neither.

    Raises
    ------
    ValueError
        Bad pressures (an :class:`~softbend.errors.InputError`, key
        ``pressures_mpa``), or with ``strict`` an extrapolation (naming the inputs
        or the support left);
        without ``strict``, an extrapolation where the model predicts a NaN or
        infinite angle (naming the file and the inputs).
    FileNotFoundError, softbend.errors.SchemaError
        As :func:`softbend.surrogates.load_surrogate`; also a ``SchemaError``
        naming the file when the model predicts a NaN or infinite angle or
        interval end inside its training ranges (its parameters overflow). A
        non-finite number is never returned.
    """
    from softbend.surrogates.features import outside_training_ranges

    # an MLP or a polynomial (alone or inside a composite) predicts from its arrays (NumPy
    # only); any other kind through its estimator
    model, saved = load_predictor(path)
    actuator = saved.actuator
    unit = actuator.pressure_unit
    pressures = _check_pressures(pressures_mpa, unit)
    design = _design_of(design, actuator, path)
    codes = design.as_array()
    rows = np.empty((pressures.size, codes.size + 1))
    rows[:, :-1] = codes
    rows[:, -1] = pressures
    ranges = saved.metadata.get("training_ranges")
    has_ranges = isinstance(ranges, dict)
    features = actuator.features
    outside = outside_training_ranges(ranges, rows, features) if has_ranges else []
    inside = (
        np.array([not outside_training_ranges(ranges, row, features) for row in rows])
        if has_ranges
        else np.ones(len(rows), dtype=bool)
    )
    if strict and outside:
        raise ValueError(
            f"The 'design' and 'pressure' must lie in the training data of {path}: "
            f"{'; '.join(outside)}."
        )
    if strict and not has_ranges:
        raise ValueError(
            f"The model {path} records no training ranges (saved by an older softbend); "
            "--strict cannot check it."
        )
    with np.errstate(all="ignore"):  # an overflow is reported below, naming the file
        angles = np.asarray(model.predict(rows), dtype=float)
        interval = None
        predict_interval = getattr(model, "predict_interval", None)
        if callable(predict_interval):
            low, high = predict_interval(rows, INTERVAL_LEVEL)
            interval = (np.asarray(low, dtype=float), np.asarray(high, dtype=float))
    _check_finite(path, saved.kind, pressures, angles, "angle", outside, unit)
    beyond, supported = _support_check(saved.metadata.get("support"), rows, angles)
    if supported is not None:  # one trust signal: inside the support and the ranges
        supported = supported & inside
    if strict and beyond:
        raise ValueError(
            f"The 'design' and 'pressure' must lie in the training data of {path}: "
            f"{'; '.join(beyond)}."
        )
    if strict and supported is None:
        raise ValueError(
            f"The model {path} records no training support (each training design's largest "
            "pressure; saved by an older softbend); --strict cannot check it."
        )
    calibrated = calibrated_interval(saved.metadata.get("interval"), angles)
    interval = calibrated if calibrated is not None else interval
    if interval is not None:
        _check_finite(path, saved.kind, pressures, interval[0], "interval's low end", outside, unit)
        _check_finite(
            path, saved.kind, pressures, interval[1], "interval's high end", outside, unit
        )
    return Prediction(
        saved.kind,
        design,
        pressures,
        angles,
        outside,
        has_ranges,
        interval,
        str(path),
        beyond,
        supported,
        actuator,
        trained_pressure_range(saved.metadata, actuator.pressure_column),
    )


def _design_of(
    design: Design | str | ArrayLike, actuator: Actuator, path: str | os.PathLike[str]
) -> Design:
    """``design`` as a design of ``actuator`` (the model's), checked."""
    if isinstance(design, Design):
        if design.actuator.names != actuator.names:
            raise ValueError(
                f"The model {path} is of the actuator {actuator.name} "
                f"({', '.join(actuator.names)}), not {design.actuator.name}'s; give its "
                "design by name."
            )
        return design
    if isinstance(design, str):
        codes = actuator.parse_design(design)
    else:
        codes = actuator.check_designs(np.asarray(design, dtype=float).ravel())[0]
    return Design(actuator, dict(zip(actuator.names, codes.tolist(), strict=True)))


def _support_check(
    record: object, rows: np.ndarray, angles: np.ndarray
) -> tuple[list[str], np.ndarray | None]:
    """The phrases and per-row mask of :class:`~softbend.surrogates.support.Support`;
    ``([], None)`` when the model records no support (checked on load)."""
    if not isinstance(record, dict):
        return [], None
    from softbend.surrogates.support import Support

    support = Support.from_dict(record)
    return support.beyond(rows, angles), support.supported(rows, angles)


def load_predictor(path: str | os.PathLike[str]) -> tuple[Any, Any]:
    """A saved surrogate's fastest predictor and its file record.

    Returns
    -------
    predictor : object
        ``.predict(rows)`` of float rows of the 7 inputs (mm, deg, MPa) in degrees:
        for an MLP its NumPy forward pass (no estimator, no scikit-learn; also
        ``.predict32`` in float32, for screening millions of rows), for a
        polynomial its NumPy evaluation, for XGBoost's plain regression its trees
        walked in NumPy (:mod:`softbend.surrogates.xgboost_core`), for a composite
        the composite over such predictors (a GP correction computes in NumPy
        too), else the estimator itself.
    saved : SavedSurrogate
        ``.kind``, ``.metadata`` and ``.actuator`` of the file.

    Raises
    ------
    FileNotFoundError, softbend.errors.SchemaError
        As :func:`softbend.surrogates.load_surrogate`.
    """
    from softbend.surrogates.persistence import load_light

    saved = load_light(
        path, {"mlp": _MLPArrays.of, "plr": _PolynomialArrays.of, "xgb": _xgboost_trees}
    )
    return saved.model, saved


def _xgboost_trees(saved: Any) -> Any:
    """A saved XGBoost model's trees in NumPy, or None where XGBoost itself must predict."""
    from softbend.surrogates.xgboost_core import booster_trees

    booster = saved.state.get("booster")
    if not isinstance(booster, str):
        return None
    return booster_trees(booster, saved.params, len(saved.actuator.features))


class _PolynomialArrays:
    """The prediction of a saved polynomial from its validated arrays (no SciPy, no sklearn).

    The same evaluation as :meth:`PolynomialRegressor.predict
    <softbend.surrogates.polynomial.PolynomialRegressor.predict>`, so the same angles bit for
    bit (rows are not validated: the caller passes finite float rows).
    """

    def __init__(self, state: dict[str, Any], chunk_rows: int) -> None:
        from softbend.surrogates.polynomial_core import plan

        self.state = state
        self.chunk_rows = int(chunk_rows)
        self.plan = plan(state["powers_"])
        self.n_features_in_ = int(state["n_features_in_"])

    @classmethod
    def of(cls, saved: Any) -> _PolynomialArrays:
        """The predictor of a :class:`~softbend.surrogates.persistence.SavedState`."""
        return cls(saved.state, saved.params["chunk_rows"])

    def predict(self, rows: np.ndarray) -> np.ndarray:
        """Angles (deg) of finite float rows of the 7 inputs (mm, deg, MPa)."""
        from softbend.surrogates.polynomial_core import polynomial_predict

        s = self.state
        return polynomial_predict(
            np.asarray(rows, dtype=np.float64),
            self.plan,
            np.asarray(s["coef_"], dtype=np.float64),
            s["x_mean_"],
            s["x_scale_"],
            s["y_mean_"],
            s["y_scale_"],
            self.chunk_rows,
        )


class _MLPArrays:
    """The prediction of a saved MLP from its validated arrays (no estimator, no sklearn).

    The same forward pass as :meth:`NormalizedMLPRegressor.predict
    <softbend.surrogates.mlp.NormalizedMLPRegressor.predict>`, so the same angles bit for bit.
    """

    def __init__(self, state: dict[str, Any]) -> None:
        self.state = state
        self.n_features_in_ = int(state["n_features_in_"])

    @classmethod
    def of(cls, saved: Any) -> _MLPArrays:
        """The predictor of a :class:`~softbend.surrogates.persistence.SavedState`."""
        return cls(saved.state)

    def predict(self, rows: np.ndarray) -> np.ndarray:
        """Angles (deg) of finite float rows of the 7 inputs (mm, deg, MPa)."""
        from softbend.surrogates.mlp_core import mlp_forward

        s = self.state
        return mlp_forward(
            np.asarray(rows, dtype=np.float64),
            s["x_mean_"],
            s["x_scale_"],
            s["y_mean_"],
            s["y_scale_"],
            s["coefs_"],
            s["intercepts_"],
        )

    def predict32(self, rows: np.ndarray) -> np.ndarray:
        """:meth:`predict` in float32 (about three times faster; some 1e-4° apart), degrees."""
        s = self.state
        if "_f32" not in s:
            s["_f32"] = (
                [np.asarray(c, dtype=np.float32) for c in s["coefs_"]],
                [np.asarray(b, dtype=np.float32) for b in s["intercepts_"]],
            )
        coefs, biases = s["_f32"]
        z = ((np.asarray(rows, dtype=np.float64) - s["x_mean_"]) / s["x_scale_"]).astype(np.float32)
        a = np.tanh(z @ coefs[0] + biases[0])
        a = np.tanh(a @ coefs[1] + biases[1])
        out = (a @ coefs[2] + biases[2])[:, 0]
        return out.astype(np.float64) * float(s["y_scale_"]) + float(s["y_mean_"])


def _check_finite(
    path: str | os.PathLike[str],
    kind: str,
    pressures: np.ndarray,
    values: np.ndarray,
    what: str,
    outside: list[str],
    unit: str = "MPa",
) -> None:
    """Raise naming ``path`` at the first non-finite value of ``values``.

    A ``ValueError`` when the inputs lie outside the training ranges (the model
    overflows where it was never trained), else a :class:`SchemaError` (the file's
    parameters overflow inside them).
    """
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        i = int(bad[0])
        error, cause = (
            (ValueError, f"the inputs lie outside its training data ({'; '.join(outside)})")
            if outside
            else (SchemaError, "its parameters are corrupt or overflow")
        )
        raise error(
            f"The model {path} ({kind} surrogate) predicts a non-finite {what} "
            f"({values[i]}) at {pressures[i]:g} {unit}; a prediction must be a finite number "
            f"of degrees: {cause}."
        )
