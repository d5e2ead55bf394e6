"""Every output folder is all or nothing, and holds one run: fem run, curling, analyze, reproduce.

Each command builds its folder beside --out and swaps it in when complete. A full
disk (``OSError(ENOSPC)`` raised midway through the writing), an interrupt
(``KeyboardInterrupt``) or a kill leaves the previous folder as it was (or no
folder), and a rerun never leaves the files of an earlier run beside the new
ones. A folder with other files than the command's own is refused, never
deleted. The expensive parts (the FEM solver, the NARX fits, the report's
sections) are stood in for: what is tested is the writing.
"""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from softbend._outdir import MANIFEST
from softbend.cli import main

from ..folders import dead_pid
from .conftest import one_error_line

# ----------------------------------------------------------------------------- helpers


def _tree(folder: Path) -> dict[str, bytes | None]:
    """Every file and folder under ``folder``: relative path → bytes (None for a folder)."""
    return {
        str(p.relative_to(folder)): (None if p.is_dir() else p.read_bytes())
        for p in sorted(folder.rglob("*"))
    }


def _staging(out: Path) -> list[str]:
    """The staging folders left beside ``out``."""
    return sorted(p.name for p in out.parent.glob(f".{out.name}.*.new"))


def _unfinished_manifest(folder: Path, command: str) -> None:
    """The manifest a run of ``command`` writes first into its staging folder (PID in the name)."""
    pid = int(folder.name.split(".")[2].split("-")[0])
    manifest = {"format": "softbend-output-manifest", "version": 1, "command": command,
                "pid": pid, "complete": False, "entries": {}}  # fmt: skip
    (folder / MANIFEST).write_text(json.dumps(manifest))


def _full_disk(*args: object, **kwargs: object) -> None:
    raise OSError(errno.ENOSPC, "No space left on device")


def _full_disk_line(out: Path, capsys: pytest.CaptureFixture[str]) -> str:
    """The one error line of a full disk; it names --out and the final file, never the stage."""
    line = one_error_line(capsys)
    assert line.startswith(
        f"softbend: error: The '--out' {out} could not be written: No space left on device"
    ), line
    assert ".new" not in line, line
    return line


# ----------------------------------------------------------------------------- stand-ins


@pytest.fixture
def quick_figures(monkeypatch: pytest.MonkeyPatch) -> None:
    """Figures saved as a few bytes instead of rendered (the writing is what is tested).

    Each figure's bytes differ from every other's: a file of a later run is told apart.
    """
    import itertools

    import matplotlib.pyplot as plt

    import softbend.reports.analysis_figures as analysis_figures
    import softbend.reports.curling_figures as curling_figures

    count = itertools.count()

    def save(fig, path):
        plt.close(fig)
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(b"\x89PNG stand-in %d" % next(count))
        return path

    monkeypatch.setattr(analysis_figures, "_save", save)
    monkeypatch.setattr(curling_figures, "_save", save)


@pytest.fixture
def fake_fem(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, object]]:
    """The FEM solver stood in for by the analytical model; ``controls`` fail or stop it.

    ``controls["fail_at_shape"] = n`` raises ENOSPC while writing the n-th VTK file
    (sweep.csv and the folder vtk/ are written by then), ``controls["stop_at_shape"]``
    raises KeyboardInterrupt there.
    """
    import dataclasses

    import softbend.fem.export as export
    from softbend._io import write_text_atomic
    from softbend.analytical import AnalyticalModel
    from softbend.fem.families import FEM_FAMILIES

    controls: dict[str, object] = {"fail_at_shape": None, "stop_at_shape": None}
    written: list[Path] = []

    def sweep(design, pressures_mpa, options, *, progress=None, keep_states=False):
        analytical = AnalyticalModel().sweep(design, pressures_mpa)
        stats = {"stop_reason": "reached the last pressure", "ndof": 0}
        result = dataclasses.replace(analytical, stats=stats, mesh_size=100)
        steps = [SimpleNamespace(pressure_mpa=float(p), state=None) for p in result.pressure_mpa]
        model = SimpleNamespace(set_state=lambda state: None)
        written.clear()
        return result, model, SimpleNamespace(steps=steps)

    def write_vtk(model, path, *, pressure_mpa):
        number = len(written) + 1
        if controls["fail_at_shape"] == number:
            raise OSError(errno.ENOSPC, "No space left on device", str(Path(path).parent))
        if controls["stop_at_shape"] == number:
            raise KeyboardInterrupt
        written.append(write_text_atomic(path, f"<VTKFile {pressure_mpa}/>\n"))
        return written[-1]

    outline = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 6.0], [0.0, 6.0], [0.0, 0.0]])
    family = FEM_FAMILIES.get("sfrba")
    fake = dataclasses.replace(family, sweep=sweep, outline=lambda model: outline)
    FEM_FAMILIES.register("sfrba", fake, replace=True)
    monkeypatch.setattr(export, "write_vtk", write_vtk)
    yield controls
    FEM_FAMILIES.register("sfrba", family, replace=True)


