"""``softbend campaign run|merge`` faults: refused before any work, or a runtime fault, one line.

The FEM's mesh-size rule is checked on every design of the space before any
sweep (with a stand-in FEM, so no NGSolve is needed); a run whose every design
fails exits 1 with the first reason; ``campaign merge`` names each input that is
not a campaign database (a CSV, an empty file, a folder, another DuckDB file).
"""

from __future__ import annotations

import dataclasses
import json
from types import SimpleNamespace

import duckdb
import pytest

from softbend.analytical import AnalyticalModel
from softbend.cli import main
from softbend.design import DesignSpace, SFRBADesign
from softbend.errors import ConvergenceError
from softbend.fem.geometry import check_mesh_size
from softbend.fem.options import FEMOptions

from .conftest import one_error_line

RUN = ["--space", "lhs:6", "--seed", "3", "--pmax", "0.1", "--pstep", "0.05", "--workers", "0"]
FEM_RUN = ["--backend", "fem", "--space", "corners", "--pmax", "0.01", "--workers", "0"]
#: The largest design of the corners: the one a too-fine mesh size is refused for.
LARGEST_CORNER = SFRBADesign(160, 10, 4, 4, 5, 12)


@dataclasses.dataclass(frozen=True)
class _StandInFEM:
    """The FEM as the campaign sees it (a name, FEM options, a sweep), without NGSolve."""

    options: FEMOptions
    compiled: bool = False
    name: str = dataclasses.field(default="fem", init=False)

    def sweep(self, design, pressures_mpa):
        raise AssertionError(f"swept {design}: the mesh size should have been refused first")


@pytest.fixture
def stand_in_fem(monkeypatch):
    """``--backend fem`` builds :class:`_StandInFEM` with the real FEMOptions."""
    import softbend.campaign.backends as backends

    fem = SimpleNamespace(FEMOptions=FEMOptions, FEMModel=_StandInFEM)
    monkeypatch.setattr(backends, "_import_fem", lambda: fem)


def _mesh_message(design: SFRBADesign, maxh_mm: float) -> str:
    with pytest.raises(ValueError) as info:
        check_mesh_size(design, maxh_mm)
    return str(info.value)


# -- --maxh: the FEM's rule, before any work ---------------------------------------------


@pytest.mark.parametrize(
    ("maxh", "message"),
    [
        ("0.3", _mesh_message(LARGEST_CORNER, 0.3)),
        ("25", "--maxh: must be a number in (0, 20]; got 25.0"),
    ],
    ids=["too many elements", "above the range"],
)
def test_a_maxh_the_fem_refuses_is_refused_before_any_design(
    tmp_path, capsys, stand_in_fem, maxh, message
):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *FEM_RUN, "--maxh", maxh]) == 2
    assert one_error_line(capsys) == f"softbend: error: {message.replace('maxh_mm: ', '--maxh: ')}"
    assert not db.exists() and list(tmp_path.iterdir()) == []


def test_the_mesh_rule_names_the_design_with_the_most_elements():
    corners = DesignSpace.corners().designs
    # At 1.445 mm only the two largest corners (phi 5 and 15, one volume) need more than
    # 400000 elements; the first of them is named, as the FEM would name it.
    largest = [
        d for d in corners if (d.l_mm, d.r_mm, d.t_mm, d.b_mm, d.lc_mm) == (160, 10, 4, 4, 12)
    ]
    assert len(largest) == 2
    check_mesh_size([d for d in corners if d not in largest], 1.445)
    with pytest.raises(ValueError) as info:
        check_mesh_size(corners, 1.445)
    assert str(info.value) == _mesh_message(LARGEST_CORNER, 1.445)
    assert "got 1.445 mm (about 407888 elements)" in str(info.value)
    FEMOptions(maxh_mm=5.0).check_mesh(corners)  # the default mesh size meshes them all
    check_mesh_size([], 0.1)  # nothing to mesh


def test_run_campaign_checks_the_mesh_of_every_design_first(tmp_path):
    from softbend.campaign import run_campaign

    db = tmp_path / "c.duckdb"
    with pytest.raises(ValueError, match="must give at most 400000 elements for design"):
        run_campaign(
            db,
            DesignSpace.corners(),
            backend=_StandInFEM(FEMOptions(maxh_mm=0.5)),
            pressures_mpa=[0.0, 0.01],
            workers=0,
        )
    assert not db.exists()


def test_the_mesh_rule_is_the_one_the_fem_applies_when_meshing():
    import softbend._torch  # noqa: F401  (PyTorch before NGSolve, as softbend.fem loads them)
    from softbend.fem.geometry import mesh_actuator

    pytest.importorskip("ngsolve")

    design = SFRBADesign(100, 6, 2, 2, 5, 10)
    with pytest.raises(ValueError) as info:
        mesh_actuator(design, maxh_mm=0.3)
    assert str(info.value) == _mesh_message(design, 0.3)


# -- a run whose every design failed is a runtime fault ----------------------------------


def _failing_sweeps(monkeypatch, fail) -> None:
    """The analytical model's sweep raises for the designs ``fail(design)`` picks."""
    sweep = AnalyticalModel.sweep

    def flaky(self, design, pressures_mpa):
        if fail(design):
            raise ConvergenceError(f"no equilibrium for design {design}", pressure_mpa=0.05)
        return sweep(self, design, pressures_mpa)

    monkeypatch.setattr(AnalyticalModel, "sweep", flaky)


