"""One recording split into contiguous segments for selection and validation.

:func:`~softbend.identification.selection.select_model` holds out whole experiments, so a
set of one experiment (a single recording, no experiment column) has nothing to hold out.
:func:`split_recording` cuts such a recording into equal contiguous segments in time order:
the last one is kept for validation, each of the others is one cross-validation fold. Every
segment is run free from its own first samples, as an experiment is. The split is recorded
(:meth:`RecordingSplit.to_dict`, which sample ranges went where) and said in one line
(:meth:`RecordingSplit.summary`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend.errors import InputError
from softbend.identification.timeseries import Series, TimeSeriesSet

__all__ = ["MIN_SEGMENTS", "MIN_SEGMENT_SAMPLES", "RecordingSplit", "split_recording"]

#: Samples a segment needs at least: ten times the longest lag of the default candidates
#: (3), so that its free run is more than its initial conditions.
MIN_SEGMENT_SAMPLES = 30
#: Segments a split needs at least: two to cross-validate on (one held out at a time) and
#: one for validation.
MIN_SEGMENTS = 3


@dataclass(frozen=True)
class RecordingSplit:
    """A recording cut into segments: the set of segments and where each came from.

    Attributes
    ----------
    data : TimeSeriesSet
        The segments, each a :class:`~softbend.identification.timeseries.Series` named
        ``<recording>[<first>:<stop>]`` (sample indices of the recording, stop excluded).
    recording : str
        The recording's (experiment's) name.
    ranges : tuple of (str, int, int)
        ``(segment, first, stop)`` of every segment, in time order.
    validation : tuple of str
        The segment kept out of the selection (the last one).
    """

    data: TimeSeriesSet
    recording: str
    ranges: tuple[tuple[str, int, int], ...]
    validation: tuple[str, ...]

    @property
    def train(self) -> tuple[str, ...]:
        """The segments the selection is cross-validated on, one fold each."""
        return tuple(name for name, _, _ in self.ranges if name not in self.validation)

    def _span(self, names: tuple[str, ...]) -> str:
        spans = [(first, stop) for name, first, stop in self.ranges if name in names]
        return f"{spans[0][0]}–{spans[-1][1] - 1}"

    def summary(self) -> str:
        """One line: the recording, the segments and which samples went where."""
        n = self.ranges[-1][2]
        return (
            f"One recording ({self.recording!r}, {n:,} samples, no experiment column): split "
            f"into {len(self.ranges)} contiguous segments; selection on samples "
            f"{self._span(self.train)} ({len(self.train)} segments, one cross-validation fold "
            f"each), validation on samples {self._span(self.validation)} (the last segment)."
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: the recording and every segment's sample range and role."""
        return {
            "recording": self.recording,
            "samples": self.ranges[-1][2],
            "segments": [
                {
                    "name": name,
                    "first_sample": first,
                    "last_sample": stop - 1,
                    "role": "validation" if name in self.validation else "selection",
                }
                for name, first, stop in self.ranges
            ],
        }


def split_recording(data: TimeSeriesSet, folds: int) -> RecordingSplit:
    """Split a set of one recording into contiguous segments for selection and validation.

    Parameters
    ----------
    data : TimeSeriesSet
        Exactly one experiment.
    folds : int
        The cross-validation folds wanted (>= 2): the recording is cut into ``folds + 1``
        equal segments, or fewer (at least :data:`MIN_SEGMENTS`) where a segment would have
        fewer than :data:`MIN_SEGMENT_SAMPLES` samples.

    Returns
    -------
    RecordingSplit
        The segments in time order; the last one is the validation segment.

    Raises
    ------
    InputError
        With the key ``experiment``: a recording shorter than
        ``MIN_SEGMENTS * MIN_SEGMENT_SAMPLES`` samples (too short to split), naming its
        samples and the samples needed.
    ValueError
        ``data`` with more than one experiment.
    """
    if len(data.experiments) != 1:
        raise ValueError(
            f"split_recording takes a set of one recording; got {len(data.experiments)}."
        )
    (recording,) = data.experiments
    n = recording.n_samples
    count = min(int(folds) + 1, n // MIN_SEGMENT_SAMPLES)
    if count < MIN_SEGMENTS:
        source = f" ({recording.source})" if recording.source else ""
        raise InputError(
            f"not given, and the data is one recording {recording.name!r}{source} of {n} "
            f"samples, too short to split into {MIN_SEGMENTS} segments of at least "
            f"{MIN_SEGMENT_SAMPLES} samples for selection and validation (needs "
            f"{MIN_SEGMENTS * MIN_SEGMENT_SAMPLES}); name a column that splits it into "
            "experiments, or record longer",
            key="experiment",
        )
    bounds = np.linspace(0, n, count + 1).round().astype(int)
    segments, ranges = [], []
    for first, stop in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        name = f"{recording.name}[{first}:{stop}]"
        segments.append(
            Series(
                name,
                recording.time[first:stop],
                recording.inputs[first:stop],
                recording.outputs[first:stop],
                source=recording.source,
            )
        )
        ranges.append((name, first, stop))
    split = TimeSeriesSet(data.input_names, data.output_names, tuple(segments), data.time_name)
    return RecordingSplit(split, recording.name, tuple(ranges), (ranges[-1][0],))