def _fem(out: Path, *extra: str) -> list[str]:
    return ["fem", "run", "--pmax", "0.01", "--out", str(out), "--json", *extra]


@pytest.fixture(scope="module")
def experiments_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Four short synthetic experiments (two per pressure sign)."""
    out = tmp_path_factory.mktemp("staged") / "experiments"
    argv = ["curling", "simulate", "--out", str(out), "--experiments", "2", "--samples", "160"]
    assert main([*argv, "--seed", "5", "--json"]) == 0
    return out


@pytest.fixture(scope="module")
def identified(experiments_dir: Path) -> object:
    """The leave-one-experiment-out identification of :func:`experiments_dir`, fitted once."""
    from softbend.identification.data import load_experiments
    from softbend.identification.study import IdentificationConfig, identify

    return identify(load_experiments(experiments_dir), IdentificationConfig())


@pytest.fixture
def fast_identify(
    monkeypatch: pytest.MonkeyPatch, identified: object, quick_figures: None
) -> dict[str, object]:
    """``curling identify`` on the fitted models of :func:`identified`; selections stood in for.

    ``controls["fail_selection"] = sign`` raises ENOSPC midway through writing
    ``selection_<sign>/``.
    """
    import softbend.identification.selection as selection
    import softbend.identification.study as study
    import softbend.reports.identify_outputs as identify_outputs

    controls: dict[str, object] = {"fail_selection": None}
    monkeypatch.setattr(study, "identify", lambda experiments, config, progress=None: identified)
    monkeypatch.setattr(
        selection, "select_model", lambda data, **kw: SimpleNamespace(verdict=lambda: "chosen")
    )

    def write_identification(chosen, data, folder):
        folder = Path(folder)
        folder.mkdir(parents=True)
        (folder / "selection.json").write_text("{}\n")
        if folder.name == f"selection_{controls['fail_selection']}":
            raise OSError(errno.ENOSPC, "No space left on device", str(folder / "model.json"))
        (folder / "model.json").write_text("{}\n")
        return {}

    monkeypatch.setattr(identify_outputs, "write_identification", write_identification)
    return controls


def _samples() -> pd.DataFrame:
    """A campaign's samples: the angle grows with pressure and falls with t."""
    rng = np.random.default_rng(0)
    n = 120
    frame = pd.DataFrame(
        {
            "design_id": [f"d{i // 12}" for i in range(n)],
            "l_mm": rng.choice([100.0, 120.0], n),
            "r_mm": rng.choice([6.0, 8.0], n),
            "t_mm": rng.choice([2.0, 3.0], n),
            "b_mm": rng.choice([2.0, 3.0], n),
            "phi_deg": rng.choice([5.0, 10.0], n),
            "lc_mm": rng.choice([8.0, 10.0], n),
            "pressure_mpa": rng.uniform(0.0, 0.2, n),
            "converged": True,
        }
    )
    frame["angle_deg"] = 900.0 * frame["pressure_mpa"] - 15.0 * frame["t_mm"] + rng.normal(0, 3, n)
    return frame


