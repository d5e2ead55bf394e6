"""The values of the two papers that softbend compares itself with, each with its source.

softbend follows two papers:

* **paper A** — *Characteristics analysis and modeling of a miniature pneumatic
  curling rubber actuator*: the curling actuator, its kinematics and its
  NARX/SVR identification with a generalized-Gaussian kernel;
* **paper B** — Ye et al., *Modelling of soft fiber-reinforced bending actuators
  through transfer learning from a machine learning algorithm trained from FEM
  data*, Sens. Actuators A 368 (2024) 115095: the fiber-reinforced actuator, its
  FEM, the PLR/XGBoost/MLP surrogates, transfer learning and control.

Every value is a :class:`Reference`: the number (or label, or tuple) as the code
uses it, its unit, the paper and where in the paper it stands (``"Table 1"``,
``"Fig. 7c"``, ``"Sec. 4.3"``, ``"Eq. 18"``). Values are grouped by topic in
module-level dicts (:data:`SURROGATES`, :data:`TRANSFER_RESULTS`,
:data:`CONTROL_RESULTS`, ...); :func:`values` turns a group into the plain dict
the code compares against, and :func:`all_references` lists every value by a
dotted name. A figure or table that quotes a value cites it with
:meth:`Reference.cite` (``"paper B, Sec. 4.3"``); ``str(ref)`` gives the value,
its unit and the citation.

Units are those of the rest of softbend: lengths in mm, angles in degrees
(``deg``), pressures and moduli in MPa, times in s (inference times in ms),
densities in g/cm³, errors in % where the paper gives a percentage; an empty
unit means a dimensionless number, a count or a label. Where softbend keeps a
number that differs from the paper's wording (another unit, an upper bound
taken as a value, an inconsistency in the paper), ``note`` says so.

This module imports nothing from softbend: every stage may read it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from softbend.errors import InputError

__all__ = [
    "CONTROL_LOOP",
    "CONTROL_RESULTS",
    "CURLING_ACTUATOR",
    "CURLING_IDENTIFICATION",
    "DESIGN_SPACE",
    "FEM_DATASET",
    "FEM_VALIDATION",
    "LINEAR_MODEL",
    "MATERIALS",
    "MEASURED_ACTUATORS",
    "PAPERS",
    "SURROGATES",
    "SURROGATE_TRAINING",
    "TRANSFER_LOSS",
    "TRANSFER_RESULTS",
    "Reference",
    "all_references",
    "values",
]

#: The papers by the letter softbend cites them with.
PAPERS: dict[str, str] = {
    "A": "Characteristics analysis and modeling of a miniature pneumatic curling rubber actuator",
    "B": "Ye et al., Sens. Actuators A 368 (2024) 115095",
}

#: A source must name a place in the paper: a table, figure, section, equation or page.
_SOURCE = re.compile(r"\b(Table|Fig\.|Sec\.|Eq\.|p\.)\s*\d")


@dataclass(frozen=True)
class Reference:
    """One value of a paper and where it stands.

    Parameters
    ----------
    value : float, int, str or tuple
        The value as softbend uses it, in ``unit``.
    unit : str
        Its unit (``"mm"``, ``"deg"``, ``"MPa"``, ``"%"``, ``"s"``, ``"ms"``);
        empty for a dimensionless number, a count or a label.
    paper : {"A", "B"}
        The paper (see :data:`PAPERS`).
    source : str
        Where in the paper: a table, figure, section, equation or page, e.g.
        ``"Table 1"``, ``"Sec. 4.1"``, ``"Eq. 18"``.
    note : str, optional
        How softbend's value relates to the paper's text, where that is not plain.

    Raises
    ------
    ValueError
        ``paper`` is not ``"A"`` or ``"B"``, ``source`` names no table, figure,
        section, equation or page, or ``unit``/``note`` is not a string.
    """

    value: Any
    unit: str
    paper: str
    source: str
    note: str = ""

    def __post_init__(self) -> None:
        if self.paper not in PAPERS:
            raise InputError(f"must be one of 'A', 'B'; got {self.paper!r}", key="paper")
        if not isinstance(self.source, str) or not _SOURCE.search(self.source):
            raise InputError(
                "must name a Table, Fig., Sec., Eq. or p. with its number (e.g. 'Sec. 4.3, "
                f"Fig. 7c'); got {self.source!r}",
                key="source",
            )
        for name in ("unit", "note"):
            if not isinstance(getattr(self, name), str):
                raise InputError(f"must be a string; got {getattr(self, name)!r}", key=name)

    def cite(self) -> str:
        """Where the value comes from, as the report writes it: ``"paper B, Sec. 4.3"``."""
        return f"paper {self.paper}, {self.source}"

    def __str__(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.value}{unit} ({self.cite()})"


_Value = float | str | tuple[object, ...]


def _ref(value: _Value, unit: str, paper: str, source: str, note: str = "") -> Reference:
    return Reference(value, unit, paper, source, note)


def _a(value: _Value, unit: str, source: str, note: str = "") -> Reference:
    return _ref(value, unit, "A", source, note)


def _b(value: _Value, unit: str, source: str, note: str = "") -> Reference:
    return _ref(value, unit, "B", source, note)


# --------------------------------------------------------------------------- paper A

#: Paper A's curling actuator (§4.1–4.2): rest length and the extremes of its arc length.
CURLING_ACTUATOR: dict[str, Reference] = {
    "rest_length_mm": _a(15.25, "mm", "Sec. 4.1"),
    "max_length_mm": _a(18.25, "mm", "Eq. 18"),
    "min_length_mm": _a(9.25, "mm", "Eq. 19"),
    "max_elongation_pct": _a(19.67, "%", "Eq. 18"),
    "max_shrink_pct": _a(39.34, "%", "Eq. 19"),
}

#: Paper A's SVR identification (§4.3): penalty, tube width, data and regressor.
CURLING_IDENTIFICATION: dict[str, Reference] = {
    "svr_c": _a(100.0, "", "Sec. 4.3", "the paper calls the penalty 'γ'"),
    "svr_epsilon": _a(0.1, "", "Sec. 4.3"),
    "experiments": _a(6, "", "Sec. 4.3", "'6 × 512 data pairs' per model"),
    "samples_per_experiment": _a(512, "", "Sec. 4.3"),
    "output_lags": _a(2, "", "Sec. 4.3, Eq. 27", "regressor [y(t-1), y(t-2), u(t), u(t-1)]"),
    "input_lags": _a(2, "", "Sec. 4.3, Eq. 27", "u(t) and u(t-1)"),
}

# --------------------------------------------------------------------------- paper B

#: Paper B's materials (§2.1, §3.1), by the name of softbend's preset.
MATERIALS: dict[str, dict[str, Reference]] = {
    "dragon-skin-30": {
        "c10_mpa": _b(0.11, "MPa", "Sec. 3.1"),
        "c20_mpa": _b(0.003, "MPa", "Sec. 3.1"),
        "c30_mpa": _b(0.0, "MPa", "Sec. 3.1"),
        "density_g_per_cm3": _b(1.08, "g/cm³", "Sec. 3.1"),
        "fit_r2": _b(0.9982, "", "Sec. 3.1, Fig. 2a", "the Yeoh fit, the best of three"),
        "fit_rmse_mpa": _b(0.0204, "MPa", "Sec. 3.1, Fig. 2a"),
    },
    "fiberglass": {
        "c10_mpa": _b(7.9, "MPa", "Sec. 3.1", "after Polygerinos et al. 2015"),
        "c20_mpa": _b(0.0, "MPa", "Sec. 3.1"),
        "c30_mpa": _b(0.0, "MPa", "Sec. 3.1"),
        "density_g_per_cm3": _b(2.40, "g/cm³", "Sec. 3.1"),
        "thickness_mm": _b(0.1, "mm", "Sec. 2.1"),
    },
    "kevlar": {
        "e_mpa": _b(31076.0, "MPa", "Sec. 3.1"),
        "nu": _b(0.36, "", "Sec. 3.1"),
        "density_g_per_cm3": _b(1.67, "g/cm³", "Sec. 3.1"),
        "diameter_mm": _b(0.28, "mm", "Sec. 2.1"),
        "modelled_radius_mm": _b(
            0.07, "mm", "Sec. 3.1", "beam radius, the real 0.14 mm halved to soften the fibers"
        ),
    },
}

#: Paper B Table 1: levels of the design parameters (mm, deg) and the pressure grid (MPa).
DESIGN_SPACE: dict[str, Reference] = {
    "l_mm": _b((100.0, 120.0, 140.0, 160.0), "mm", "Table 1", "100 to 160 in steps of 20"),
    "r_mm": _b((6.0, 8.0, 10.0), "mm", "Table 1", "6 to 10 in steps of 2"),
    "t_mm": _b((2.0, 3.0, 4.0), "mm", "Table 1", "2 to 4 in steps of 1"),
    "b_mm": _b((2.0, 3.0, 4.0), "mm", "Table 1", "2 to 4 in steps of 1"),
    "phi_deg": _b((5.0, 10.0, 15.0), "deg", "Table 1", "5 to 15 in steps of 5"),
    "lc_mm": _b((8.0, 10.0, 12.0), "mm", "Table 1", "8 to 12 in steps of 2"),
    "pressure_max_mpa": _b(0.5, "MPa", "Table 1, Sec. 3.3"),
    "pressure_step_mpa": _b(0.005, "MPa", "Table 1"),
}

#: Paper B's FEM against its rig (§3.1–3.2, Figs. 2 and 3).
FEM_VALIDATION: dict[str, Reference] = {
    "design": _b("100,6,2,2,5,10", "mm, deg", "Sec. 3.1, Fig. 2b", "(l, r, t, b, φ, lc)"),
    "pmax_mpa": _b(0.17, "MPa", "Sec. 3.2, Fig. 2b"),
    "pressure_step_mpa": _b(0.01, "MPa", "Sec. 3.2", "the rig's pressure increment"),
    "hysteresis_error_pct": _b(5.0, "%", "Sec. 3.2, Fig. 3c", "an upper bound: 'less than 5%'"),
    "fem_mape_pct": _b(5.5, "%", "Sec. 3.2, Fig. 3d", "an upper bound: 'less than 5.5%'"),
}

#: Paper B's FEM dataset (§3.3).
FEM_DATASET: dict[str, Reference] = {
    "designs": _b(972, "", "Sec. 3.3", "the 4 × 3⁵ designs of Table 1"),
    "samples": _b(29577, "", "Sec. 3.3"),
}

#: Paper B's standardized multiple linear regression of the FEM data (§3.3, Fig. 4b–c).
LINEAR_MODEL: dict[str, Reference] = {
    "pressure_mpa": _b(0.832, "", "Sec. 3.3, Fig. 4b", "standardized loading of Pact"),
    "t_mm": _b(-0.369, "", "Sec. 3.3, Fig. 4b", "standardized loading"),
    "b_mm": _b(-0.005, "", "Sec. 3.3, Fig. 4b", "standardized loading"),
    "r2": _b(0.8893, "", "Sec. 3.3, Fig. 4c"),
    "f_value": _b(33935.8, "", "Sec. 3.3, Fig. 4c"),
    "mape_pct": _b(42.3, "%", "Sec. 3.3, Fig. 4c"),
}

_IT_NOTE = "the paper gives the average inference time in s: {} s"

#: Paper B §4.1: the best configuration of each surrogate family, 5-fold CV (the text
#: gives the numbers, Fig. 5 the parity plots).
SURROGATES: dict[str, dict[str, Reference]] = {
    "plr": {
        "params": _b("degree 4", "", "Sec. 4.1"),
        "r2": _b(0.9986, "", "Sec. 4.1"),
        "mape_pct": _b(1.8, "%", "Sec. 4.1"),
        "inference_ms": _b(22.39, "ms", "Sec. 4.1", _IT_NOTE.format(0.02239)),
    },
    "xgb": {
        "params": _b("max depth 9, learning rate 0.2", "", "Sec. 4.1"),
        "r2": _b(0.9995, "", "Sec. 4.1"),
        "mape_pct": _b(0.8, "%", "Sec. 4.1"),
        "inference_ms": _b(
            53.77,
            "ms",
            "Sec. 4.1",
            _IT_NOTE.format(0.05377) + " with the configuration; a later sentence of "
            "Sec. 4.1 says 0.05337 s",
        ),
    },
    "mlp": {
        "params": _b("hidden (63, 65)", "", "Sec. 4.1"),
        "r2": _b(0.9991, "", "Sec. 4.1"),
        "mape_pct": _b(0.89, "%", "Sec. 4.1"),
        "inference_ms": _b(12.99, "ms", "Sec. 4.1", _IT_NOTE.format(0.01299)),
    },
}

#: Paper B §4.1: how its surrogates were searched and trained.
SURROGATE_TRAINING: dict[str, Reference] = {
    "folds": _b(5, "", "Sec. 4.1", "five-fold cross-validation"),
    "plr_degrees": _b((2, 10), "", "Sec. 4.1", "orders 2 to 10"),
    "xgb_max_depths": _b((1, 20), "", "Sec. 4.1", "1 to 20"),
    "xgb_learning_rates": _b((0.1, 1.0), "", "Sec. 4.1", "0.1 to 1"),
    "mlp_hidden_units": _b((55, 65), "", "Sec. 4.1", "each of the two hidden layers, 55 to 65"),
    "mlp_hidden": _b((63, 65), "", "Sec. 4.1", "the best configuration"),
    "mlp_epochs": _b(1000, "", "Sec. 4.1"),
    "mlp_batch_size": _b(1024, "", "Sec. 4.1"),
    "mlp_learning_rate": _b(6e-4, "", "Sec. 4.1", "Adam"),
}

#: Paper B Fig. 6: final training MSE (deg²) of the FEM MLP on FEM data and of the
#: refined MLP after 1000 epochs, by softbend's strategy name.
TRANSFER_LOSS: dict[str, Reference] = {
    "fem-only": _b(4.8124, "deg²", "Sec. 4.2, Fig. 6", "the paper gives no unit"),
    "refined": _b(0.1631, "deg²", "Sec. 4.2, Fig. 6", "after 1000 epochs; no unit given"),
}

#: Paper B §4.2–4.3 (Fig. 7): the refined MLP, leave one configuration out.
TRANSFER_RESULTS: dict[str, Reference] = {
    "rmse_deg": _b(7.935, "deg", "Sec. 4.3, Fig. 7", "mean over the seven actuators"),
    "mape_pct": _b(6.45, "%", "Sec. 4.3, Fig. 7", "mean over the seven actuators"),
    "worst": _b("120,6,2,2,5,8", "mm, deg", "Sec. 4.3, Fig. 7c", "(l, r, t, b, φ, lc)"),
    "worst_rmse_deg": _b(19.58, "deg", "Sec. 4.3, Fig. 7c"),
    "worst_mape_pct": _b(11.24, "%", "Sec. 4.3, Fig. 7c"),
    "n_measurements": _b(139, "", "Sec. 4.2"),
}

#: Paper B Fig. 7b–h: the seven measured actuators, nominal (l, r, t, b, φ, lc) in mm and
#: deg: the reference (100, 6, 2, 2, 5, 8) and one parameter changed at a time.
MEASURED_ACTUATORS: Reference = _b(
    (
        (100, 6, 2, 2, 5, 8),
        (120, 6, 2, 2, 5, 8),
        (100, 8, 2, 2, 5, 8),
        (100, 6, 3, 2, 5, 8),
        (100, 6, 2, 3, 5, 8),
        (100, 6, 2, 2, 10, 8),
        (100, 6, 2, 2, 5, 10),
    ),
    "mm, deg",
    "Sec. 4.3, Fig. 7b-h",
)

#: Paper B §5 (Fig. 9): its deadzone bang-bang on its rig.
CONTROL_RESULTS: dict[str, dict[str, Reference]] = {
    "square": {
        "mape_pct": _b(5.5, "%", "Sec. 5, Fig. 9a", "the paper's 'step response' test"),
        "settling_s": _b(0.7, "s", "Sec. 5, Fig. 9a", "the paper's 'average convergence time'"),
        "rise_s": _b(0.104, "s", "Sec. 5, Fig. 9a", "average rise time"),
    },
    "triangle": {
        "mape_pct": _b(5.3, "%", "Sec. 5, Fig. 9b"),
        "delay_s": _b(0.0875, "s", "Sec. 5, Fig. 9b", "average tracking delay"),
    },
}

#: Paper B §5 (Fig. 8): the loop's settings.
CONTROL_LOOP: dict[str, Reference] = {
    "deadzone": _b(0.05, "", "Sec. 5, Eq. 1", "θ_deadzone = ±0.05 θr, a fraction of θr"),
    "sample_rate_hz": _b(100.0, "Hz", "Sec. 5"),
    "triangle_frequency_hz": _b(0.2, "Hz", "Sec. 5, Fig. 9b"),
}

#: Every group of this module by name (what :func:`all_references` walks).
_GROUPS: dict[str, Any] = {
    "CURLING_ACTUATOR": CURLING_ACTUATOR,
    "CURLING_IDENTIFICATION": CURLING_IDENTIFICATION,
    "MATERIALS": MATERIALS,
    "DESIGN_SPACE": DESIGN_SPACE,
    "FEM_VALIDATION": FEM_VALIDATION,
    "FEM_DATASET": FEM_DATASET,
    "LINEAR_MODEL": LINEAR_MODEL,
    "SURROGATES": SURROGATES,
    "SURROGATE_TRAINING": SURROGATE_TRAINING,
    "TRANSFER_LOSS": TRANSFER_LOSS,
    "TRANSFER_RESULTS": TRANSFER_RESULTS,
    "MEASURED_ACTUATORS": MEASURED_ACTUATORS,
    "CONTROL_RESULTS": CONTROL_RESULTS,
    "CONTROL_LOOP": CONTROL_LOOP,
}


def values(group: Mapping[str, Any]) -> dict[str, Any]:
    """The plain values of a group, nested groups included: ``{"r2": 0.8893, ...}``.

    Parameters
    ----------
    group : mapping
        ``{name: Reference}`` or ``{name: {name: Reference}}`` (e.g. :data:`SURROGATES`).

    Returns
    -------
    dict
        The same keys, in the same order, with each :class:`Reference` replaced by
        its ``value`` (units as the Reference says).

    Raises
    ------
    ValueError
        An entry is neither a Reference nor a mapping of them.
    """
    out: dict[str, Any] = {}
    for name, entry in group.items():
        if isinstance(entry, Reference):
            out[name] = entry.value
        elif isinstance(entry, Mapping):
            out[name] = values(entry)
        else:
            raise InputError(
                f"{name} must be a Reference or a mapping of them; got {type(entry).__name__}",
                key="group",
            )
    return out


def _walk(prefix: str, entry: Reference | Mapping[str, Any], out: dict[str, Reference]) -> None:
    if isinstance(entry, Reference):
        out[prefix] = entry
    else:
        for name, sub in entry.items():
            _walk(f"{prefix}.{name}", sub, out)


def all_references() -> dict[str, Reference]:
    """Every reference of this module by dotted name, e.g. ``"SURROGATES.mlp.r2"``."""
    out: dict[str, Reference] = {}
    for name, group in _GROUPS.items():
        _walk(name, group, out)
    return out
