"""SearchCheckpoint: durable folds, torn lines, other searches, a second writer."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.errors import SoftbendError
from softbend.surrogates.checkpoint import SearchCheckpoint, checkpoint_path, group_id

FINGERPRINT = {"data_hash": "abc", "folds": 3, "seed": 0, "configs": {"plr": [{"degree": 2}]}}


def _messages():
    said: dict[str, list[str]] = {"resume": [], "discard": []}
    return said, {"on_resume": said["resume"].append, "on_discard": said["discard"].append}


def test_the_path_lies_beside_the_output_folder(tmp_path):
    path = checkpoint_path(tmp_path / "surrogates")
    assert path.parent == tmp_path
    assert path.name == ".surrogates.train-checkpoint.jsonl"


def test_nothing_is_written_before_the_search_starts(tmp_path):
    with SearchCheckpoint(tmp_path / "c.jsonl"):
        pass
    assert not (tmp_path / "c.jsonl").exists()


def test_folds_come_back_bit_for_bit_after_reopening(tmp_path):
    path = tmp_path / "c.jsonl"
    pred = np.random.default_rng(0).normal(size=7) * 1e3
    pred[2] = np.nextafter(1.0, 2.0)
    with SearchCheckpoint(path) as first:
        assert first.start(FINGERPRINT) == 0
        first.add("plr", {"degree": 2}, 0, pred, 0.5)
        first.add("mlp", {"hidden_sizes": (8, 8)}, 1, pred[:3], 0.1, epochs=20, group="g")
    said, hooks = _messages()
    with SearchCheckpoint(path, **hooks) as again:
        assert again.start(FINGERPRINT) == 2
        got, seconds = again.get("plr", {"degree": 2}, 0, size=7)
        np.testing.assert_array_equal(got, pred)
        assert seconds == 0.5
        # tuples and lists are the same configuration; epochs and group tell MLPs apart
        mlp = again.get("mlp", {"hidden_sizes": [8, 8]}, 1, size=3, epochs=20, group="g")
        np.testing.assert_array_equal(mlp[0], pred[:3])
        assert again.get("mlp", {"hidden_sizes": (8, 8)}, 1, size=3, epochs=40, group="g") is None
        assert again.get("plr", {"degree": 2}, 1, size=7) is None  # another fold
        assert again.get("plr", {"degree": 2}, 0, size=6) is None  # another fold's size
    assert said["discard"] == []
    assert len(said["resume"]) == 1 and "2 configuration-folds" in said["resume"][0]


def test_a_line_cut_by_a_kill_is_dropped_and_later_folds_still_read(tmp_path):
    path = tmp_path / "c.jsonl"
    with SearchCheckpoint(path) as first:
        first.start(FINGERPRINT)
        first.add("plr", {"degree": 2}, 0, np.arange(4.0), 0.1)
    whole = path.read_bytes()
    with open(path, "ab") as handle:  # the kill came in the middle of the next line
        handle.write(b'{"key":["plr",{"degree":2},1,null,null],"seconds":0.1,"pred":"AAA')
    with SearchCheckpoint(path) as again:
        assert again.start(FINGERPRINT) == 1
        assert path.read_bytes() == whole
        again.add("plr", {"degree": 2}, 1, np.arange(4.0) + 1, 0.1)
    with SearchCheckpoint(path) as third:
        assert third.start(FINGERPRINT) == 2


def test_a_checkpoint_of_another_search_is_discarded_with_one_message(tmp_path):
    path = tmp_path / "c.jsonl"
    with SearchCheckpoint(path) as first:
        first.start(FINGERPRINT)
        first.add("plr", {"degree": 2}, 0, np.arange(4.0), 0.1)
    said, hooks = _messages()
    other = {**FINGERPRINT, "folds": 4, "seed": 1}
    with SearchCheckpoint(path, **hooks) as again:
        assert again.start(other) == 0
        assert again.get("plr", {"degree": 2}, 0, size=4) is None
    assert said["resume"] == []
    assert len(said["discard"]) == 1
    assert "other settings (folds, seed)" in said["discard"][0] and str(path) in said["discard"][0]
    header = json.loads(path.read_text().splitlines()[0])
    assert header["fingerprint"] == other  # the file now belongs to the new search


@pytest.mark.parametrize("content", [b"not json\n", b"[1, 2]\n", b"\x00\x01garbage"])
def test_an_unreadable_file_is_discarded(tmp_path, content):
    path = tmp_path / "c.jsonl"
    path.write_bytes(content)
    said, hooks = _messages()
    with SearchCheckpoint(path, **hooks) as checkpoint:
        assert checkpoint.start(FINGERPRINT) == 0
    assert len(said["discard"]) == 1 and "not a readable search checkpoint" in said["discard"][0]


def test_a_second_search_on_the_same_file_is_refused(tmp_path):
    path = tmp_path / "c.jsonl"
    with SearchCheckpoint(path) as first:
        first.start(FINGERPRINT)
        with pytest.raises(SoftbendError, match="Another search is writing the checkpoint"):
            SearchCheckpoint(path).start(FINGERPRINT)
    with SearchCheckpoint(path) as after:  # released when the first one closed
        assert after.start(FINGERPRINT) == 0


def test_remove_deletes_the_file_and_one_checkpoint_serves_one_search(tmp_path):
    path = tmp_path / "c.jsonl"
    checkpoint = SearchCheckpoint(path)
    checkpoint.start(FINGERPRINT)
    assert checkpoint.start(dict(FINGERPRINT)) == 0  # the same search again: fine
    with pytest.raises(ValueError, match="another search"):
        checkpoint.start({**FINGERPRINT, "seed": 3})
    checkpoint.remove()
    assert not path.exists()
    with pytest.raises(ValueError, match="not started"):
        checkpoint.add("plr", {"degree": 2}, 0, np.zeros(2), 0.0)


def test_group_id_depends_on_the_configurations_and_their_order():
    assert group_id([(8, 8), (16, 16)]) == group_id([[8, 8], [16, 16]])
    assert group_id([(8, 8), (16, 16)]) != group_id([(8, 8)])
    assert group_id([(8, 8), (16, 16)]) != group_id([(16, 16), (8, 8)])