@pytest.fixture
def fake_db(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, quick_figures: None) -> Path:
    """A campaign database whose samples are :func:`_samples`."""
    store = pytest.importorskip("softbend.campaign.store")
    monkeypatch.setattr(store, "load_samples", lambda path: _samples())
    db = tmp_path / "c.duckdb"
    db.write_bytes(b"")
    return db


@pytest.fixture
def fake_reproduce(monkeypatch: pytest.MonkeyPatch) -> dict[str, object]:
    """Every section of the report stood in for: a file per section, and a campaign that resumes.

    The campaign database is a text file of the designs done, four more per run
    (eight in all); each section writes ``<section>/result.txt`` with the seed.
    ``controls["stop_at"] = section`` raises KeyboardInterrupt when that section
    starts, ``controls["campaigns"]`` records the designs each run found done.
    """
    import softbend.reports.reproduce as reproduce
    from softbend.reports import (
        control_section,
        design_section,
        paper_b_fem,
        paper_b_fem_data,
        pneunet_section,
        summary_section,
        transfer_section,
    )

    controls: dict[str, object] = {"stop_at": None, "seed": None, "campaigns": []}

    def section(name: str, result: dict[str, object] | None = None):
        def run(report, out_dir, *args, **kwargs):
            if controls["stop_at"] == name:
                raise KeyboardInterrupt
            folder = Path(out_dir) / name
            folder.mkdir(parents=True, exist_ok=True)
            (folder / "result.txt").write_text(f"seed {controls['seed']}\n")
            return {"file": str(folder / "result.txt"), **(result or {})}

        return run

    def paper_a(report, out_dir, seed, progress):
        controls["seed"] = seed
        return section("paper_a")(report, out_dir)

    def paper_b(report, out_dir, workers, progress, space=None):
        db = Path(out_dir) / "paper_b" / "campaign.duckdb"
        before = int(db.read_text()) if db.is_file() else 0
        controls["campaigns"].append(before)
        db.parent.mkdir(parents=True, exist_ok=True)
        db.write_text(f"{min(before + 4, 8)}\n")
        return {**section("paper_b")(report, out_dir), "resumed_done": before}

    fem_data = {"designs_done": 15, "samples_sha256": "0" * 64}
    monkeypatch.setattr(reproduce, "_paper_a", paper_a)
    monkeypatch.setattr(reproduce, "_paper_b", paper_b)
    monkeypatch.setattr(reproduce, "_paper_b_surrogates", section("paper_b"))
    monkeypatch.setattr(paper_b_fem, "add_section", section("paper_b_fem"))
    monkeypatch.setattr(paper_b_fem_data, "add_section", section("paper_b_fem", fem_data))
    monkeypatch.setattr(transfer_section, "add_section", section("transfer"))
    monkeypatch.setattr(control_section, "add_section", section("control"))
    monkeypatch.setattr(design_section, "add_section", section("design"))
    monkeypatch.setattr(pneunet_section, "add_section", section("pneunet"))
    monkeypatch.setattr(summary_section, "add_summary", lambda report, summary, reduced: None)
    return controls


def _reproduce(out: Path, seed: int) -> list[str]:
    return ["reproduce", "--out", str(out), "--seed", str(seed), "--json"]


# ----------------------------------------------------------------------------- refusals


def _argv(command: str, tmp_path: Path, out: Path) -> list[str]:
    data = tmp_path / "data"
    data.mkdir(exist_ok=True)
    db = tmp_path / "c.duckdb"
    db.touch()
    return {
        "fem run": _fem(out),
        "curling simulate": ["curling", "simulate", "--out", str(out), "--samples", "16"],
        "curling identify": ["curling", "identify", str(data), "--out", str(out)],
        "analyze": ["analyze", str(db), "--out", str(out)],
        "reproduce": _reproduce(out, 0),
    }[command]


COMMANDS = ["fem run", "curling simulate", "curling identify", "analyze", "reproduce"]


