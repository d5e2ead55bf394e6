"""A campaign records its backend's settings and refuses to mix others on resume or merge."""

from __future__ import annotations

import hashlib
import json

import duckdb
import numpy as np
import pytest

from softbend.campaign import CampaignStore, run_campaign
from softbend.campaign.settings import (
    SettingsMismatchError,
    UncheckedSettingsWarning,
    backend_settings,
    settings_differences,
)
from softbend.campaign.store import merge_campaigns
from softbend.cli import main
from softbend.design import sfrba_design
from softbend.errors import SchemaError
from softbend.models import SweepResult, default_pressures_mpa

GRID = default_pressures_mpa(0.1, 0.05)
DESIGNS = [sfrba_design(100, 6, 2, 2, 5, 8), sfrba_design(120, 8, 2, 2, 5, 10)]
CLI_RUN = ["--space", "lhs:3", "--seed", "2", "--pmax", "0.1", "--pstep", "0.05", "--workers", "0"]


@pytest.fixture
def fast_fem(monkeypatch):
    """The FEM backend with its solve replaced by a linear stand-in (no mesh, no Newton)."""

    def fake_simulate(design, pressures_mpa, options=None):
        grid = np.asarray(pressures_mpa, dtype=float)
        zeros = np.zeros_like(grid)
        return SweepResult.from_angles(design, grid, 500.0 * grid, zeros, zeros, wall_time_s=0.0)

    monkeypatch.setattr("softbend.fem.model.simulate", fake_simulate)
    monkeypatch.setattr("softbend.fem.model.use_compiled", lambda compiled: None)


def _fem(db, **options):
    material = options.pop("material", None)
    return run_campaign(
        db,
        DESIGNS,
        backend="fem",
        backend_options=options or None,
        pressures_mpa=GRID,
        workers=0,
        material=material,
    )


def _forget_settings(db):
    """Make ``db`` look like a database of a softbend that recorded no settings."""
    con = duckdb.connect(str(db))
    con.execute("DELETE FROM meta WHERE key = 'settings'")
    con.close()


def test_the_settings_are_recorded_at_the_start(tmp_path, fast_fem, fit_file):
    db = tmp_path / "c.duckdb"
    _fem(db, maxh_mm=6.0, material=f"{fit_file}#yeoh")
    with CampaignStore(db, read_only=True) as store:
        settings = store.settings
        status = store.status_summary()
    assert settings["backend"] == "fem"
    assert settings["pressures_mpa"] == {"count": 3, "first": 0.0, "last": 0.1}
    assert settings["options"]["maxh_mm"] == 6.0 and settings["options"]["order"] == 2
    assert "threads" not in settings["options"]
    material = settings["material"]
    assert material["model"]["model"] == "yeoh" and material["model"]["c10_mpa"] > 0
    assert material["given"] == {
        "spec": f"{fit_file}#yeoh",
        "file": str(fit_file),
        "model": "yeoh",
        "sha256": hashlib.sha256(fit_file.read_bytes()).hexdigest(),
    }
    assert status["settings"] == settings


@pytest.mark.parametrize(
    ("first", "second", "needles"),
    [
        ({"maxh_mm": 5.0}, {"maxh_mm": 4.0}, ["options.maxh_mm is 5 there, 4 here"]),
        ({}, {"material": "{fit}#neo-hookean"}, ["material.model.model is 'yeoh' there, "]),
        ({"gravity": "none"}, {}, ["options.gravity is 'none' there, 'bending' here"]),
    ],
    ids=["another maxh", "another material", "another option"],
)
def test_a_resume_with_other_settings_is_refused(
    tmp_path, fast_fem, fit_file, first, second, needles
):
    db = tmp_path / "c.duckdb"
    _fem(db, **first)
    second = {k: v.format(fit=fit_file) if isinstance(v, str) else v for k, v in second.items()}
    with pytest.raises(SettingsMismatchError) as caught:
        _fem(db, **second)
    message = str(caught.value)
    assert all(needle in message for needle in needles), message
    assert message.startswith(
        f"accept_new_settings: must be set to resume the campaign '{db}'"
    ) and ("a new database" in message)
    with CampaignStore(db, read_only=True) as store:
        assert len(store.runs()) == 1  # nothing of the refused run was recorded


def test_the_same_settings_resume_and_a_named_default_is_the_default(tmp_path, fast_fem):
    db = tmp_path / "c.duckdb"
    assert _fem(db).n_done == 2
    again = _fem(db, material="dragon-skin-30", maxh_mm=5.0)
    assert (again.n_skipped_done, again.n_done) == (2, 0)


def test_an_accepted_change_runs_and_is_kept_in_the_run_record(tmp_path, fast_fem, fit_file):
    db = tmp_path / "c.duckdb"
    run_campaign(db, DESIGNS[:1], backend="fem", pressures_mpa=GRID, workers=0)
    summary = run_campaign(
        db,
        DESIGNS,
        backend="fem",
        backend_options={"maxh_mm": 4.0},
        pressures_mpa=GRID,
        workers=0,
        accept_new_settings=True,
    )
    assert summary.n_done == 1
    with CampaignStore(db, read_only=True) as store:
        assert store.settings["options"]["maxh_mm"] == 5.0  # the campaign's first settings
        assert [r["settings"]["options"]["maxh_mm"] for r in store.runs()] == [5.0, 4.0]


