"""Uniaxial tensile data: the shipped Marechal et al. tests and the file parser."""

import json
from importlib import resources

import numpy as np
import pytest

from softbend.errors import DatasetError, LimitError
from softbend.materials import (
    SHIPPED_ATTRIBUTION,
    TensileTest,
    load_shipped,
    load_tensile_csv,
    shipped_tensile_tests,
)

#: Data rows of each shipped file (counted from the files themselves).
SHIPPED_ROWS = {
    "dragon-skin-10-medium": 457,
    "dragon-skin-20": 404,
    "dragon-skin-30": 311,
    "ecoflex-0030": 705,
    "ecoflex-0050": 721,
}
HEADER = "Time (s);True Strain;True Stress (MPa);Engineering Strain;Engineering Stress (MPa)"
METADATA = [
    "PARAMETER;INFO;URL;;",
    "Standard;ASTM D412;;;",
    "Material supplier;Smooth-On;https://example.org/ds30;;",
    "Material;TestSilicone;;;",
    ";;;;",
]


def _rows(n, start=0.05, step=0.05):
    """``n`` well-formed data rows (time; true strain; true stress; eng. strain; eng. stress)."""
    rows = []
    for i in range(n):
        eps = start + step * i
        sig = 0.4 * eps
        rows.append(f"{0.1 * i:.1f};{np.log1p(eps):.6f};{sig * (1 + eps):.6f};{eps:.6f};{sig:.6f}")
    return rows


def _write(tmp_path, rows, *, header=HEADER, metadata=METADATA, name="Test_Silicone.csv"):
    path = tmp_path / name
    path.write_text("\n".join([*metadata, header, *rows]) + "\n", encoding="utf-8")
    return path


def test_shipped_names():
    assert shipped_tensile_tests() == tuple(sorted(SHIPPED_ROWS))


def _reference_columns(path):
    """Engineering strain and stress read independently: fixed layout, 18 lines to skip."""
    table = np.loadtxt(path, delimiter=";", skiprows=18, usecols=(3, 4))
    return table[:, 0], table[:, 1]


@pytest.mark.parametrize("name", sorted(SHIPPED_ROWS))
def test_shipped_round_trip(name):
    test = load_shipped(name)
    assert test.name == name
    assert test.n_points == SHIPPED_ROWS[name]
    assert test.source is not None and test.source.is_file()
    strain, stress = _reference_columns(test.source)
    np.testing.assert_array_equal(test.engineering_strain, strain)
    np.testing.assert_array_equal(test.engineering_stress_mpa, stress)
    np.testing.assert_allclose(test.stretch, 1.0 + strain, rtol=0, atol=0)
    # Pull to failure from (almost) rest: the strain starts small and rises.
    assert 0.0 <= test.engineering_strain[0] < 0.1
    assert np.all(np.diff(test.engineering_strain[:50]) > 0.0)
    # Silicones fail at several hundred percent strain and a few MPa.
    assert 5.0 < test.max_strain < 20.0
    assert 1.0 < test.engineering_stress_mpa.max() < 6.0
    assert test.metadata["Standard"] == "ASTM D412"
    assert test.metadata["Type of test"] == "Pull-to-failure"
    assert test.attribution == SHIPPED_ATTRIBUTION
    # A file path loads the same arrays as the package resource.
    again = load_tensile_csv(test.source)
    assert again.name == name
    np.testing.assert_array_equal(again.engineering_stress_mpa, test.engineering_stress_mpa)


def test_dragon_skin_30_units_and_metadata():
    test = load_shipped("dragon-skin-30")
    assert test.material == "Dragon Skin 30"
    assert test.metadata["Material"] == "DragonSkin30"
    assert test.metadata["Specimen Cross-section (cm^2)"] == "0.18"
    assert test.metadata["Material supplier URL"].startswith("https://www.smooth-on.com/")
    # MPa, not kPa or Pa: about 0.44 MPa at 100 % strain (Smooth-On quotes 0.59 MPa).
    at_100 = np.interp(1.0, test.engineering_strain, test.engineering_stress_mpa)
    assert 0.2 < at_100 < 1.0
    assert test.max_strain == pytest.approx(7.09091)
    assert test.engineering_stress_mpa.max() == pytest.approx(4.15491)


