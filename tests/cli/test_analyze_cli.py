"""``softbend analyze``: preliminary analysis of a campaign database."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from softbend.cli import main
from softbend.design import sfrba_design

OUTPUTS = ("correlation.png", "loadings.png", "parity.png", "coefficients.csv", "correlation.csv")
FEATURES = ["l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm", "pressure_mpa"]


def _fake_store(monkeypatch, frame: pd.DataFrame) -> list:
    """Make ``softbend.campaign.store.load_samples`` return ``frame`` (a known samples table)."""
    store = pytest.importorskip("softbend.campaign.store")
    calls: list = []

    def load_samples(db_path):
        calls.append(db_path)
        return frame.copy()

    monkeypatch.setattr(store, "load_samples", load_samples)
    return calls


def _synthetic_samples(seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    n = 240
    frame = pd.DataFrame(
        {
            "design_id": [f"d{i // 12}" for i in range(n)],
            "l_mm": rng.choice([100.0, 120.0, 140.0], n),
            "r_mm": rng.choice([6.0, 8.0, 10.0], n),
            "t_mm": rng.choice([2.0, 3.0, 4.0], n),
            "b_mm": rng.choice([2.0, 3.0, 4.0], n),
            "phi_deg": rng.choice([5.0, 10.0, 15.0], n),
            "lc_mm": rng.choice([8.0, 10.0, 12.0], n),
            "pressure_mpa": rng.uniform(0.0, 0.2, n),
            "tip_x_mm": rng.normal(size=n),
            "tip_z_mm": rng.normal(size=n),
            "converged": True,
        }
    )
    frame["angle_deg"] = (
        900.0 * frame["pressure_mpa"] - 15.0 * frame["t_mm"] + rng.normal(0.0, 3.0, n)
    )
    return frame


def test_missing_database_is_one_line_exit_2(tmp_path, capsys):
    code = main(["analyze", str(tmp_path / "nope.duckdb"), "--out", str(tmp_path / "o")])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nope.duckdb" in err[0] and "does not exist" in err[0]
    assert not (tmp_path / "o").exists()


def test_database_without_samples_is_one_line_exit_2(tmp_path, capsys):
    store = pytest.importorskip("softbend.campaign.store")
    db = tmp_path / "empty.duckdb"
    store.CampaignStore(db).close()  # a campaign database with its schema and no samples
    assert main(["analyze", str(db), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no samples" in err[0] and "empty.duckdb" in err[0]


def test_file_that_is_not_a_database_is_one_line_exit_2(tmp_path, capsys):
    pytest.importorskip("softbend.campaign.store")
    db = tmp_path / "notes.duckdb"
    db.write_text("not a database")
    assert main(["analyze", str(db), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notes.duckdb" in err[0]


def test_json_output_and_files_from_a_samples_table(tmp_path, capsys, monkeypatch):
    pytest.importorskip("softbend.campaign")
    db = tmp_path / "c.duckdb"
    db.write_bytes(b"")
    frame = _synthetic_samples()
    calls = _fake_store(monkeypatch, frame)
    out = tmp_path / "analysis"
    assert main(["analyze", str(db), "--out", str(out), "--json"]) == 0
    assert [str(c) for c in calls] == [str(db)]
    payload = json.loads(capsys.readouterr().out)
    assert [row["feature"] for row in payload["coefficients"]] == FEATURES
    loadings = {row["feature"]: row["loading"] for row in payload["coefficients"]}
    assert max(loadings, key=lambda k: abs(loadings[k])) == "pressure_mpa"
    assert loadings["t_mm"] < 0
    assert payload["n_samples"] == len(frame)
    assert 0.8 < payload["r2"] <= 1.0 and payload["f_value"] > 0
    assert payload["correlation"]["angle_deg"]["angle_deg"] == pytest.approx(1.0)
    for name in OUTPUTS:
        assert (out / name).stat().st_size > 0
    table = pd.read_csv(out / "coefficients.csv", index_col="feature")
    assert list(table.index) == FEATURES
    assert table.loc["pressure_mpa", "loading"] == pytest.approx(loadings["pressure_mpa"])


def test_table_output(tmp_path, capsys, monkeypatch):
    pytest.importorskip("softbend.campaign")
    db = tmp_path / "c.duckdb"
    db.write_bytes(b"")
    _fake_store(monkeypatch, _synthetic_samples())
    assert main(["analyze", str(db), "--out", str(tmp_path / "o")]) == 0
    text = capsys.readouterr().out
    for word in ("pressure_mpa", "loading", "R²", "adjusted R²", "MAPE", "***"):
        assert word in text


# ----------------------------------------------------------------------------- end to end


def _campaign_api():
    campaign = pytest.importorskip("softbend.campaign")
    pytest.importorskip("softbend.analytical")
    pytest.importorskip("softbend.campaign.store")
    if not hasattr(campaign, "run_campaign"):
        pytest.skip("softbend.campaign.run_campaign is not available")
    return campaign


def test_analyze_an_analytical_campaign(tmp_path, capsys):
    campaign = _campaign_api()

    designs = [
        sfrba_design(l_mm=l_mm, r_mm=r_mm, t_mm=t_mm, b_mm=2.0, phi_deg=5.0, lc_mm=lc_mm)
        for l_mm in (100.0, 140.0)
        for r_mm in (6.0, 8.0)
        for t_mm in (2.0, 3.0)
        for lc_mm in (8.0, 12.0)
    ]
    db = tmp_path / "campaign.duckdb"
    campaign.run_campaign(
        db, designs, backend="analytical", pressures_mpa=np.linspace(0.0, 0.1, 11), workers=1
    )
    out = tmp_path / "analysis"
    assert main(["analyze", str(db), "--out", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    # the constant features are named in one warning line, whatever ran before
    warned = [x for x in captured.err.splitlines() if x.startswith("softbend: warning:")]
    assert any("is constant" in x and "left out of the regression" in x for x in warned)
    assert not any("Warning)" in x for x in warned)  # no Python class in the line
    payload = json.loads(captured.out)
    # b and phi are constant in this grid: left out of the regression.
    assert set(payload["dropped_features"]) == {"b_mm", "phi_deg"}
    loadings = {row["feature"]: row["loading"] for row in payload["coefficients"]}
    # The analytical model: the angle grows with pressure, length and radius and
    # falls with the top wall thickness; pressure dominates.
    assert max(loadings, key=lambda k: abs(loadings[k])) == "pressure_mpa"
    assert loadings["pressure_mpa"] > 0 and loadings["t_mm"] < 0
    assert loadings["l_mm"] > 0 and loadings["r_mm"] > 0
    assert payload["n_samples"] == len(designs) * 11
    assert 0.5 < payload["r2"] < 1.0
    # The zero-pressure samples (0°) are left out of the MAPE.
    assert payload["n_mape_excluded"] >= len(designs)
    for name in OUTPUTS:
        assert (out / name).stat().st_size > 0


def test_truncated_database_is_one_line_naming_the_file(tmp_path, capsys):
    """``head -c 600000 good.duckdb > t.duckdb``: one line and exit 2, no traceback."""
    store = pytest.importorskip("softbend.campaign.store")
    from softbend.campaign import default_pressures_mpa
    from softbend.campaign.backends import AnalyticalBackend

    good = tmp_path / "good.duckdb"
    grid = default_pressures_mpa(0.1, 0.05)
    with store.CampaignStore(good) as opened:
        opened.bind("analytical", grid)
        for l_mm in (100.0, 120.0, 140.0):
            design = sfrba_design(l_mm, 8.0, 3.0, 2.0, 5.0, 10.0)
            opened.record_success(AnalyticalBackend().sweep(design, grid))
    data = good.read_bytes()
    db = tmp_path / "t.duckdb"
    db.write_bytes(data[: min(600000, len(data) // 2)])
    assert main(["analyze", str(db), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"{str(db)!r} is not a readable softbend campaign database (truncated" in err[0]
    assert not (tmp_path / "o").exists()
