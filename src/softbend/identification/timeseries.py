"""Time series of any actuator: named inputs and outputs, one block per experiment.

Paper A's curling actuator has one input (pressure) and the two outputs of its
kinematics (ρ, L); a lab's own recording may have three chamber pressures in
and a tip's x and y out. :class:`TimeSeriesSet` holds either: each
:class:`Series` is one experiment (a contiguous recording, its own initial
conditions), all with the same named input and output columns.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend.tables import not_increasing, not_increasing_text

__all__ = ["Series", "TimeSeriesSet", "from_experiments"]


@dataclass(frozen=True)
class Series:
    """One experiment: time, inputs and outputs, sample by sample.

    Attributes
    ----------
    name : str
        The experiment's name (unique in its set).
    time : ndarray, shape (n,)
        Sample times, strictly increasing (the unit of the set's time column).
    inputs : ndarray, shape (n, k)
        The k inputs, in the set's ``input_names`` order.
    outputs : ndarray, shape (n, m)
        The m outputs, in the set's ``output_names`` order.
    source : str
        Where it was read from (a file), or how it was made.
    """

    name: str
    time: np.ndarray
    inputs: np.ndarray
    outputs: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=np.float64).ravel()
        inputs = np.asarray(self.inputs, dtype=np.float64)
        outputs = np.asarray(self.outputs, dtype=np.float64)
        inputs = inputs[:, None] if inputs.ndim == 1 else inputs
        outputs = outputs[:, None] if outputs.ndim == 1 else outputs
        n = time.size
        if inputs.ndim != 2 or outputs.ndim != 2 or inputs.shape[0] != n or outputs.shape[0] != n:
            raise ValueError(
                f"The experiment {self.name!r} must have one row of inputs and outputs per "
                f"time sample ({n}). Got inputs {inputs.shape} and outputs {outputs.shape}."
            )
        for what, values in (("time", time), ("inputs", inputs), ("outputs", outputs)):
            if not np.all(np.isfinite(values)):
                raise ValueError(f"The {what} of experiment {self.name!r} must be finite.")
        k = not_increasing(time)
        if k is not None:
            raise ValueError("time: " + not_increasing_text(time, k, f"sample {k - 1}", self.name))
        for name, value in (("time", time), ("inputs", inputs), ("outputs", outputs)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.time.size)


@dataclass(frozen=True)
class TimeSeriesSet:
    """Experiments with the same named inputs and outputs.

    Attributes
    ----------
    input_names, output_names : tuple of str
        Column names of the inputs and outputs (at least one each).
    experiments : tuple of Series
        At least one; unique names.
    time_name : str
        Name of the time column (``"time_s"`` if unnamed).
    """

    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    experiments: tuple[Series, ...]
    time_name: str = "time_s"

    def __post_init__(self) -> None:
        object.__setattr__(self, "input_names", tuple(self.input_names))
        object.__setattr__(self, "output_names", tuple(self.output_names))
        object.__setattr__(self, "experiments", tuple(self.experiments))
        if not self.input_names or not self.output_names:
            raise ValueError("A time-series set needs at least one input and one output.")
        if not self.experiments:
            raise ValueError("A time-series set needs at least one experiment.")
        names = [e.name for e in self.experiments]
        if len(set(names)) != len(names):
            raise ValueError(f"The experiments of a set must have unique names. Got {names}.")
        k, m = len(self.input_names), len(self.output_names)
        for e in self.experiments:
            if e.inputs.shape[1] != k or e.outputs.shape[1] != m:
                raise ValueError(
                    f"The experiment {e.name!r} must have {k} inputs and {m} outputs "
                    f"({', '.join(self.input_names)}; {', '.join(self.output_names)})."
                )

    @property
    def names(self) -> tuple[str, ...]:
        """The experiments' names, in order."""
        return tuple(e.name for e in self.experiments)

    def subset(self, names: Sequence[str]) -> TimeSeriesSet:
        """The experiments named, in the order given.

        Raises
        ------
        ValueError
            A name that is not an experiment of the set (the message lists them).
        """
        by_name = {e.name: e for e in self.experiments}
        missing = [n for n in names if n not in by_name]
        if missing:
            raise ValueError(
                f"Unknown experiment(s) {', '.join(map(repr, missing))}; the experiments are "
                f"{', '.join(self.names)}."
            )
        return TimeSeriesSet(
            self.input_names,
            self.output_names,
            tuple(by_name[n] for n in names),
            self.time_name,
        )

    def stacked(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(U, Y, groups)``: inputs (N, k), outputs (N, m), experiment name per row."""
        U = np.vstack([e.inputs for e in self.experiments])
        Y = np.vstack([e.outputs for e in self.experiments])
        groups = np.concatenate(
            [np.full(e.n_samples, e.name, dtype=object) for e in self.experiments]
        )
        return U, Y, groups


def from_experiments(experiments: Sequence[Any]) -> TimeSeriesSet:
    """Paper A's curling experiments as a set: pressure (kPa) in, ρ and L (mm) out.

    Parameters
    ----------
    experiments : sequence of Experiment
        :class:`~softbend.identification.data.Experiment` s (one pressure sign,
        as paper A models each sign on its own).
    """
    return TimeSeriesSet(
        ("pressure_kpa",),
        ("rho", "length_mm"),
        tuple(
            Series(
                e.name,
                e.time_s,
                np.asarray(e.pressure_kpa)[:, None],
                np.column_stack([e.rho, e.length_mm]),
                source=str(getattr(e, "source", "") or ""),
            )
            for e in experiments
        ),
    )