def test_attribution_and_licence_ship_beside_the_data():
    folder = resources.files("softbend").joinpath("data", "materials")
    readme = folder.joinpath("README.md").read_text(encoding="utf-8")
    licence = folder.joinpath("LICENSE-ODbL.md").read_text(encoding="utf-8")
    assert "Marechal" in readme and "10.1089/soro.2019.0115" in readme
    assert "Open Database License" in licence
    assert "Marechal" in SHIPPED_ATTRIBUTION and "ODbL" in SHIPPED_ATTRIBUTION


def test_unknown_shipped_name_lists_the_allowed_names():
    with pytest.raises(ValueError, match=r"^name: must be one of 'dragon-skin-10-medium'") as info:
        load_shipped("dragon-skin-40")
    message = str(info.value)
    assert '"dragon-skin-40"' in message
    for name in SHIPPED_ROWS:
        assert repr(name) in message


def test_header_is_found_by_name_with_other_layouts(tmp_path):
    # Two metadata lines, no blank line, columns reordered, an extra column.
    rows = [f"{0.1 * i:.1f};x;{0.4 * 0.1 * i:.4f};{0.1 * i:.4f}" for i in range(1, 8)]
    path = _write(
        tmp_path,
        rows,
        header="Time (s);Comment;Engineering Stress (MPa);Engineering Strain",
        metadata=["Material;Mine;;", "Lab;Here;;"],
        name="My_Rubber.csv",
    )
    test = load_tensile_csv(path)
    assert test.name == "my-rubber"
    assert test.material == "Mine"
    assert test.metadata == {"Material": "Mine", "Lab": "Here"}
    np.testing.assert_allclose(test.engineering_strain, 0.1 * np.arange(1, 8))
    np.testing.assert_allclose(test.engineering_stress_mpa, 0.04 * np.arange(1, 8))
    assert test.attribution == ""


def test_metadata_and_trailing_blank_lines(tmp_path):
    path = _write(tmp_path, [*_rows(6), ";;;;", ""])
    test = load_tensile_csv(path, name="sample", material="Sample silicone")
    assert (test.name, test.material, test.n_points) == ("sample", "Sample silicone", 6)
    assert test.metadata["Material supplier URL"] == "https://example.org/ds30"
    assert "PARAMETER" not in test.metadata


@pytest.mark.parametrize(
    "missing", ["Engineering Strain", "Engineering Stress (MPa)"], ids=["strain", "stress"]
)
def test_missing_column_names_column_file_and_found_columns(tmp_path, missing):
    renamed = {"Engineering Strain": "Eng Strain", "Engineering Stress (MPa)": "Eng Stress (kPa)"}
    header = HEADER.replace(missing, renamed[missing])
    path = _write(tmp_path, _rows(6), header=header)
    with pytest.raises(DatasetError) as info:
        load_tensile_csv(path)
    message = str(info.value)
    assert repr(missing) in message
    assert "Test_Silicone.csv" in message
    assert repr(renamed[missing]) in message and "'Time (s)'" in message


def test_header_without_any_known_column_still_lists_what_it_has(tmp_path):
    path = _write(tmp_path, ["0.1;0.04", "0.2;0.08"] * 3, header="strain;stress")
    with pytest.raises(DatasetError, match="Engineering Strain") as info:
        load_tensile_csv(path)
    assert "'strain', 'stress'" in str(info.value)


@pytest.mark.parametrize("bad", ["nan", "abc", "", "inf"])
def test_non_numeric_value_names_column_and_row(tmp_path, bad):
    rows = _rows(8)
    cells = rows[2].split(";")
    cells[4] = bad  # engineering stress of the third data row
    rows[2] = ";".join(cells)
    path = _write(tmp_path, rows)
    with pytest.raises(DatasetError) as info:
        load_tensile_csv(path)
    message = str(info.value)
    assert "'Engineering Stress (MPa)'" in message
    assert "data row 3" in message and f"line {len(METADATA) + 1 + 3}" in message
    assert repr(bad) in message