@pytest.mark.parametrize("command", COMMANDS)
def test_a_folder_of_other_files_is_refused_in_one_line_and_kept(
    tmp_path, capsys, fake_fem, fake_reproduce, command
):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me\n")
    (out / "positive-01.csv").write_text("time_s,pressure_kpa\n0,0\n")  # not a simulated one
    assert main(_argv(command, tmp_path, out)) == 2
    line = one_error_line(capsys)
    assert f"The '--out' {out} is replaced as a whole by the results of '{command}'" in line
    assert "holds other files (notes.txt" in line or "holds other files (positive-01.csv" in line
    assert (out / "notes.txt").read_text() == "keep me\n"
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "positive-01.csv"]
    assert _staging(out) == []


@pytest.mark.parametrize("command", ["fem run", "curling identify", "analyze", "reproduce"])
def test_a_folder_without_the_commands_marker_is_refused(
    tmp_path, capsys, fake_fem, fake_reproduce, command
):
    # the names the command writes, but not its marker: someone else's files
    out = tmp_path / "mine"
    out.mkdir()
    name = {
        "fem run": "sweep.csv",
        "curling identify": "summary.csv",
        "analyze": "correlation.csv",
        "reproduce": "index.html",
    }[command]
    (out / name).write_text("mine\n")
    assert main(_argv(command, tmp_path, out)) == 2
    assert "'--out'" in one_error_line(capsys)
    assert (out / name).read_text() == "mine\n"


# ----------------------------------------------------------------------------- fem run


def test_fem_run_on_a_full_disk_leaves_the_previous_run(tmp_path, capsys, fake_fem):
    out = tmp_path / "fem"
    assert main(_fem(out, "--shapes", "3")) == 0
    before = _tree(out)
    assert len(list((out / "vtk").iterdir())) == 3
    fake_fem["fail_at_shape"] = 2  # sweep.csv and one shape written into the stage by then
    capsys.readouterr()
    assert main(_fem(out, "--shapes", "3", "--design", "120,6,2,2,5,10")) == 2
    line = _full_disk_line(out, capsys)
    assert f"({out / 'vtk'})" in line  # the file under its final name
    assert _tree(out) == before
    assert _staging(out) == []


def test_fem_run_on_a_full_disk_leaves_no_folder(tmp_path, capsys, fake_fem):
    out = tmp_path / "fem"
    fake_fem["fail_at_shape"] = 1
    assert main(_fem(out)) == 2
    _full_disk_line(out, capsys)
    assert not out.exists() and _staging(out) == []


def test_fem_rerun_keeps_no_file_of_the_previous_run(tmp_path, capsys, fake_fem):
    out = tmp_path / "fem"
    assert main(_fem(out, "--shapes", "4")) == 0
    assert main(_fem(out, "--shapes", "1", "--design", "120,6,2,2,5,10")) == 0
    assert [p.name for p in (out / "vtk").iterdir()] == ["shape_p0.000MPa.vtu"]
    assert json.loads((out / "sweep.json").read_text())["design"].startswith("120")
    assert sorted(p.name for p in out.iterdir()) == [
        MANIFEST,
        "angle_pressure.png",
        "shapes.png",
        "sweep.csv",
        "sweep.json",
        "vtk",
    ]


def test_fem_run_interrupted_leaves_the_previous_run(tmp_path, capsys, fake_fem):
    out = tmp_path / "fem"
    assert main(_fem(out, "--shapes", "3")) == 0
    before = _tree(out)
    fake_fem["stop_at_shape"] = 2
    assert main(_fem(out, "--shapes", "2", "--design", "120,6,2,2,5,10")) != 0
    assert _tree(out) == before
    assert _staging(out) == []


@pytest.mark.slow
def test_fem_run_with_the_solver_on_a_full_disk_while_writing_vtk(tmp_path, capsys, monkeypatch):
    import softbend.fem.export as export

    monkeypatch.setattr(export, "write_vtk", _full_disk)
    out = tmp_path / "fem"
    assert main(["fem", "run", "--pmax", "0.01", "--maxh", "6", "--shapes", "2",
                 "--out", str(out), "--json"]) == 2  # fmt: skip
    _full_disk_line(out, capsys)
    assert not out.exists() and _staging(out) == []