def test_the_cli_refuses_another_material_in_one_line_and_accepts_on_request(
    tmp_path, capsys, fit_file
):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *CLI_RUN, "--json"]) == 0
    capsys.readouterr()
    assert main(["campaign", "run", str(db), *CLI_RUN, "--material", "dragon-skin-30"]) == 0
    assert "3 of 3 designs already recorded" in capsys.readouterr().err
    other = ["campaign", "run", str(db), *CLI_RUN, "--material", f"{fit_file}#neo-hookean"]
    assert main(other) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith(
        f"softbend: error: --accept-new-settings: must be set to resume the campaign '{db}'"
    )
    assert "material.model.model is 'yeoh' there, 'neo-hookean' here" in err[0]
    assert "or write to a new database" in err[0]
    assert main([*other, "--accept-new-settings", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_skipped_done"] == 3


def test_an_old_database_without_settings_resumes_with_a_warning(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    run_campaign(db, DESIGNS[:1], backend="analytical", pressures_mpa=GRID, workers=0)
    _forget_settings(db)
    with pytest.warns(UncheckedSettingsWarning, match="1 designs recorded before could not"):
        summary = run_campaign(db, DESIGNS, backend="analytical", pressures_mpa=GRID, workers=0)
    assert summary.n_done == 1
    with CampaignStore(db, read_only=True) as store:
        assert store.settings["backend"] == "analytical"  # recorded now, checked from now on
    _forget_settings(db)
    assert main(["campaign", "run", str(db), *CLI_RUN, "--json"]) == 0
    err = capsys.readouterr().err
    assert "softbend: warning: The campaign database" in err and "could not be checked" in err


def test_a_merge_of_shards_with_other_settings_writes_nothing(tmp_path, fast_fem):
    first, second, merged = (tmp_path / f"{n}.duckdb" for n in ("s0", "s1", "all"))
    run_campaign(first, DESIGNS[:1], backend="fem", pressures_mpa=GRID, workers=0)
    run_campaign(
        second,
        DESIGNS[1:],
        backend="fem",
        backend_options={"maxh_mm": 4.0},
        pressures_mpa=GRID,
        workers=0,
    )
    with pytest.raises(ValueError, match=r"options.maxh_mm is 5 in .*s0.duckdb', 4 in .*s1"):
        merge_campaigns(merged, [first, second])
    assert not merged.exists()
    # Shards of one campaign merge, and the merged database keeps their settings.
    run_campaign(
        second, DESIGNS[1:], backend="fem", pressures_mpa=GRID, workers=0, accept_new_settings=True
    )
    _forget_settings(second)
    with pytest.warns(UncheckedSettingsWarning, match="s1.duckdb"):
        merge_campaigns(merged, [first, second])
    with CampaignStore(merged, read_only=True) as store, CampaignStore(first, read_only=True) as s0:
        assert store.settings == s0.settings


def test_a_dataset_records_the_material(tmp_path, capsys):
    db, out = tmp_path / "c.duckdb", tmp_path / "data"
    preset = ["--material", "dragon-skin-30"]
    assert main(["campaign", "run", str(db), *CLI_RUN, *preset, "--json"]) == 0
    capsys.readouterr()
    command = ["campaign", "dataset", str(db), "--out", str(out), "--command", "x", "--json"]
    assert main(command) == 0
    printed = json.loads(capsys.readouterr().out)
    provenance = json.loads((out / "provenance.json").read_text())
    assert printed == provenance
    material = provenance["campaign_runs"][0]["material"]
    assert material["name"] == "Dragon Skin 30" and material["model"]["c10_mpa"] == 0.11
    assert material["given"] == {"spec": "dragon-skin-30"}


def test_damaged_settings_are_refused_on_opening(tmp_path):
    db = tmp_path / "c.duckdb"
    run_campaign(db, DESIGNS[:1], backend="analytical", pressures_mpa=GRID, workers=0)
    con = duckdb.connect(str(db))
    con.execute("UPDATE meta SET value = '[1, 2]' WHERE key = 'settings'")
    con.close()
    with pytest.raises(SchemaError, match=r"damaged 'settings'.*must be a JSON object"):
        CampaignStore(db, read_only=True)


def test_labels_are_recorded_but_not_compared():
    from softbend.analytical import AnalyticalModel
    from softbend.materials import DRAGON_SKIN_30
    from softbend.materials.presets import Material

    renamed = Material(
        name="DS30, batch 7",
        model=DRAGON_SKIN_30.model,
        density_t_per_mm3=DRAGON_SKIN_30.density_t_per_mm3,
        source="our lab",
    )
    paper = backend_settings(AnalyticalModel(), GRID)
    ours = backend_settings(AnalyticalModel(material=renamed), GRID)
    assert ours["material"]["name"] == "DS30, batch 7"
    assert settings_differences(paper, ours) == []
    stiffer = backend_settings(AnalyticalModel(max_angle_deg=360.0), default_pressures_mpa(0.2))
    assert settings_differences(paper, stiffer) == [
        ("options.max_angle_deg", None, 360.0),
        ("pressures_mpa.count", 3, 41),
        ("pressures_mpa.last", 0.1, 0.2),
    ]


def test_the_cli_mesh_size_reaches_the_fem_and_a_resume_with_another_is_refused(
    tmp_path, capsys, fast_fem
):
    db = tmp_path / "fem.duckdb"
    fem = ["campaign", "run", str(db), *CLI_RUN, "--backend", "fem", "--no-compile"]
    assert main([*fem, "--maxh", "4", "--json"]) == 0
    capsys.readouterr()
    with CampaignStore(db, read_only=True) as store:
        assert store.settings["options"]["maxh_mm"] == 4.0
    assert main([*fem, "--maxh", "3"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "options.maxh_mm is 4 there, 3 here" in err[0]
    analytical = ["campaign", "run", str(tmp_path / "a.duckdb"), *CLI_RUN, "--maxh", "4"]
    assert main(analytical) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--maxh" in err[0] and "no mesh" in err[0]
