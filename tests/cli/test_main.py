import numpy as np
import pytest

from softbend.cli import main


def test_help_exits_zero(capsys):
    assert main(["--help"]) == 0
    assert "curling" in capsys.readouterr().out


def test_unknown_command_is_one_line_and_exit_2(capsys):
    assert main(["no-such-command"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("softbend: error: No such command")


def test_unknown_option_is_one_line_and_exit_2(capsys):
    assert main(["curling", "--no-such-option"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--no-such-option" in err[0]


def _status_raising(tmp_path, monkeypatch, message):
    """``campaign status`` of a new database whose status query raises ``RuntimeError(message)``."""
    from softbend.campaign import CampaignStore

    db = tmp_path / "c.duckdb"
    with CampaignStore(db) as store:
        store.bind("analytical", np.array([0.0, 0.1]))

    def raising(self):
        raise RuntimeError(message)

    monkeypatch.setattr(CampaignStore, "status_summary", raising)
    return ["campaign", "status", str(db)]


def test_a_ctrl_c_inside_a_duckdb_query_is_the_one_interrupted_line(tmp_path, capsys, monkeypatch):
    # DuckDB turns a Ctrl-C during a query into "RuntimeError: Query interrupted".
    assert main(_status_raising(tmp_path, monkeypatch, "Query interrupted")) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0]


def test_other_runtime_errors_are_not_taken_for_a_ctrl_c(tmp_path, monkeypatch):
    with pytest.raises(RuntimeError, match="something else"):
        main(_status_raising(tmp_path, monkeypatch, "something else"))
