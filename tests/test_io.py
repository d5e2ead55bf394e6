"""Atomic writes: all or nothing, and the permissions a plain ``open`` would give."""

from __future__ import annotations

import os
import stat

import pytest

from softbend._io import atomic_file, write_bytes_atomic, write_text_atomic


@pytest.fixture
def umask():
    """Set the process umask for one test and restore it afterwards."""
    saved = os.umask(0o022)
    os.umask(saved)
    yield os.umask
    os.umask(saved)


def _mode(path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.mark.parametrize("mask", [0o022, 0o002, 0o077])
def test_a_new_file_gets_0666_less_the_umask_as_with_open(tmp_path, umask, mask):
    umask(mask)
    (tmp_path / "plain.txt").write_text("x")
    write_text_atomic(tmp_path / "atomic.txt", "x")
    write_bytes_atomic(tmp_path / "atomic.bin", b"x")
    assert _mode(tmp_path / "atomic.txt") == _mode(tmp_path / "plain.txt") == 0o666 & ~mask
    assert _mode(tmp_path / "atomic.bin") == 0o666 & ~mask


def test_a_replaced_file_keeps_its_permissions(tmp_path, umask):
    umask(0o077)
    path = tmp_path / "shared.json"
    path.write_text("old")
    path.chmod(0o644)
    write_text_atomic(path, "new")
    assert path.read_text() == "new" and _mode(path) == 0o644


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "a.csv"
    path.write_text("old\n")
    with pytest.raises(OSError, match="No space left"), atomic_file(path) as handle:
        handle.write("half")
        raise OSError(28, "No space left on device")
    assert path.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]


def test_text_is_utf8_and_the_folder_is_created(tmp_path):
    path = write_text_atomic(tmp_path / "new" / "t.txt", "λ ≤ 4\n")
    assert path.read_bytes() == "λ ≤ 4\n".encode()
    with pytest.raises(ValueError, match="'mode' of atomic_file"), atomic_file(path, "a"):
        pass


def test_json_text_is_strict_json_with_nan_as_null():
    import json

    import numpy as np

    from softbend._io import json_text

    payload = {
        "nan": float("nan"),
        "inf": [np.inf, -np.inf, 1.5],
        "array": np.array([1.0, np.nan]),
        "scalar": np.float32(0.25),
        "count": np.int64(3),
        3: "key as text",
        "path": __import__("pathlib").Path("a/b"),
    }
    text = json_text(payload)

    def refuse(name):
        raise AssertionError(name)

    back = json.loads(text, parse_constant=refuse)
    assert back == {
        "nan": None,
        "inf": [None, None, 1.5],
        "array": [1.0, None],
        "scalar": 0.25,
        "count": 3,
        "3": "key as text",
        "path": "a/b",
    }


def test_atomic_files_replace_all_targets_or_none(tmp_path):
    import pytest

    from softbend._io import atomic_files

    a, b = tmp_path / "run.csv", tmp_path / "run.png"
    a.write_text("old a")
    b.write_text("old b")
    with pytest.raises(OSError, match="full"), atomic_files(a, b) as (ta, tb):
        assert ta.suffix == ".csv" and tb.suffix == ".png" and ta.parent == tmp_path
        ta.write_text("new a")
        raise OSError(28, "full")
    assert a.read_text() == "old a" and b.read_text() == "old b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv", "run.png"]
    with atomic_files(a, b, tmp_path / "skipped.txt") as (ta, tb, _):
        ta.write_text("new a")
        tb.write_text("new b")
    assert a.read_text() == "new a" and b.read_text() == "new b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv", "run.png"]


