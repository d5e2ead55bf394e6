"""--material: a preset or a fit of one's own tensile test, used by the FEM and recorded."""

from __future__ import annotations

import json

import pytest

from softbend.cli import main
from softbend.errors import SchemaError
from softbend.materials import DRAGON_SKIN_30, material_from_spec
from softbend.registry import UnknownNameError


def test_a_preset_by_name():
    assert material_from_spec("dragon-skin-30") is DRAGON_SKIN_30


def test_a_fit_file_gives_its_best_or_named_model(fit_file):
    fits = json.loads(fit_file.read_text())
    best = material_from_spec(fit_file)
    assert best.model.name == fits["best_model"] == "yeoh"
    neo = material_from_spec(f"{fit_file}#neo-hookean")
    assert neo.model.name == "neo-hookean"
    assert neo.model.to_dict()["c10_mpa"] == pytest.approx(fits["fits"][0]["parameters"]["c10_mpa"])
    assert "assumed (Dragon Skin 30's)" in best.source and str(fit_file) in best.source
    tested = fits["test"]["material"]
    assert tested and best.name == f"{tested} (yeoh)"  # named as the tensile test names it
    assert best.density_g_per_cm3 == pytest.approx(DRAGON_SKIN_30.density_g_per_cm3)
    assert material_from_spec(fit_file, density_g_per_cm3=1.07).density_g_per_cm3 == (
        pytest.approx(1.07)
    )


def test_bad_specs_are_one_line(fit_file):
    with pytest.raises(UnknownNameError, match="known: dragon-skin-30, fiberglass, kevlar") as info:
        material_from_spec("ecoflex")
    assert info.value.key == "spec" and "or a fit.json of 'softbend materials fit'" in str(
        info.value
    )
    with pytest.raises(SchemaError, match=r"^spec: names model 'ogden'.*holds neo-hookean, yeoh"):
        material_from_spec(f"{fit_file}#ogden")


def test_fem_run_uses_and_records_the_material(fit_file, tmp_path, capsys):
    """The lab's own Yeoh fit (stiffer than paper B's constants) bends the actuator less."""
    base = ["fem", "run", "--design", "100,6,2,2,5,8", "--pmax", "0.04", "--pstep", "0.02",
            "--maxh", "8", "--json"]  # fmt: skip
    angles = {}
    for name, extra in (("paper", []), ("own", ["--material", f"{fit_file}#yeoh"])):
        assert main([*base, "-o", str(tmp_path / name), *extra]) == 0, capsys.readouterr().err
        angles[name] = json.loads(capsys.readouterr().out)["angle_deg"][-1]
        sweep = json.loads((tmp_path / name / "sweep.json").read_text())
        recorded = sweep["stats"]["options"]["elastomer"]
        assert recorded["model"]["model"] == "yeoh"
    assert recorded["source"].startswith(str(fit_file))
    assert 0 < angles["own"] < angles["paper"]
    code = main([*base, "-o", str(tmp_path / "bad"), "--material", "ecoflex"])
    assert code == 2 and "Unknown material preset 'ecoflex'" in capsys.readouterr().err


def test_a_fit_whose_test_names_no_material_is_named_after_its_file(fit_file, tmp_path):
    fits = json.loads(fit_file.read_text())
    fits["test"]["material"] = ""
    unnamed = tmp_path / "bench-3.json"
    unnamed.write_text(json.dumps(fits))
    assert material_from_spec(unnamed).name == "bench-3 (yeoh)"