@pytest.mark.parametrize("as_json", [False, True], ids=["table", "json"])
def test_a_run_whose_every_design_failed_exits_1_with_the_reason(
    tmp_path, capsys, monkeypatch, as_json
):
    _failing_sweeps(monkeypatch, lambda design: True)
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, *(["--json"] if as_json else [])]) == 1
    captured = capsys.readouterr()
    errors = [line for line in captured.err.splitlines() if line.startswith("softbend: error:")]
    assert len(errors) == 1 and "Traceback" not in captured.err
    assert errors[0].startswith("softbend: error: every design of this run failed (6 of 6); ")
    assert "; the first: no equilibrium for design " in errors[0]
    assert "ConvergenceError" not in errors[0]  # the reason, not the exception's type
    assert f"recorded in {db} as failed" in errors[0]
    if as_json:  # the summary still comes first, whole
        assert json.loads(captured.out)["n_failed"] == 6
    else:
        assert "failed in this run" in captured.out
    # The failures stay recorded; a re-run that sweeps them retries them.
    monkeypatch.undo()
    assert main(["campaign", "run", str(db), *RUN, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_done"] == 6


def test_a_run_with_some_failed_designs_or_none_left_exits_0(tmp_path, capsys, monkeypatch):
    failed: list[SFRBADesign] = []

    def first_only(design):
        if not failed:
            failed.append(design)
        return design == failed[0]

    _failing_sweeps(monkeypatch, first_only)
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["n_done"], summary["n_failed"]) == (5, 1)
    # Nothing left to sweep (the failed one kept): no design run, no fault.
    assert main(["campaign", "run", str(db), *RUN, "--no-retry-failed", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_run"] == 0


# -- campaign merge: every input that is not a campaign, named ---------------------------


@pytest.fixture
def shard(tmp_path, capsys):
    path = tmp_path / "s0.duckdb"
    assert main(["campaign", "run", str(path), *RUN, "--json"]) == 0
    capsys.readouterr()
    return path


def _csv(path):
    path.write_text("design_id,angle_deg\nd1,12.5\n")


def _empty(path):
    path.write_bytes(b"")


def _folder(path):
    path.mkdir()


def _other_duckdb(path):
    con = duckdb.connect(str(path))
    con.execute("CREATE TABLE measurements (x INTEGER)")
    con.close()


NOT_READABLE = "is not a readable softbend campaign database"
WHAT_IT_MUST_BE = (
    "a campaign database is the DuckDB file that 'softbend campaign run' or "
    "'softbend campaign merge' writes)."
)


@pytest.mark.parametrize(
    ("name", "make", "said"),
    [
        ("all.csv", _csv, f"{NOT_READABLE} (not a DuckDB database file; "),
        ("x.duckdb", _csv, f"{NOT_READABLE} (not a DuckDB database file; "),
        ("e.duckdb", _empty, f"{NOT_READABLE} (an empty file; "),
        ("d.duckdb", _folder, "is a folder, not a softbend campaign database ("),
        ("o.duckdb", _other_duckdb, "is not a softbend campaign database (no 'meta' table; found"),
    ],
    ids=["a csv", "a csv named .duckdb", "empty", "a folder", "another duckdb"],
)
@pytest.mark.parametrize("role", ["shard", "target"])
def test_merge_names_an_input_that_is_not_a_campaign(
    tmp_path, capsys, shard, name, make, said, role
):
    bad = tmp_path / name
    make(bad)
    before = None if bad.is_dir() else bad.read_bytes()
    target, shards = (tmp_path / "m.duckdb", [shard, bad]) if role == "shard" else (bad, [shard])
    assert main(["campaign", "merge", str(target), *map(str, shards)]) == 2
    line = one_error_line(capsys)
    if role == "target" and bad.is_dir():  # the output's own check
        assert line == f"softbend: error: The 'DB' must name a file; {bad} is a folder."
    else:
        assert line.startswith(f"softbend: error: {str(bad)!r} {said}")
        assert line.endswith(WHAT_IT_MUST_BE)
    for words in ("Catalog Error", "IO Error", "in-memory", "Traceback"):
        assert words not in line
    assert (bad.is_dir() and before is None) or bad.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted({shard.name, name})


def test_merge_names_a_missing_shard(tmp_path, capsys, shard):
    missing = tmp_path / "missing.duckdb"
    assert main(["campaign", "merge", str(tmp_path / "m.duckdb"), str(shard), str(missing)]) == 2
    assert one_error_line(capsys) == f"softbend: error: No campaign database at {str(missing)!r}."
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s0.duckdb"]


def test_status_and_run_read_a_csv_as_no_campaign(tmp_path, capsys):
    bad = tmp_path / "all.csv"
    _csv(bad)
    for argv in (["campaign", "status", str(bad)], ["campaign", "run", str(bad), *RUN]):
        assert main(argv) == 2
        line = one_error_line(capsys)
        assert line.startswith(f"softbend: error: {str(bad)!r} is not a readable softbend campaign")
        assert line.endswith(WHAT_IT_MUST_BE)
    assert bad.read_text() == "design_id,angle_deg\nd1,12.5\n"
