"""One recording cut into contiguous segments for selection and validation."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.errors import InputError
from softbend.identification.segments import (
    MIN_SEGMENT_SAMPLES,
    MIN_SEGMENTS,
    split_recording,
)
from softbend.identification.timeseries import Series, TimeSeriesSet


def _recording(n: int) -> TimeSeriesSet:
    rng = np.random.default_rng(0)
    u = rng.normal(size=n)
    series = Series("rec", 0.02 * np.arange(n), u, np.cumsum(u), source="rec.csv")
    return TimeSeriesSet(("u",), ("y",), (series,), "time_s")


def test_the_recording_is_cut_in_time_order_the_last_segment_for_validation():
    data = _recording(200)
    split = split_recording(data, folds=4)
    assert [(first, stop) for _, first, stop in split.ranges] == [
        (0, 40), (40, 80), (80, 120), (120, 160), (160, 200)
    ]  # fmt: skip
    assert split.validation == ("rec[160:200]",) and len(split.train) == 4
    joined = np.concatenate([e.outputs[:, 0] for e in split.data.experiments])
    np.testing.assert_array_equal(joined, data.experiments[0].outputs[:, 0])
    record = split.to_dict()
    assert record["segments"][-1] == {
        "name": "rec[160:200]", "first_sample": 160, "last_sample": 199, "role": "validation"
    }  # fmt: skip
    assert {s["role"] for s in record["segments"][:-1]} == {"selection"}
    assert "selection on samples 0–159" in split.summary()
    assert "validation on samples 160–199" in split.summary()


def test_a_short_recording_has_fewer_segments_down_to_three():
    split = split_recording(_recording(MIN_SEGMENTS * MIN_SEGMENT_SAMPLES), folds=4)
    assert len(split.ranges) == MIN_SEGMENTS


def test_a_recording_too_short_to_split_names_the_experiment_column():
    with pytest.raises(InputError, match=r"one recording 'rec' \(rec\.csv\) of 89 samples, "
                       r"too short to split") as caught:  # fmt: skip
        split_recording(_recording(MIN_SEGMENTS * MIN_SEGMENT_SAMPLES - 1), folds=4)
    assert caught.value.key == "experiment"
