"""The one rule by which a name from a file or an option becomes a path."""

from __future__ import annotations

import pytest

from softbend._names import MAX_NAME_CHARS, check_output_names, output_name


@pytest.mark.parametrize(
    "name",
    ["stiff", "gripper finger", "spec_2", "v1.5", "Fingerspitze-ä", "a" * MAX_NAME_CHARS],
)
def test_plain_names_pass_unchanged(name):
    assert output_name(name) == name


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("", "is empty"),
        (".", "starts with '.'"),
        ("..", "starts with '.'"),
        (".hidden", "starts with '.'"),
        ("../../escaped_spec", "path separator"),
        ("/home/me/notes", "path separator"),
        ("a/b", "path separator"),
        ("a\\b", "path separator"),
        ("C:spec", "names a drive"),
        (" padded", "space"),
        ("padded ", "space"),
        ("tab\there", "character '\\t'"),
        ("new\nline", "character '\\n'"),
        ("star*", "character '*'"),
        ("NUL", "device name"),
        ("com1.txt", "device name"),
        ("a" * (MAX_NAME_CHARS + 1), "characters"),
    ],
)
def test_names_that_are_not_plain_entries_are_refused(name, why):
    with pytest.raises(ValueError) as info:
        output_name(name)
    message = str(info.value)
    assert message.startswith("name: must be a plain name of a folder or file")
    assert info.value.key == "name"
    assert why in message
    assert "\n" not in message


@pytest.mark.parametrize("name", [3, None, ["a"]])
def test_a_name_must_be_text(name):
    with pytest.raises(ValueError, match="must be a text name"):
        output_name(name)


def test_reserved_names_are_refused_ignoring_case():
    with pytest.raises(ValueError, match="writes itself"):
        output_name("Search.JSON", reserved=("search.json", "candidates.csv"))


def test_a_second_result_of_the_same_name_is_refused():
    with pytest.raises(ValueError, match="given twice"):
        check_output_names(["a", "b", "a"])
    with pytest.raises(ValueError, match=r"^names: name 2 must be .*only in case"):
        check_output_names(["Stiff", "stiff"])
    assert check_output_names(["a", "b"]) == ["a", "b"]


def test_the_name_at_fault_is_counted_and_repeated_reserved_names_are_listed_once():
    with pytest.raises(ValueError, match=r"^names: name 2 must be a plain name.*is empty"):
        check_output_names(["a", ""])
    with pytest.raises(ValueError) as info:
        output_name("x.csv", reserved=("x.csv", "x.csv"))
    assert "(x.csv)" in str(info.value)
