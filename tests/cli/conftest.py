"""Helpers shared by the CLI tests."""


def one_error_line(capsys) -> str:
    """The single ``softbend: error: …`` line a failed command wrote to stderr."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("softbend: error: ")
    return err[0]