# ----------------------------------------------------------------------------- curling simulate


def _simulate(out: Path, *extra: str) -> list[str]:
    return ["curling", "simulate", "--out", str(out), "--samples", "32", "--json", *extra]


def test_simulate_on_a_full_disk_leaves_the_previous_experiments(tmp_path, capsys, monkeypatch):
    import softbend.identification.data as data

    out = tmp_path / "sim"
    assert main(_simulate(out, "--experiments", "6")) == 0
    before = _tree(out)
    assert len(before) == 13  # the twelve experiments and the manifest
    lines = data._header_lines
    calls = []

    def header_lines(experiment):
        calls.append(experiment.name)
        if len(calls) == 3:  # two experiments are written by then
            raise OSError(errno.ENOSPC, "No space left on device")
        return lines(experiment)

    monkeypatch.setattr(data, "_header_lines", header_lines)
    capsys.readouterr()
    assert main(_simulate(out, "--experiments", "6", "--seed", "1")) == 2
    _full_disk_line(out, capsys)
    assert _tree(out) == before
    assert _staging(out) == []
    new = tmp_path / "new"
    calls.clear()
    assert main(_simulate(new, "--experiments", "6")) == 2
    assert not new.exists() and _staging(new) == []


def test_simulate_rerun_leaves_no_experiment_of_the_previous_run(tmp_path, capsys):
    out = tmp_path / "sim"
    assert main(_simulate(out, "--experiments", "6")) == 0
    assert len(list(out.iterdir())) == 13
    assert main(_simulate(out, "--experiments", "1", "--seed", "1")) == 0
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "negative-01.csv", "positive-01.csv"]


def test_simulate_prints_the_final_paths(tmp_path, capsys):
    out = tmp_path / "sim"
    assert main(_simulate(out, "--experiments", "1")) == 0
    payload = json.loads(capsys.readouterr().out)
    assert [e["path"] for e in payload["experiments"]] == [
        str(out / "positive-01.csv"),
        str(out / "negative-01.csv"),
    ]


def test_simulate_killed_midway_leaves_the_previous_experiments(tmp_path):
    out = tmp_path / "sim"
    assert main(_simulate(out, "--experiments", "6")) == 0
    before = _tree(out)
    script = textwrap.dedent(
        f"""
        import os, signal
        import softbend.identification.data as data
        from softbend.cli import main

        lines, calls = data._header_lines, []

        def header_lines(experiment):
            calls.append(1)
            if len(calls) == 3:
                os.kill(os.getpid(), signal.SIGKILL)
            return lines(experiment)

        data._header_lines = header_lines
        main(["curling", "simulate", "--out", {str(out)!r}, "--samples", "32",
              "--experiments", "6", "--seed", "1"])
        """
    )
    killed = subprocess.run([sys.executable, "-c", script], capture_output=True, check=False)
    assert killed.returncode == -9, killed.stderr
    assert _tree(out) == before
    assert len(_staging(out)) == 1  # what the killed run had written, beside --out
    assert main(_simulate(out, "--experiments", "1", "--seed", "2")) == 0
    assert _staging(out) == []  # removed by the next run
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "negative-01.csv", "positive-01.csv"]


def test_simulate_replaces_its_own_earlier_experiments_only(tmp_path, capsys):
    out = tmp_path / "sim"
    assert main(_simulate(out, "--experiments", "1")) == 0
    (out / "negative-02.csv").write_text("# softbend experiment CSV v1\n# synthetic: false\n")
    assert main(_simulate(out, "--experiments", "1")) == 2
    assert "holds other files (negative-02.csv)" in one_error_line(capsys)
    assert (out / "negative-02.csv").exists()


# ----------------------------------------------------------------------------- curling identify


def _identify(data: Path, out: Path, *extra: str) -> list[str]:
    return ["curling", "identify", str(data), "--out", str(out), "--json", *extra]


