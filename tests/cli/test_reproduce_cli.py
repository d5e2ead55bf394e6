"""``softbend reproduce``: the README's main job on its built-in defaults."""

import json

import pytest

from softbend.cli import main


@pytest.mark.slow
def test_reproduce_defaults_end_to_end(tmp_path, capsys):
    code = main(["reproduce", "--out", str(tmp_path), "--workers", "2", "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    b = summary["paper_b"]
    assert b["n_designs"] == 972 and b["done"] == 972 and b["failed"] == 0
    assert b["n_samples"] > 29577  # 101 pressures per design less the sweeps' stops
    assert all(v < 0.10 for v in summary["paper_a"]["free_run_nrmse_worst"].values())
    assert (tmp_path / "index.html").is_file()


def test_reproduce_rejects_bad_workers(tmp_path, capsys):
    code = main(["reproduce", "--out", str(tmp_path), "--workers", "-1"])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "workers" in err[0]
