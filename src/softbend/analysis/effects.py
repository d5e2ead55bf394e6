"""Main effects of a design space: how each parameter alone moves a response.

A campaign over a space-filling sample (Sobol or Latin hypercube) varies every
parameter at once, and no two designs share all but one value, so the effect of
one parameter is read the way a designed experiment reads it: the designs are
grouped by that parameter's value (its quantile bins, or its values when it has
few), and the mean response of each group is compared. With the other
parameters spread evenly over every group, the spread of the group means is the
parameter's main effect; the interactions average out.

:func:`angle_at_pressure` reads the response most questions start from, a
design's bending angle at one pressure, from the campaign samples;
:func:`main_effects` returns the group means of every parameter and response as
one :class:`MainEffects`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from softbend._validation import check_int, must_be
from softbend.errors import DatasetError, InputError

__all__ = ["MainEffects", "angle_at_pressure", "main_effects"]


def angle_at_pressure(
    samples: pd.DataFrame,
    pressure_mpa: float,
    *,
    design_column: str = "design_id",
    pressure_column: str = "pressure_mpa",
    angle_column: str = "angle_deg",
) -> pd.Series:
    """Each design's bending angle at ``pressure_mpa``, linear between its samples.

    Parameters
    ----------
    samples : DataFrame
        One row per design and pressure (a campaign's samples); rows whose
        ``converged`` column is false are left out.
    pressure_mpa : float
        The pressure, MPa (finite, ≥ 0).
    design_column, pressure_column, angle_column : str
        The columns of the design's id, the pressure (MPa) and the angle (degrees).

    Returns
    -------
    Series
        The angle in degrees, indexed by design id; NaN for a design whose
        sweep stopped below ``pressure_mpa``.
    """
    if not np.isfinite(pressure_mpa) or pressure_mpa < 0:
        raise InputError(must_be("a finite pressure ≥ 0 MPa", pressure_mpa), key="pressure_mpa")
    missing = [c for c in (design_column, pressure_column, angle_column) if c not in samples]
    if missing:
        raise DatasetError(
            f"the samples lack the column(s) {', '.join(missing)}; they have "
            f"{', '.join(map(str, samples.columns))}"
        )
    rows = samples
    if "converged" in rows:
        rows = rows[rows["converged"].astype(bool)]
    angles = {}
    for design, group in rows.groupby(design_column, sort=True):
        group = group.sort_values(pressure_column)
        p = group[pressure_column].to_numpy(np.float64)
        a = group[angle_column].to_numpy(np.float64)
        reached = p.size > 0 and pressure_mpa <= p.max() + 1e-12
        angles[design] = float(np.interp(pressure_mpa, p, a)) if reached else np.nan
    return pd.Series(angles, name=f"angle at {pressure_mpa * 1e3:g} kPa (°)", dtype=np.float64)


@dataclass(frozen=True)
class MainEffects:
    """The group means of every parameter and response.

    Attributes
    ----------
    table : DataFrame
        One row per parameter, response and group: ``parameter``, ``response``,
        ``group`` (0, 1, ...), ``low`` and ``high`` (the group's parameter
        values), ``centre`` (their mean), ``mean`` (the response's mean over
        the group), ``n`` (the designs with a response).
    effects : DataFrame
        Parameters × responses: the largest minus the smallest group mean, in
        the response's unit; negative when the means fall with the parameter.
    trends : DataFrame
        Parameters × responses: ``"rises"`` or ``"falls"`` when the group means
        all rise or all fall with the parameter, ``"mixed"`` otherwise (the
        effect is then the spread, unsigned).
    """

    table: pd.DataFrame
    effects: pd.DataFrame
    trends: pd.DataFrame

    def ranking(self, response: str) -> list[str]:
        """The parameters by the size of their effect on ``response``, largest first."""
        if response not in self.effects:
            raise InputError(
                must_be(f"one of {', '.join(self.effects.columns)}", response), key="response"
            )
        return list(self.effects[response].abs().sort_values(ascending=False).index)


def _groups(values: np.ndarray, bins: int) -> np.ndarray:
    """The group number of each value: its distinct values when few, else quantile bins."""
    distinct = np.unique(values)
    if distinct.size <= bins:
        return np.searchsorted(distinct, values)
    edges = np.quantile(values, np.linspace(0.0, 1.0, bins + 1)[1:-1])
    return np.searchsorted(np.unique(edges), values, side="right")


def main_effects(
    designs: pd.DataFrame,
    parameters: Sequence[str],
    responses: Mapping[str, pd.Series | np.ndarray],
    *,
    bins: int = 4,
) -> MainEffects:
    """Group means of each response over each parameter's quantile bins.

    Parameters
    ----------
    designs : DataFrame
        One row per design, with the ``parameters`` columns.
    parameters : sequence of str
        The design parameters to read effects of.
    responses : mapping of str to array_like
        Name → one value per row of ``designs`` (a Series is aligned on the
        index); NaN values (a design without the response) are left out of
        that response's means.
    bins : int, default 4
        Groups per parameter (2–20): quantile bins, or the parameter's own
        values when it takes at most ``bins`` of them.

    Returns
    -------
    MainEffects
    """
    if check_int(bins, "bins", low=2) > 20:
        raise InputError(must_be("an integer in [2, 20]", bins), key="bins")
    missing = [p for p in parameters if p not in designs]
    if missing:
        raise DatasetError(
            f"the designs lack the parameter column(s) {', '.join(missing)}; they have "
            f"{', '.join(map(str, designs.columns))}"
        )
    if not parameters or not responses:
        raise InputError("needs at least one parameter and one response", key="parameters")
    values = {}
    for name, response in responses.items():
        if isinstance(response, pd.Series):
            response = response.reindex(designs.index)
        array = np.asarray(response, dtype=np.float64)
        if array.shape != (len(designs),):
            raise InputError(
                must_be(f"one value per design ({len(designs)})", f"{array.size} values"),
                key=name,
            )
        if np.isfinite(array).sum() < bins:
            raise DatasetError(f"{name}: fewer than {bins} designs have a value")
        values[name] = array
    rows: list[dict[str, object]] = []
    effects: dict[str, dict[str, float]] = {}
    trends: dict[str, dict[str, str]] = {}
    for parameter in parameters:
        x = designs[parameter].to_numpy(np.float64)
        group = _groups(x, bins)
        for name, y in values.items():
            means = []
            for g in np.unique(group):
                member = (group == g) & np.isfinite(y)
                mean = float(y[member].mean()) if member.any() else np.nan
                means.append(mean)
                inside = x[group == g]
                rows.append(
                    {
                        "parameter": parameter,
                        "response": name,
                        "group": int(g),
                        "low": float(inside.min()),
                        "high": float(inside.max()),
                        "centre": float(inside.mean()),
                        "mean": mean,
                        "n": int(member.sum()),
                    }
                )
            m = np.asarray(means)[np.isfinite(means)]
            spread = float(m.max() - m.min()) if m.size else np.nan
            steps = np.diff(m)
            trend = (
                "falls"
                if steps.size and np.all(steps < 0)
                else "rises"
                if steps.size and np.all(steps > 0)
                else "mixed"
            )
            effects.setdefault(name, {})[parameter] = -spread if trend == "falls" else spread
            trends.setdefault(name, {})[parameter] = trend
    order = list(parameters)
    return MainEffects(
        pd.DataFrame(rows), pd.DataFrame(effects).loc[order], pd.DataFrame(trends).loc[order]
    )
