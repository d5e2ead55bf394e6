from softbend.cli import _common


def test_phase_progress_writes_plain_lines_off_a_terminal(capsys):
    with _common.phase_progress() as progress:
        for done in range(101):
            progress("fitting", done, 100)
        progress("refit", 0, 1)
        progress("refit", 1, 1)
    lines = capsys.readouterr().err.strip().splitlines()
    fitting = [line for line in lines if line.startswith("fitting:")]
    assert len(fitting) == 11  # start, every tenth, end
    assert fitting[0].startswith("fitting: 0/100") and fitting[-1].startswith("fitting: 100/100")
    assert [line.split(" (")[0] for line in lines if line.startswith("refit")] == [
        "refit: 0/1",
        "refit: 1/1",
    ]


def test_phase_progress_disabled_is_silent(capsys):
    with _common.phase_progress(enabled=False) as progress:
        progress("fitting", 5, 10)
    assert capsys.readouterr().err == ""


def test_progress_bar_writes_plain_lines_with_an_estimate_off_a_terminal(capsys):
    with _common.progress_bar("campaign c.duckdb", total=40) as advance:
        advance(0, done=0, failed=0)
        for done in range(1, 41):
            advance(1, done=done, failed=0)
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 11  # start and every tenth
    assert lines[0].startswith("campaign c.duckdb: 0/40")
    assert lines[4].startswith("campaign c.duckdb: 16/40  done 16  failed 0")
    assert "s left" in lines[4] and lines[-1].startswith("campaign c.duckdb: 40/40")
