"""curling identify --select: paper A's models beside the one chosen by free-run error."""

from __future__ import annotations

import json

from softbend.cli import main


def test_select_writes_a_selection_per_pressure_sign(tmp_path, capsys):
    data = tmp_path / "data"
    assert main(["curling", "simulate", "-o", str(data), "--experiments", "3",
                 "--samples", "200", "--json"]) == 0  # fmt: skip
    capsys.readouterr()
    out = tmp_path / "ident"
    assert main(["curling", "identify", str(data), "-o", str(out), "--select", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert set(payload["selection"]) == {"positive", "negative"}
    for sign in ("positive", "negative"):
        folder = out / f"selection_{sign}"
        record = json.loads((folder / "selection.json").read_text())
        assert record["outputs"] == ["rho", "length_mm"] and len(record["train"]) == 3
        assert "paper-a" in {row["candidate"] for row in record["table"]}
        assert (folder / "holdout_freerun.csv").is_file()
