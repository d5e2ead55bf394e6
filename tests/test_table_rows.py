"""pandas' C parser reads a plain file's rows to the very values and errors of the line reader."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import softbend.tables
from softbend.errors import DatasetError
from softbend.table_rows import row_lines
from softbend.tables import Column, HeaderKey, TableFormat, read_table

FORMAT = TableFormat(
    name="test CSV",
    columns=(
        Column("time_s", "s", quantity="time_s"),
        Column("pressure_kpa", "kPa", low=0.0, missing=True),
        Column("run", kind="text", required=False),
        Column("cycle", kind="integer", required=False, low=1),
        Column("mode", kind="choice", required=False, choices=("up", "down")),
    ),
    header=(HeaderKey("rig", required=True),),
    other_columns="keep",
)


def _both(path, fmt=FORMAT, monkeypatch=None, plain=True):
    """The table read as it is (by pandas where ``plain``) and by the line reader alone."""
    assert monkeypatch is not None
    parsed = []
    parse = softbend.tables.parse_rows
    with monkeypatch.context() as patch:
        patch.setattr(
            softbend.tables, "parse_rows", lambda *a: parsed.append(parse(*a)) or parsed[-1]
        )
        fast = read_table(path, fmt)
    assert (len(parsed) == 1 and parsed[0] is not None) == plain
    with monkeypatch.context() as patch:
        patch.setattr(softbend.tables, "_read_plain", lambda *args: None)
        slow = read_table(path, fmt)
    return fast, slow


def _same(fast, slow) -> None:
    pd.testing.assert_frame_equal(fast.frame, slow.frame, check_exact=True)
    assert [fast.frame[c].dtype for c in fast.frame] == [slow.frame[c].dtype for c in slow.frame]
    np.testing.assert_array_equal(fast.lines, slow.lines)
    assert (fast.header, fast.header_lines, fast.header_line) == (
        slow.header,
        slow.header_lines,
        slow.header_line,
    )
    assert (fast.positions, fast.columns) == (slow.positions, slow.columns)


BODY = (
    "time_s,pressure_kpa,run,cycle,mode,note,level,code\n"
    "0,0,a,1,up,x,1,7\n"
    "\n"
    "0.5,,a,2.0,down,,2.5,8\n"
    "1e-1,12.345678901234567,b,3,up,y_z,,9\n"
)


@pytest.mark.parametrize(
    "text",
    [
        "# rig: r\n" + BODY,
        "\ufeff# rig: r\n# a remark\n\n" + BODY,
        ("# rig: r\n" + BODY).replace("\n", "\r\n"),
        "# rig: r\n" + BODY.rstrip("\n"),
        "\ufeff# rig: r \u00b5-stage\n# r\u00e9sum\u00e9: none\n\n\n" + BODY,
    ],
    ids=["plain", "bom-and-remarks", "crlf", "no-final-newline", "non-ascii-header"],
)
def test_a_file_reads_the_same_through_pandas_and_line_by_line(tmp_path, monkeypatch, text):
    path = tmp_path / "t.csv"
    path.write_bytes(text.encode("utf-8"))
    fast, slow = _both(path, monkeypatch=monkeypatch)
    _same(fast, slow)
    assert fast.frame["code"].dtype == np.int64 and fast.frame["level"].dtype == np.float64
    header_line = fast.header_line
    assert fast.frame["cycle"].tolist() == [1, 2, 3]
    assert fast.lines.tolist() == [header_line + 1, header_line + 3, header_line + 4]


def test_random_numbers_read_to_the_same_bits(tmp_path, monkeypatch):
    rng = np.random.default_rng(7)
    values = rng.normal(size=(2000, 2)) * 10.0 ** rng.integers(-8, 9, size=(2000, 2))
    lines = [f"{abs(a)!r},{b!r},{i},{i % 5 + 1}" for i, (a, b) in enumerate(values.tolist())]
    path = tmp_path / "t.csv"
    path.write_text("# rig: r\ntime_s,pressure_kpa,other,cycle\n" + "\n".join(lines) + "\n")
    fmt = TableFormat(
        "test CSV",
        (Column("time_s"), Column("pressure_kpa"), Column("cycle", kind="integer")),
        header=FORMAT.header,
        other_columns="keep",
    )
    fast, slow = _both(path, fmt, monkeypatch)
    _same(fast, slow)
    assert fast.frame["time_s"].to_numpy().tobytes() == np.abs(values[:, 0]).tobytes()


@pytest.mark.parametrize(
    ("row", "message"),
    [
        ("0,n/a,a,1,up", r":3:2: pressure_kpa: must be a finite number >= 0 kPa; got .n/a."),
        ("0,-1,a,1,up", r":3:2: pressure_kpa: must be a finite number >= 0 kPa; got .-1."),
        ("0,1,a,1.5,up", r":3:4: cycle: must be an integer >= 1; got .1\.5."),
        ("0,1,a,1,sideways", r":3:5: mode: must be one of 'up', 'down'; got .sideways."),
        ("0,1,,1,up", r":3:3: run: must be non-empty text; got an empty cell"),
        ("inf,1,a,1,up", r":3:1: time_s: must be a finite number; got .inf."),
        ("0,1,a,1,up,extra", r":3: has 6 cells, but the header \(line 2\) has 5 columns"),
        ('"0",1,a,1,up', None),
        ("0, 1,a,1,up", None),
    ],
)
def test_a_bad_or_unusual_row_reads_as_the_line_reader_reads_it(
    tmp_path, monkeypatch, row, message
):
    path = tmp_path / "t.csv"
    path.write_text(f"# rig: r\ntime_s,pressure_kpa,run,cycle,mode\n{row}\n0.5,2,b,2,down\n")
    if message is None:  # quotes and spaces: the line reader reads the file
        _same(*_both(path, monkeypatch=monkeypatch, plain=False))
        return
    for reader in ("as it is", "line by line"):
        with monkeypatch.context() as patch:
            if reader == "line by line":
                patch.setattr(softbend.tables, "_read_plain", lambda *args: None)
            with pytest.raises(DatasetError, match=message):
                read_table(path, FORMAT)


def test_row_lines_finds_the_rows_of_a_plain_section_and_declines_the_rest():
    assert row_lines(b"1,2\n\n3,4\n", ",", 2, 100).tolist() == [0, 2]
    assert row_lines(b"1,2\r\n\r\n3,4", ",", 2, 100).tolist() == [0, 2]
    assert row_lines(b"1,2\n3\n", ",", 2, 100) is None  # a row of another width
    assert row_lines(b"1,2\r3,4\n", ",", 2, 100) is None  # a lone carriage return
    assert row_lines(b'1,"2"\n', ",", 2, 100) is None  # quotes
    assert row_lines(b"1, 2\n", ",", 2, 100) is None  # a space the line reader strips
    assert row_lines(b"1,2\n# note\n", ",", 2, 100) is None  # a comment line
    assert row_lines("1,\u00b52\n".encode(), ",", 2, 100) is None  # not ASCII
    assert row_lines(b"1,2\n", ",", 2, 2) is None  # a line over the field limit
    assert row_lines(b"\n\n", ",", 2, 100) is None  # no row
    assert row_lines(b"1,2,3\n4\n", ",", 2, 100) is None  # widths 3 and 1: 2 on average
    assert row_lines(b"1\n2,3,4\n", ",", 2, 100) is None
    assert row_lines(b"\n1,2\n\n\n3,4\n\n5,6", ",", 2, 100).tolist() == [1, 4, 6]
    assert row_lines(b"1;2\n3;4\n", ";", 2, 100).tolist() == [0, 1]
    # from an offset: the bytes before it (a header, remarks) are not the section's
    assert row_lines(b'# "\xb5"\na,b\n1,2\n\n3,4', ",", 2, 100, 10).tolist() == [0, 2]
    assert row_lines(b"a,b\n1,2\n", ",", 2, 100, 8) is None  # nothing after the offset
    assert row_lines(b"1;2\n3,4\n", ";", 2, 100) is None  # a comma is text here


def _rows_line_by_line(data: bytes, separator: str, width: int, field_limit: int) -> list | None:
    """What :func:`row_lines` finds, one line at a time (its definition)."""
    text = data.decode("ascii", errors="replace")
    if not data.isascii() or any(c in text for c in '"\0# \t\x0b\x0c\x1c\x1d\x1e\x1f'):
        return None
    if text.count("\r") != text.count("\r\n"):
        return None
    lines = text.split("\n")
    if text.endswith("\n"):
        lines = lines[:-1]
    rows = []
    for number, line in enumerate(lines):
        line = line.removesuffix("\r")
        if not line:
            continue
        if len(line) > field_limit or line.count(separator) != width - 1:
            return None
        rows.append(number)
    return rows or None


def test_row_lines_agrees_with_reading_line_by_line_on_random_sections():
    rng = np.random.default_rng(7)
    alphabet = [b"1", b"2", b",", b",", b"\n", b"\n", b"\r\n", b"x", b" ", b'"']
    agreed = 0
    for _ in range(3000):
        pieces = rng.choice(len(alphabet), size=int(rng.integers(1, 14)))
        data = b"".join(alphabet[k] for k in pieces)
        width = int(rng.integers(1, 4))
        found = row_lines(data, ",", width, 5)
        expected = _rows_line_by_line(data, ",", width, 5)
        assert (found.tolist() if found is not None else None) == expected, (data, width)
        agreed += found is not None
    assert agreed > 100  # plain sections were drawn, not only declined ones


@pytest.mark.parametrize("where", ["header", "row"])
def test_a_file_not_utf8_is_the_line_readers_one_error(tmp_path, where):
    head, row = b"# rig: r\n", b"0.5,2\n"
    if where == "header":
        head = b"# rig: r\xff\n"
    else:
        row = b"0.5,2\xff\n"
    path = tmp_path / "t.csv"
    path.write_bytes(head + b"time_s,pressure_kpa\n" + row)
    offset = (head + b"time_s,pressure_kpa\n" + row).index(b"\xff")
    with pytest.raises(DatasetError, match=f"not UTF-8 text .undecodable byte at offset {offset}"):
        read_table(path, FORMAT)