def test_nan_outside_the_used_columns_is_ignored(tmp_path):
    rows = _rows(6)
    rows[1] = "nan;" + rows[1].split(";", 1)[1]
    assert load_tensile_csv(_write(tmp_path, rows)).n_points == 6


def test_negative_strain_names_the_row(tmp_path):
    rows = _rows(6)
    cells = rows[4].split(";")
    cells[3] = "-0.01"
    rows[4] = ";".join(cells)
    with pytest.raises(DatasetError, match=r"\[0, inf\).*'-0.01' at data row 5"):
        load_tensile_csv(_write(tmp_path, rows))


def test_short_row_names_the_row(tmp_path):
    rows = _rows(6)
    rows[3] = "0.3;0.1"
    with pytest.raises(DatasetError, match="Got 2 at data row 4"):
        load_tensile_csv(_write(tmp_path, rows))


@pytest.mark.parametrize("n", [0, 1, 4])
def test_too_few_rows(tmp_path, n):
    with pytest.raises(DatasetError, match=f"at least 5. Got {n} instead"):
        load_tensile_csv(_write(tmp_path, _rows(n)))


def test_five_rows_are_enough(tmp_path):
    assert load_tensile_csv(_write(tmp_path, _rows(5))).n_points == 5


def test_empty_missing_and_folder_paths(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("\n\n", encoding="utf-8")
    with pytest.raises(DatasetError, match="empty file"):
        load_tensile_csv(empty)
    with pytest.raises(FileNotFoundError, match=r"nope\.csv"):
        load_tensile_csv(tmp_path / "nope.csv")
    with pytest.raises(DatasetError, match="folder"):
        load_tensile_csv(tmp_path)


def test_tensile_test_validates_and_freezes():
    strain = np.linspace(0.0, 1.0, 6)
    test = TensileTest("t", "m", strain, 0.3 * strain, metadata={"a": "b"})
    np.testing.assert_allclose(test.stretch, 1.0 + strain)
    strain[0] = 5.0  # the test kept its own copy
    assert test.engineering_strain[0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        test.engineering_strain[0] = 1.0
    with pytest.raises(TypeError):
        test.metadata["a"] = "c"
    with pytest.raises(DatasetError, match="at least 5"):
        TensileTest("t", "m", strain[:4], strain[:4])
    with pytest.raises(DatasetError, match="one length"):
        TensileTest("t", "m", strain, strain[:5])
    with pytest.raises(DatasetError, match="must be finite"):
        TensileTest("t", "m", strain, np.where(strain > 0.5, np.nan, strain))
    with pytest.raises(DatasetError, match=r"\[0, inf\)"):
        TensileTest("t", "m", np.linspace(-0.1, 0.9, 6), strain)
    with pytest.raises(ValueError, match="'name' of TensileTest"):
        TensileTest(" ", "m", strain, strain)


def test_summary_describes_the_shipped_dragon_skin_30():
    summary = load_shipped("dragon-skin-30").summary()
    assert summary["name"] == "dragon-skin-30"
    assert summary["n_points"] == 311
    assert summary["max_engineering_strain"] == pytest.approx(7.09, abs=0.01)  # stretch 8.09
    assert summary["source"].endswith("Dragon_Skin_30.csv")
    assert "Marechal" in summary["attribution"]
    json.dumps(summary)  # JSON-friendly as it is


def _in_kpa(tmp_path, name, *, below_mpa=1.0):
    """The shipped test ``name`` up to ``below_mpa`` of stress, written in kPa under (MPa)."""
    test = load_shipped(name)
    keep = test.engineering_stress_mpa < below_mpa
    rows = [
        f"{e:.6f};{1000.0 * s:.4f}"
        for e, s in zip(
            test.engineering_strain[keep], test.engineering_stress_mpa[keep], strict=True
        )
    ]
    header = "Engineering Strain;Engineering Stress (MPa)"
    return _write(tmp_path, rows, header=header, metadata=[], name=f"{name}_kpa.csv")


@pytest.mark.parametrize("name", ["ecoflex-0030", "dragon-skin-10-medium", "dragon-skin-30"])
def test_a_stress_column_in_kpa_is_caught_by_its_stiffness(tmp_path, name):
    # Below 1 MPa (1000 kPa) every value is inside the plausible stress range: only the
    # stiffness tells. The shipped tests themselves are far below the threshold.
    path = _in_kpa(tmp_path, name)
    with pytest.raises(DatasetError, match="looks like kPa: its median secant modulus") as caught:
        load_tensile_csv(path)
    assert "Divide the column by 1000" in str(caught.value) and path.name in str(caught.value)
    with pytest.warns(UserWarning, match="read as given"):
        stiff = load_tensile_csv(path, force=True)
    assert stiff.engineering_stress_mpa.max() > 100.0  # read as given, nothing rescaled


def test_every_shipped_test_is_well_below_the_kpa_stiffness():
    for name in shipped_tensile_tests():
        test = load_shipped(name)
        small = (test.engineering_strain > 0) & (test.engineering_strain <= 0.5)
        ratio = test.engineering_stress_mpa[small] / test.engineering_strain[small]
        assert np.median(ratio) < 0.5  # MPa: 40 times below the threshold


# --- Tensile data files: size and row limits before parsing, absurd values named by line ---


HEADER_BIG = "Time (s);Engineering Strain;Engineering Stress (MPa)"


def _rows_big(n):
    return [f"{0.1 * i:.1f};{0.05 * (i + 1):.4f};{0.02 * (i + 1):.4f}" for i in range(n)]


def _write_big(path, rows, metadata=("PARAMETER;INFO;URL", "Material;Test", "")):
    path.write_text("\n".join([*metadata, HEADER_BIG, *rows]) + "\n", encoding="utf-8")
    return path


def test_a_file_over_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = _write_big(tmp_path / "big.csv", _rows_big(60_000))  # about 1.6 MiB
    with pytest.raises(LimitError) as info:
        load_tensile_csv(path)
    assert str(path) in str(info.value) and "SOFTBEND_MAX_FILE_MIB" in str(info.value)


def test_more_rows_than_the_limit_are_refused_before_any_row_is_parsed(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "10")
    rows = _rows_big(11)
    rows[2] = "0.2;oops;0.1"
    path = _write_big(tmp_path / "rows.csv", rows)
    with pytest.raises(LimitError) as info:
        load_tensile_csv(path)
    message = str(info.value)
    assert str(path) in message and "11 rows" in message and "SOFTBEND_MAX_CSV_ROWS" in message


@pytest.mark.parametrize(
    ("cell", "value", "column", "needle"),
    [
        (1, "1e5", "Engineering Strain", "100000 is not a plausible strain (allowed -1 to 100)"),
        (2, "2.5e6", "Engineering Stress (MPa)", "not a plausible stress (allowed -1000 to 1000"),
        (2, "-5000", "Engineering Stress (MPa)", "-5000 is not a plausible stress"),
    ],
)
def test_an_absurd_value_names_file_line_and_column(tmp_path, cell, value, column, needle):
    rows = _rows_big(8)
    cells = rows[5].split(";")
    cells[cell] = value
    rows[5] = ";".join(cells)
    path = _write_big(tmp_path / "absurd.csv", rows)
    with pytest.raises(DatasetError) as info:
        load_tensile_csv(path)
    message = str(info.value)
    assert message.startswith(f"'{path}', line 10, column '{column}': ")  # 3 metadata, header
    assert needle in message


def test_the_first_absurd_value_in_file_order_is_named(tmp_path):
    rows = _rows_big(8)
    rows[3] = "0.3;0.2;5000"
    rows[6] = "0.6;500;0.1"
    with pytest.raises(DatasetError, match=r"line 8, column 'Engineering Stress \(MPa\)'"):
        load_tensile_csv(_write_big(tmp_path / "two.csv", rows))


@pytest.mark.parametrize("name", shipped_tensile_tests())
def test_the_shipped_tests_are_plausible(name):
    assert load_shipped(name).n_points > 300
