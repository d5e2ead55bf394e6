import pytest

from softbend.errors import DatasetError
from softbend.identification.data import load_experiments, save_experiments
from softbend.identification.resources import (
    BASE_BYTES,
    MIB,
    available_memory_bytes,
    check_identify_memory,
    estimate_identify_memory,
    peak_memory_mib,
)
from softbend.identification.synthetic import synthetic_dataset


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("experiments")
    data = synthetic_dataset(n_experiments=2, n_samples=2_000, seed=2)
    save_experiments([e for group in data.values() for e in group], out)
    return out


def test_the_estimate_counts_the_samples_and_grows_with_them(folder):
    rows = sum(e.n_samples for e in load_experiments(folder))
    estimate = estimate_identify_memory(folder)
    assert estimate.rows == pytest.approx(rows, rel=0.02)  # from the first 64 KiB of each file
    assert estimate.csv_bytes == sum(p.stat().st_size for p in folder.glob("*.csv"))
    one = next(iter(sorted(folder.glob("*.csv"))))
    single = estimate_identify_memory(one)
    assert single.rows == pytest.approx(2_000, rel=0.02)
    assert BASE_BYTES < single.peak_bytes < estimate.peak_bytes
    # No n^2 term: ten times the samples cost well under ten times the memory.
    assert estimate.peak_bytes < 2 * single.peak_bytes


def test_a_small_file_is_counted_exactly(tmp_path):
    path = tmp_path / "one.csv"
    path.write_text("# comment\ntime_s,pressure_kpa,x_mm,y_mm\n0,0,0,0\n0.1,1,0,0\n\n0.2,2,0,0\n")
    assert estimate_identify_memory(path).rows == 3
    assert estimate_identify_memory(tmp_path / "missing.csv").rows == 0


def test_the_guard_refuses_before_reading_with_one_clear_line(folder, monkeypatch):
    import softbend.identification.data as data_module

    def must_not_read(*args, **kwargs):
        raise AssertionError("the data were read before the memory check")

    monkeypatch.setattr(data_module, "_read_csv", must_not_read)
    with pytest.raises(DatasetError) as info:
        check_identify_memory(folder, max_memory_mb=100)
    message = str(info.value)
    assert "\n" not in message
    assert f"The data at {folder}" in message
    assert "would need about" in message and "more than --max-memory-mb (100 MiB)" in message
    estimate = check_identify_memory(folder, max_memory_mb=64_000)
    assert estimate.peak_bytes < 64_000 * MIB


def test_the_limit_must_be_positive_and_defaults_to_the_memory_available(folder):
    with pytest.raises(ValueError, match=r"^max_memory_mb: must be a number"):
        check_identify_memory(folder, max_memory_mb=0)
    available = available_memory_bytes()
    assert available is None or available > 0
    check_identify_memory(folder)  # a few MB of CSV fit in any machine that runs the tests


def test_curling_identify_refuses_data_too_big_for_its_memory_limit(folder, tmp_path, capsys):
    from softbend.cli import main

    capsys.readouterr()
    out = tmp_path / "out"
    code = main(["curling", "identify", str(folder), "--out", str(out), "--max-memory-mb", "50"])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert "would need about" in err and "--max-memory-mb" in err
    assert not (out / "metrics.csv").exists()


def test_the_peak_memory_is_the_kernels_high_water_mark():
    import sys
    from pathlib import Path

    if not sys.platform.startswith("linux"):
        pytest.skip("/proc/self/status is Linux's")
    status = Path("/proc/self/status").read_text().splitlines()
    rss, hwm = (
        int(next(line for line in status if line.startswith(key)).split()[1]) / 1024
        for key in ("VmRSS:", "VmHWM:")
    )
    peak = peak_memory_mib()
    assert peak is not None and rss <= peak + 1 and peak == pytest.approx(hwm, abs=2)