def test_identify_on_a_full_disk_leaves_the_previous_results(
    tmp_path, capsys, monkeypatch, experiments_dir, fast_identify
):
    import softbend.reports.curling_figures as figures

    out = tmp_path / "ident"
    assert main(_identify(experiments_dir, out)) == 0
    before = _tree(out)

    def empty_figure(result, output, path):
        Path(path).write_bytes(b"")  # what savefig leaves on a full disk
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(figures, "identified_vs_measured", empty_figure)
    capsys.readouterr()
    assert main(_identify(experiments_dir, out, "--C", "10")) == 2
    line = _full_disk_line(out, capsys)
    assert f"({out / 'fig9_identified_rho.png'})" in line
    assert _tree(out) == before
    assert _staging(out) == []
    new = tmp_path / "new"
    assert main(_identify(experiments_dir, new)) == 2
    assert not new.exists() and _staging(new) == []


def test_identify_select_on_a_full_disk_leaves_the_previous_results(
    tmp_path, capsys, experiments_dir, fast_identify
):
    out = tmp_path / "ident"
    assert main(_identify(experiments_dir, out, "--select")) == 0
    before = _tree(out)
    assert "selection_negative/model.json" in before
    fast_identify["fail_selection"] = "negative"
    capsys.readouterr()
    assert main(_identify(experiments_dir, out, "--select")) == 2
    line = _full_disk_line(out, capsys)
    assert f"({out / 'selection_negative' / 'model.json'})" in line
    assert _tree(out) == before
    assert _staging(out) == []


def test_identify_rerun_keeps_no_selection_of_the_previous_run(
    tmp_path, capsys, experiments_dir, fast_identify
):
    out = tmp_path / "ident"
    assert main(_identify(experiments_dir, out, "--select")) == 0
    assert (out / "selection_positive").is_dir()
    capsys.readouterr()
    assert main(_identify(experiments_dir, out)) == 0
    payload = json.loads(capsys.readouterr().out)
    assert not any(p.name.startswith("selection_") for p in out.iterdir())
    assert payload["files"]["metrics"] == str(out / "metrics.csv")
    assert all(Path(p).exists() and ".new" not in p for p in payload["files"].values())


def test_identify_interrupted_leaves_the_previous_results(
    tmp_path, capsys, monkeypatch, experiments_dir, fast_identify
):
    import softbend.reports.curling_figures as figures

    out = tmp_path / "ident"
    assert main(_identify(experiments_dir, out)) == 0
    before = _tree(out)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(figures, "output_vs_pressure", interrupted)
    assert main(_identify(experiments_dir, out)) != 0
    assert _tree(out) == before
    assert _staging(out) == []


# ----------------------------------------------------------------------------- analyze


def test_analyze_on_a_full_disk_leaves_the_previous_results(tmp_path, capsys, monkeypatch, fake_db):
    import softbend.reports.analysis_figures as figures

    out = tmp_path / "analysis"
    assert main(["analyze", str(fake_db), "--out", str(out), "--json"]) == 0
    before = _tree(out)
    assert len(before) == 6  # five files and the manifest
    monkeypatch.setattr(figures, "parity_plot", _full_disk)
    capsys.readouterr()
    assert main(["analyze", str(fake_db), "--out", str(out), "--mape-threshold-deg", "5"]) == 2
    _full_disk_line(out, capsys)
    assert _tree(out) == before
    assert _staging(out) == []
    new = tmp_path / "new"
    assert main(["analyze", str(fake_db), "--out", str(new)]) == 2
    assert not new.exists() and _staging(new) == []


def test_analyze_interrupted_leaves_the_previous_results(tmp_path, capsys, monkeypatch, fake_db):
    import softbend.reports.analysis_figures as figures

    out = tmp_path / "analysis"
    assert main(["analyze", str(fake_db), "--out", str(out)]) == 0
    before = _tree(out)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(figures, "loadings_bar", interrupted)
    assert main(["analyze", str(fake_db), "--out", str(out)]) != 0
    assert _tree(out) == before
    assert _staging(out) == []


