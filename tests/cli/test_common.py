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


def _duckdb_file(path):
    import duckdb

    duckdb.connect(str(path)).close()
    return path


def test_an_output_file_never_replaces_an_input_under_any_name(tmp_path):
    import os

    import pytest

    db = _duckdb_file(tmp_path / "c.duckdb")
    os.link(db, tmp_path / "alias.duckdb")
    for out in (db, tmp_path / "alias.duckdb", tmp_path / "." / "c.duckdb"):
        with pytest.raises(ValueError, match=r"The 'OUT' .* is also an input; choose another"):
            _common.check_output_file(out, "OUT", inputs=(db,), kind="csv")
    _common.check_output_file(tmp_path / "new.csv", "OUT", inputs=(db,), kind="csv")


def test_an_output_file_replaces_only_a_file_of_its_own_kind(tmp_path):
    import pytest

    db = _duckdb_file(tmp_path / "other.duckdb")
    text = tmp_path / "old.csv"
    text.write_text("a,b\n1,2\n")
    (tmp_path / "empty").touch()
    assert _common.file_kind(db) == "DuckDB database" and _common.file_kind(text) == "text"
    for kind in ("csv", "parquet"):
        with pytest.raises(ValueError, match=rf"must be a new file or a {kind} file to replace"):
            _common.check_output_file(db, "OUT", kind=kind)
    with pytest.raises(ValueError, match=r"Got .*old.csv, an existing text file, instead"):
        _common.check_output_file(text, "OUT", kind="parquet")
    _common.check_output_file(text, "OUT", kind="csv")
    _common.check_output_file(tmp_path / "empty", "OUT", kind="parquet")


def test_an_output_folder_is_refused_up_front(tmp_path):
    import pytest

    (tmp_path / "afile").touch()
    with pytest.raises(ValueError, match=r"The '--out' must name a folder; .*afile is a file"):
        _common.check_output_dir(tmp_path / "afile", "--out")
    with pytest.raises(ValueError, match=r"cannot be created: .*afile is a file"):
        _common.check_output_dir(tmp_path / "afile" / "sub", "--out")
    (tmp_path / "o" / "fit.json").mkdir(parents=True)
    with pytest.raises(ValueError, match=r"holds a folder fit.json where a file is written"):
        _common.check_output_dir(tmp_path / "o", "--out", files=("fit.json",))
    data = tmp_path / "data"
    data.mkdir()
    (data / "metrics.csv").write_text("x\n")
    with pytest.raises(ValueError, match="is also an input; choose another folder"):
        _common.check_output_dir(data, "--out", inputs=(data,))
    with pytest.raises(ValueError, match=r"would overwrite the input .*metrics.csv"):
        _common.check_output_dir(
            data, "--out", inputs=(data / "metrics.csv",), files=("metrics.csv",)
        )


def test_os_errors_of_an_output_become_one_line_naming_the_option(tmp_path):
    import errno

    import pytest

    out = tmp_path / "o"
    cases = [
        (OSError(errno.ENOSPC, "No space left on device"), "No space left on device."),
        (
            PermissionError(errno.EACCES, "Permission denied", str(out / "vtk" / "a.vtu")),
            f"Permission denied ({out / 'vtk' / 'a.vtu'}).",
        ),
        (
            IsADirectoryError(
                errno.EISDIR, "Is a directory", str(tmp_path / ".o.1.tmp"), None, str(out)
            ),
            "Is a directory.",
        ),
    ]
    for error, ending in cases:
        with pytest.raises(_common.OutputError) as caught, _common.output_errors(out, "--out"):
            raise error
        assert str(caught.value) == f"The '--out' {out} could not be written: {ending}"
        assert isinstance(caught.value, _common.SoftbendError) and caught.value.__cause__ is error
    # Errors about the inputs, and errors raised on purpose, pass unchanged.
    missing = FileNotFoundError(errno.ENOENT, "No such file", str(tmp_path / "in.duckdb"))
    for error in (missing, FileNotFoundError("The folder of the export does not exist.")):
        with pytest.raises(FileNotFoundError) as caught, _common.output_errors(out, "--out"):
            raise error
        assert caught.value is error


def test_an_os_error_reads_as_reason_and_path_without_an_errno():
    import errno

    error = IsADirectoryError(errno.EISDIR, "Is a directory", ".x.tmp", None, "x")
    assert _common.os_error_message(error) == "Is a directory: .x.tmp -> x"
    assert _common.os_error_message(OSError(errno.ENOSPC, "No space left on device")) == (
        "No space left on device"
    )
    assert _common.os_error_message(FileNotFoundError("No campaign database at 'c'.")) == (
        "No campaign database at 'c'."
    )


def test_parse_assignments_reads_name_value_pairs_once_each():
    import pytest

    assert _common.parse_assignments(["epochs=500", " share = 0.5 "]) == {
        "epochs": "500",
        "share": "0.5",
    }
    assert _common.parse_assignments([]) == {}
    for bad, needle in ((["epochs"], "^settings: .*NAME=VALUE"), (["=3"], "NAME=VALUE")):
        with pytest.raises(ValueError, match=needle):
            _common.parse_assignments(bad)
    with pytest.raises(ValueError, match=r"^settings: the parameter .epochs. is given twice"):
        _common.parse_assignments(["epochs=1", "epochs=2"])


def test_as_written_names_the_final_file_of_a_staged_one(tmp_path):
    import errno

    import pytest

    stage, final = tmp_path / ".stage", tmp_path / "out"
    with pytest.raises(OSError) as caught, _common.as_written(stage, final):
        raise OSError(errno.ENOSPC, "No space left on device", str(stage / "a.csv"))
    assert caught.value.filename == str(final / "a.csv")
    elsewhere = str(tmp_path / "input.csv")
    with pytest.raises(OSError) as caught, _common.as_written(stage, final):
        raise OSError(errno.ENOENT, "No such file or directory", elsewhere)
    assert caught.value.filename == elsewhere
