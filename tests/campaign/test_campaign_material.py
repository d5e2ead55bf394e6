"""``campaign run --material``: the elastomer of every sweep of a campaign, in every process."""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

from softbend.campaign import CampaignStore, run_campaign
from softbend.campaign.backends import backend_for_run, get_backend, with_material
from softbend.cli import main
from softbend.design import DesignSpace, sfrba_design
from softbend.errors import SchemaError
from softbend.materials import DRAGON_SKIN_30, material_from_spec
from softbend.materials.models import Yeoh
from softbend.materials.presets import Material
from softbend.models import SweepResult, default_pressures_mpa
from softbend.registry import UnknownNameError

GRID = default_pressures_mpa(0.1, 0.05)
#: A softer elastomer than Dragon Skin 30 (half its Yeoh constants).
SOFT = Material(
    name="half Dragon Skin 30",
    model=Yeoh(c10_mpa=0.055, c20_mpa=0.0015),
    density_t_per_mm3=DRAGON_SKIN_30.density_t_per_mm3,
)
CLI_RUN = ["--space", "lhs:2", "--seed", "1", "--pmax", "0.1", "--pstep", "0.05", "--workers", "0"]


@pytest.fixture
def solves(monkeypatch):
    """Replace the FEM solve by a stand-in that records the elastomer of each call."""
    seen: list[Material] = []

    def fake_simulate(design, pressures_mpa, options=None):
        from softbend.fem import FEMOptions

        seen.append((options or FEMOptions()).elastomer)
        grid = np.asarray(pressures_mpa, dtype=float)
        angle = 500.0 * grid
        return SweepResult.from_angles(
            design, grid, angle, np.zeros_like(grid), np.zeros_like(grid), wall_time_s=0.0
        )

    monkeypatch.setattr("softbend.fem.model.simulate", fake_simulate)
    monkeypatch.setattr("softbend.fem.model.use_compiled", lambda compiled: None)
    return seen


def _two_designs() -> DesignSpace:
    return DesignSpace(
        (sfrba_design(100, 6, 2, 2, 5, 8), sfrba_design(120, 8, 2, 2, 5, 10)), name="two"
    )


def test_the_material_reaches_every_fem_solve(tmp_path, solves, fit_file):
    spec = f"{fit_file}#neo-hookean"
    summary = run_campaign(
        tmp_path / "c.duckdb",
        _two_designs(),
        backend="fem",
        pressures_mpa=GRID,
        workers=0,
        material=spec,
    )
    assert summary.n_done == 2
    assert solves == [material_from_spec(spec)] * 2
    assert solves[0].model.name == "neo-hookean"


def test_without_a_material_the_fem_solves_dragon_skin_30(tmp_path, solves):
    run_campaign(
        tmp_path / "c.duckdb", _two_designs(), backend="fem", pressures_mpa=GRID, workers=0
    )
    assert solves == [DRAGON_SKIN_30] * 2


def test_the_cli_material_reaches_the_solve_and_the_store(tmp_path, solves, fit_file, capsys):
    db = tmp_path / "c.duckdb"
    args = ["campaign", "run", str(db), "--backend", "fem", "--no-compile", *CLI_RUN, "--json"]
    assert main([*args, "--material", f"{fit_file}#yeoh"]) == 0, capsys.readouterr().err
    assert json.loads(capsys.readouterr().out)["n_done"] == 2
    assert solves == [material_from_spec(f"{fit_file}#yeoh")] * 2
    with CampaignStore(db, read_only=True) as store:
        material = store.settings["material"]
        run = store.runs()[-1]
    assert material["model"] == solves[0].model.to_dict()
    assert material["model"]["model"] == "yeoh"
    assert material["given"]["spec"] == f"{fit_file}#yeoh"
    assert run["material"] == material


def test_what_is_sent_to_workers_keeps_the_material(fit_file):
    material = material_from_spec(f"{fit_file}#neo-hookean")
    fem = backend_for_run("fem", material=f"{fit_file}#neo-hookean")
    assert backend_for_run("fem", material=material) == fem
    back = pickle.loads(pickle.dumps(fem))
    assert back == fem and back.options.elastomer == material
    faulty = get_backend("fault-injection", inner="fem")
    assert with_material(faulty, material).inner.options.elastomer == material


def test_a_material_reaches_worker_processes(tmp_path, designs, grid):
    """A softer wall bends the analytical actuator more, alike in one process and in two."""
    angles = {}
    for name, material, workers in (("paper", None, 0), ("soft", SOFT, 0), ("soft2", SOFT, 2)):
        db = tmp_path / f"{name}.duckdb"
        summary = run_campaign(
            db,
            designs,
            backend="analytical",
            pressures_mpa=grid,
            workers=workers,
            material=material,
        )
        assert summary.n_done + summary.n_failed == len(designs)
        with CampaignStore(db, read_only=True) as store:
            samples = store.load_samples()
        angles[name] = samples[samples["converged"]].set_index(["design_id", "pressure_mpa"])
    assert angles["soft2"]["angle_deg"].equals(angles["soft"]["angle_deg"])
    common = angles["paper"].index.intersection(angles["soft"].index)
    positive = [i for i in common if i[1] > 0]
    assert positive and all(
        angles["soft"].loc[i, "angle_deg"] > angles["paper"].loc[i, "angle_deg"] for i in positive
    )


def test_a_backend_without_a_material_refuses_one(tmp_path, capsys):
    with pytest.raises(ValueError, match=r"^material: applies to a backend that takes a material"):
        run_campaign(
            tmp_path / "c.duckdb",
            _two_designs(),
            backend=_NoMaterial(),
            pressures_mpa=GRID,
            workers=0,
            material="dragon-skin-30",
        )
    assert not (tmp_path / "c.duckdb").exists()
    db = tmp_path / "s.duckdb"
    args = ["campaign", "run", str(db), "--backend", "surrogate", "--material", "dragon-skin-30"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "softbend: error: --material: applies to a backend that takes a material "
        "(analytical, fem); got backend 'surrogate'"
    ]
    assert not db.exists()


@pytest.mark.parametrize(
    ("spec", "error", "needle"),
    [
        ("ecoflex", UnknownNameError, "known: dragon-skin-30, fiberglass, kevlar"),
        ("{fit}#ogden", SchemaError, "names model 'ogden'"),
    ],
    ids=["unknown preset", "unknown model of a fit"],
)
def test_a_bad_material_is_one_line_before_anything_is_written(
    tmp_path, capsys, fit_file, spec, error, needle
):
    spec = spec.format(fit=fit_file)
    with pytest.raises(error, match=needle):
        backend_for_run("fem", material=spec)
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), "--backend", "fem", *CLI_RUN, "--material", spec]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softbend: error: ")
    assert needle in err[0] and "--material" in err[0]
    assert not db.exists()


class _NoMaterial:
    """A backend with no elastomer to set."""

    name = "no-material"

    def sweep(self, design, pressures_mpa):  # pragma: no cover - never reached
        raise AssertionError("not swept")
