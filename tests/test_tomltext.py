"""TOML input files read under the size, encoding and nesting limits, one line per fault."""

from __future__ import annotations

import pytest

from softbend._tomltext import parse_toml, read_toml, toml_nesting
from softbend.errors import DatasetError, LimitError


def test_depth_counts_arrays_and_inline_tables_not_strings_or_comments():
    text = 'a = [[1, 2], [3]]\nb = {c = {d = [1]}}\ns = "[[[[{{{"\n# [[[[[[\nm = """\n[[[\n"""\n'
    assert toml_nesting(text).depth == 3
    assert parse_toml(text, "x.toml")["s"] == "[[[[{{{"


def test_table_headers_count_only_on_their_line():
    assert toml_nesting("[a]\nx = 1\n[[b]]\ny = [1]\n").depth == 2


@pytest.mark.parametrize(
    "text",
    ["a = " + "[" * 20_000 + "]" * 20_000, "a = " + "{b = " * 3_000 + "1" + "}" * 3_000],
)
def test_deep_nesting_is_one_line_before_the_parser(text):
    with pytest.raises(DatasetError) as info:
        parse_toml(text, "deep.toml")
    message = str(info.value)
    assert message.startswith("deep.toml, line 1: nested")
    assert "under the key 'a'" in message and "SOFTBEND_MAX_NESTING" in message


def test_deep_dotted_tables_are_refused_after_parsing():
    text = "[" + ".".join(["t"] * 100) + "]\nx = 1\n"
    with pytest.raises(DatasetError, match=r"tables .* nested 101 levels"):
        parse_toml(text, "dotted.toml")


def test_the_limit_follows_the_environment(monkeypatch):
    text = "a = " + "[" * 70 + "]" * 70
    with pytest.raises(DatasetError):
        parse_toml(text, "x.toml")
    monkeypatch.setenv("SOFTBEND_MAX_NESTING", "100")
    assert parse_toml(text, "x.toml")["a"]


def test_a_syntax_error_names_line_and_column():
    with pytest.raises(DatasetError) as info:
        parse_toml("a = 1\nb = = 2\n", "bad.toml")
    assert str(info.value).startswith("bad.toml, line 2, column 5: not valid TOML: ")


@pytest.mark.parametrize(
    "data",
    [b"\x89PNG\r\n\x1a\n\x00\x00", "a = 1\n".encode("utf-16"), b"a = \x80\n"],
)
def test_binary_or_utf16_files_are_named(tmp_path, data):
    path = tmp_path / "spec.toml"
    path.write_bytes(data)
    with pytest.raises(DatasetError) as info:
        read_toml(path, "spec.toml")
    message = str(info.value)
    assert message.startswith("spec.toml is not")
    assert "codec" not in message


def test_a_missing_file_and_an_oversized_one(tmp_path, monkeypatch):
    with pytest.raises(FileNotFoundError, match=r"nope\.toml does not exist"):
        read_toml(tmp_path / "nope.toml", "nope.toml")
    big = tmp_path / "big.toml"
    big.write_text("a = 1\n" * 200_000)
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    with pytest.raises(LimitError, match=r"big\.toml"):
        read_toml(big, "big.toml")