def test_analyze_prints_the_final_paths(tmp_path, capsys, fake_db):
    out = tmp_path / "analysis"
    assert main(["analyze", str(fake_db), "--out", str(out), "--json"]) == 0
    files = json.loads(capsys.readouterr().out)["files"]
    assert files["loadings"] == str(out / "loadings.png")
    assert files["parity"] == str(out / "parity.png")
    assert files["coefficients"] == str(out / "coefficients.csv")
    assert files["correlation"] == str(out / "correlation.csv")  # the table, after the figure
    assert all(Path(p).is_file() for p in files.values())


# ----------------------------------------------------------------------------- reproduce


def test_reproduce_stopped_midway_leaves_the_previous_report(tmp_path, capsys, fake_reproduce):
    out = tmp_path / "report"
    assert main(_reproduce(out, 0)) == 0
    before = _tree(out)
    assert json.loads((out / "summary.json").read_text())["seed"] == 0
    fake_reproduce["stop_at"] = "transfer"  # paper A, the campaign and the FEM written by then
    assert main(_reproduce(out, 1)) != 0
    assert _tree(out) == before  # no file of seed 1 under seed 0's report
    assert _staging(out) == []
    # the campaign went further: kept aside for the next run, which resumes it
    assert fake_reproduce["campaigns"] == [0, 4]
    fake_reproduce["stop_at"] = None
    capsys.readouterr()
    assert main(_reproduce(out, 1)) == 0
    # the sections finished before the stop (paper A, the campaign) are taken over, not rerun
    assert fake_reproduce["campaigns"] == [0, 4]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["seed"] == 1
    taken = summary["provenance"]["sections taken over from an interrupted run"]
    assert taken.startswith("paper_a, paper_b") and "transfer" not in taken
    assert (out / "transfer" / "result.txt").read_text() == "seed 1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]  # nothing left beside it


def test_reproduce_killed_resumes_the_campaign_and_removes_the_stage(
    tmp_path, capsys, fake_reproduce
):
    out = tmp_path / "report"
    assert main(_reproduce(out, 0)) == 0
    before = _tree(out)
    # a run killed (kill -9) after its campaign: its staging folder is left beside --out
    stale = tmp_path / f".report.{dead_pid()}-abcd1234.new"
    (stale / "paper_b").mkdir(parents=True)
    (stale / "paper_b" / "campaign.duckdb").write_text("8\n")
    (stale / "paper_a").mkdir()
    (stale / "paper_a" / "result.txt").write_text("seed 1\n")
    _unfinished_manifest(stale, "reproduce")  # what every staging folder starts with
    assert _tree(out) == before  # --out never saw the killed run
    assert main(_reproduce(out, 1)) == 0
    assert fake_reproduce["campaigns"] == [0, 8]  # resumed where the killed run was
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]
    assert json.loads((out / "summary.json").read_text())["seed"] == 1


def test_reproduce_rerun_resumes_from_a_copy_and_names_the_final_files(
    tmp_path, capsys, fake_reproduce
):
    out = tmp_path / "report"
    assert main(_reproduce(out, 0)) == 0
    capsys.readouterr()
    fake_reproduce["stop_at"] = "paper_b_fem"
    assert main(_reproduce(out, 1)) != 0
    # the previous report's database is its own: the failed run worked on a copy
    assert (out / "paper_b" / "campaign.duckdb").read_text() == "4\n"
    fake_reproduce["stop_at"] = None
    capsys.readouterr()
    assert main(_reproduce(out, 1)) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["report"] == str(out / "index.html")
    assert summary["paper_a"]["file"] == str(out / "paper_a" / "result.txt")
    assert json.loads((out / "summary.json").read_text()) == summary
    assert ".new" not in (out / "index.html").read_text(encoding="utf-8")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_run_reproduce_refuses_a_folder_of_other_files(tmp_path, fake_reproduce):
    from softbend.reports.reproduce import run_reproduce

    out = tmp_path / "mine"
    out.mkdir()
    (out / "data.csv").write_text("keep me\n")
    with pytest.raises(ValueError, match=r"^out_dir: .*mine is replaced as a whole .*\(data.csv\)"):
        run_reproduce(out)
    assert (out / "data.csv").read_text() == "keep me\n"
    assert os.listdir(tmp_path) == ["mine"]