def test_read_input_text_checks_the_size_limit_and_the_encoding(tmp_path, monkeypatch):
    import pytest

    from softbend._io import read_input_text
    from softbend.errors import DatasetError, LimitError, SchemaError

    good = tmp_path / "a.csv"
    good.write_bytes(b"\xef\xbb\xbfx,y\n1,2\n")
    assert read_input_text(good, "a.csv", encoding="utf-8-sig") == "x,y\n1,2\n"
    bad = tmp_path / "b.csv"
    bad.write_bytes(b"x,y\n1,\xe92\n")
    with pytest.raises(
        DatasetError, match=r"^The file b is not UTF-8 text \(undecodable byte at offset 6\)\.$"
    ):
        read_input_text(bad, "The file b")
    with pytest.raises(SchemaError, match="not UTF-8 text"):
        read_input_text(bad, "The file b", error=SchemaError)
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    (tmp_path / "big.csv").write_bytes(b"x" * (2 * 2**20))
    with pytest.raises(LimitError, match=r"^The big file is 2.0 MiB"):
        read_input_text(tmp_path / "big.csv", "The big file")


# ----------------------------------------------------------- the commented CSV reader


def _lines(path, **kwargs):
    from softbend._io import read_header_csv

    return [(c.number, c.kind, c.cells, c.key, c.value) for c in read_header_csv(path, **kwargs)]


def test_read_header_csv_yields_metadata_header_and_rows_numbered_as_an_editor_shows(tmp_path):
    path = tmp_path / "m.csv"
    text = (
        "\ufeff# softbend measurements CSV v1\n"  # a comment with no colon: skipped
        "#  rig :  bench 2: left \n"  # split at the first colon, both sides stripped
        "#: no key\n"  # an empty key: skipped
        "\n"
        "  # operator: AB\r\n"
        " a , b ,c\r"
        "1, 2 ,3\n"
        "# after: the header is a comment, not metadata\n"
        "\n"
        '4,"5, five",6\n'
    )
    path.write_text(text, encoding="utf-8")
    assert _lines(path) == [
        (2, "meta", (), "rig", "bench 2: left"),
        (5, "meta", (), "operator", "AB"),
        (6, "header", ("a", "b", "c"), "", ""),
        (7, "row", ("1", "2", "3"), "", ""),
        (10, "row", ("4", "5, five", "6"), "", ""),
    ]


def test_read_header_csv_without_rows_or_header(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("# note: only comments\n\n", encoding="utf-8")
    assert _lines(empty) == [(1, "meta", (), "note", "only comments")]
    header = tmp_path / "header.csv"
    header.write_text("x,y", encoding="utf-8")
    assert _lines(header) == [(1, "header", ("x", "y"), "", "")]


def test_read_header_csv_names_the_file_and_line_a_csv_row_fails_on(tmp_path):
    import pytest

    from softbend._io import read_header_csv
    from softbend.errors import DatasetError

    path = tmp_path / "long.csv"
    path.write_text("x,y\n1,2\n3," + "4" * 200_000 + "\n5,6\n", encoding="utf-8")
    lines = read_header_csv(path)
    assert next(lines).kind == "header" and next(lines).cells == ("1", "2")
    with pytest.raises(DatasetError, match=rf"^{path}:3: not a CSV row \(field larger") as info:
        next(lines)
    assert (info.value.file, info.value.line) == (str(path), 3)


def test_read_header_csv_checks_the_encoding_and_the_limits_before_any_row(tmp_path, monkeypatch):
    import pytest

    from softbend._io import read_header_csv
    from softbend.errors import DatasetError, LimitError

    bad = tmp_path / "bad.csv"
    bad.write_bytes(b"x,y\n1,\xe92\n")
    with pytest.raises(DatasetError, match="not UTF-8 text"):
        next(read_header_csv(bad))
    rows = tmp_path / "rows.csv"
    rows.write_text("# a: b\nx\n" + "1\n" * 6 + "\n# c\n", encoding="utf-8")
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "6")
    assert len(_lines(rows)) == 8  # six data rows: at the limit
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "5")
    lines = read_header_csv(rows)
    with pytest.raises(LimitError, match="6 rows") as info:
        next(lines)  # refused before the first line is yielded
    assert "SOFTBEND_MAX_CSV_ROWS" in str(info.value)
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    (tmp_path / "big.csv").write_bytes(b"x\n" * 2**20)
    with pytest.raises(LimitError, match="MiB"):
        next(read_header_csv(tmp_path / "big.csv"))
