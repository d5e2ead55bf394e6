"""``softbend materials fit`` never leaves half a figure in place of the last good one."""

import errno

from softbend.cli import main

from .conftest import one_error_line


def test_a_figure_cut_short_keeps_the_previous_one(tmp_path, capsys, monkeypatch):
    out = tmp_path / "fit"
    assert main(["materials", "fit", "--out", str(out), "--json"]) == 0
    capsys.readouterr()
    before = (out / "fit.png").read_bytes()

    def full_disk(test, results, path, **kwargs):
        with open(path, "wb") as handle:
            handle.write(b"\x89PNG half")
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr("softbend.reports.material_figures.fit_figure", full_disk)
    assert main(["materials", "fit", "--out", str(out), "--models", "yeoh"]) == 2
    line = one_error_line(capsys)
    assert "'--out'" in line and "No space left on device" in line
    assert (out / "fit.png").read_bytes() == before
    assert sorted(p.name for p in out.iterdir()) == ["fit.json", "fit.png"]
