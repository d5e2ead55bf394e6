import numpy as np
import pytest

from softbend.errors import DatasetError, LimitError
from softbend.limits import LIMITS, check_file_size, check_limit, limit
from softbend.plausibility import RANGES, check_plausible, implausible_index


def test_a_value_over_a_limit_names_it_and_the_variable(monkeypatch):
    monkeypatch.delenv("SOFTBEND_MAX_CYCLES", raising=False)
    check_limit("cycles", 1000, "--cycles")  # at the limit: fine
    with pytest.raises(
        LimitError,
        match=r"--cycles is 1,000,000,000 cycles, more than the limit "
        r"of 1,000 cycles .*SOFTBEND_MAX_CYCLES",
    ):
        check_limit("cycles", 10**9, "--cycles")
    # a huge integer does not overflow anything
    with pytest.raises(LimitError, match="designs"):
        check_limit("designs", 99999999999999999999, "--space lhs:N")


def test_the_environment_raises_a_limit_and_a_bad_value_is_named(monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CYCLES", "2_000")
    assert limit("cycles") == 2000
    check_limit("cycles", 1500, "--cycles")
    monkeypatch.setenv("SOFTBEND_MAX_CYCLES", "-3")
    with pytest.raises(LimitError, match="SOFTBEND_MAX_CYCLES must be a positive integer"):
        limit("cycles")
    with pytest.raises(ValueError, match="the limits are csv_rows, cycles"):
        limit("rows")


def test_file_size_limit(tmp_path, monkeypatch):
    big = tmp_path / "big.csv"
    big.write_bytes(b"x" * (2 * 2**20 + 10))
    check_file_size(big)
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    with pytest.raises(LimitError, match=r"big.csv is 2.0 MiB, more than the limit of 1 MiB"):
        check_file_size(big)
    check_file_size(tmp_path / "missing.csv")  # the reader names a missing file


def test_every_limit_is_documented():
    import softbend.limits as module

    for name, entry in LIMITS.items():
        assert f"``{name}``" in module.__doc__ and entry.default >= 1


def test_implausible_values_are_named_by_file_line_and_column():
    check_plausible([0.0, 0.1, np.nan, 0.5], "pressure_mpa", source="m.csv", column="p")
    with pytest.raises(
        DatasetError,
        match=r"m.csv, line 4, column 'angle_deg': 1e\+300 is not a "
        r"plausible bending angle \(allowed -3600 to 3600 °\)",
    ):
        check_plausible([1.0, 2.0, 1e300], "angle_deg", source="m.csv", column="angle_deg")
    with pytest.raises(DatasetError, match=r"line 9.*looks like kPa"):
        check_plausible([0.0, 120.0], "pressure_mpa", source="m.csv", column="p", lines=[3, 9])
    assert implausible_index([0.0, -np.inf], "angle_deg") == 1
    assert implausible_index([-0.1013, 2.0], "pressure_mpa") is None  # both ends included
    with pytest.raises(ValueError, match="the quantities are angle_deg"):
        implausible_index([1.0], "speed")


def test_every_range_is_documented():
    import softbend.plausibility as module

    for name, bounds in RANGES.items():
        assert f"``{name}``" in module.__doc__ and bounds.low < bounds.high


def test_training_epochs_are_bounded_before_any_work():
    from softbend.surrogates.batched import train_mlp_grid

    X = np.random.default_rng(0).random((20, 7))
    rows = np.arange(20)
    with pytest.raises(LimitError, match=r"'epochs' of train_mlp_grid is 1,000,000 epochs"):
        train_mlp_grid(X, X[:, 0], [(rows, rows[:0])], [(3, 3)], epochs=1_000_000)


def test_a_control_loop_run_is_bounded_by_its_ticks():
    from softbend.control import loop

    with pytest.raises(
        LimitError,
        match=r"A run of 86400 s at a period of 1e-06 s is "
        r"86,400,000,000 ticks.*SOFTBEND_MAX_LOOP_TICKS",
    ):
        loop.run_loop(None, None, "step:90", duration_s=86400, period_s=1e-6, sensor_period_s=0.01)
    with pytest.raises(LimitError, match="ticks"):  # a period so short the count overflows
        loop.run_loop(
            None, None, "step:90", duration_s=86400, period_s=5e-324, sensor_period_s=0.01
        )


@pytest.mark.parametrize(
    "argv",
    [
        ["transfer", "base", "--out", "m.json", "--epochs", "1000000000"],
        ["transfer", "refine", "b.json", "x.csv", "--out", "m.json", "--epochs", "1000000000"],
    ],
)
def test_the_cli_names_the_epochs_option(argv, tmp_path, monkeypatch, capsys):
    from softbend.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--epochs is 1,000,000,000 epochs" in err[0]
    assert not (tmp_path / "m.json").exists()


def test_the_first_implausible_value_in_file_order_is_named_whatever_its_column():
    from softbend.plausibility import check_plausible_columns

    columns = {"time_s": ([0.0, 0.1, 0.2, -5.0], "time_s"), "p": ([0, 1, 1e6, 2], "pressure_kpa")}
    # row 3 (line 12) in 'p' comes before row 4 (line 13) in 'time_s'
    with pytest.raises(DatasetError, match=r"^e.csv, line 12, column 'p': 1e\+06 is not"):
        check_plausible_columns(columns, source="e.csv", lines=[10, 11, 12, 13])
    check_plausible_columns({"p": ([0.0, 1.0], "pressure_kpa")}, source="e.csv", lines=[2, 3])


def test_a_count_of_thousands_of_digits_is_refused_by_its_length(monkeypatch):
    from softbend.limits import check_count_text

    monkeypatch.delenv("SOFTBEND_MAX_DESIGNS", raising=False)
    assert check_count_text("designs", "000120", "--space lhs:N") == 120
    with pytest.raises(LimitError, match=r"^--space lhs:N is a number of 5,000 digits, more than"):
        check_count_text("designs", "9" * 5000, "--space lhs:N")  # beyond int()'s 4300 digits
    with pytest.raises(LimitError, match=r"is 1,000,001 designs, more than the limit"):
        check_count_text("designs", "1000001", "--space lhs:N")
