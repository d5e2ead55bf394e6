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
