"""softbend.references: each paper value has a source, is the paper's, and the code uses it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import softbend
from softbend import references as refs
from softbend.references import Reference, all_references, values

ROOT = Path(softbend.__file__).resolve().parents[2]


def test_every_reference_names_its_paper_and_a_place_in_it():
    found = all_references()
    assert len(found) > 60
    for name, ref in found.items():
        assert isinstance(ref, Reference), name
        assert ref.paper in {"A", "B"}, name
        assert ref.source.strip(), name
        assert re.search(r"\b(Table|Fig\.|Sec\.|Eq\.|p\.)\s*\d", ref.source), (name, ref.source)
        assert isinstance(ref.unit, str) and isinstance(ref.note, str), name
        assert ref.cite() == f"paper {ref.paper}, {ref.source}"


def test_every_group_of_the_module_is_listed():
    groups = {
        name
        for name in refs.__all__
        if name.isupper() and name != "PAPERS" and not name.startswith("_")
    }
    listed = {name.split(".")[0] for name in all_references()}
    assert groups == listed


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"paper": "C"}, "paper"),
        ({"source": ""}, "source"),
        ({"source": "somewhere in the text"}, "source"),
        ({"unit": None}, "unit"),
        ({"note": 3}, "note"),
    ],
)
def test_a_bad_reference_is_one_value_error_naming_the_field(kwargs, field):
    args = {"value": 1.0, "unit": "mm", "paper": "B", "source": "Table 1", **kwargs}
    with pytest.raises(ValueError, match=rf"^{field}: must") as info:
        Reference(**args)
    assert info.value.key == field
    assert "\n" not in str(info.value)


def test_str_gives_value_unit_and_citation():
    ref = refs.TRANSFER_RESULTS["rmse_deg"]
    assert str(ref) == "7.935 deg (paper B, Sec. 4.3, Fig. 7)"
    assert str(refs.LINEAR_MODEL["r2"]) == "0.8893 (paper B, Sec. 3.3, Fig. 4c)"


def test_values_keeps_keys_and_order_and_refuses_other_entries():
    assert values(refs.CONTROL_RESULTS) == {
        "square": {"mape_pct": 5.5, "settling_s": 0.7, "rise_s": 0.104},
        "triangle": {"mape_pct": 5.3, "delay_s": 0.0875},
    }
    assert list(values(refs.LINEAR_MODEL)) == list(refs.LINEAR_MODEL)
    with pytest.raises(ValueError, match=r"^group: x must be a Reference"):
        values({"x": 1.0})


# Spot checks against the papers: a typo in references.py fails here.


def test_paper_b_surrogate_figures_sec_4_1():
    expected = {
        "plr": ("degree 4", 0.9986, 1.8, 22.39),
        "xgb": ("max depth 9, learning rate 0.2", 0.9995, 0.8, 53.77),
        "mlp": ("hidden (63, 65)", 0.9991, 0.89, 12.99),
    }
    got = values(refs.SURROGATES)
    for family, (params, r2, mape, it_ms) in expected.items():
        assert got[family] == {"params": params, "r2": r2, "mape_pct": mape, "inference_ms": it_ms}
        assert refs.SURROGATES[family]["inference_ms"].unit == "ms"
    training = values(refs.SURROGATE_TRAINING)
    assert training["mlp_hidden"] == (63, 65)
    assert training["mlp_hidden_units"] == (55, 65)
    assert (training["mlp_epochs"], training["mlp_batch_size"]) == (1000, 1024)
    assert training["mlp_learning_rate"] == 6e-4
    assert training["folds"] == 5


def test_paper_b_fem_data_and_linear_model_sec_3_3():
    assert values(refs.FEM_DATASET) == {"designs": 972, "samples": 29577}
    assert values(refs.LINEAR_MODEL) == {
        "pressure_mpa": 0.832,
        "t_mm": -0.369,
        "b_mm": -0.005,
        "r2": 0.8893,
        "f_value": 33935.8,
        "mape_pct": 42.3,
    }


def test_paper_b_table_1():
    space = values(refs.DESIGN_SPACE)
    assert space["l_mm"] == (100, 120, 140, 160)
    assert space["r_mm"] == (6, 8, 10)
    assert space["t_mm"] == space["b_mm"] == (2, 3, 4)
    assert space["phi_deg"] == (5, 10, 15)
    assert space["lc_mm"] == (8, 10, 12)
    assert (space["pressure_max_mpa"], space["pressure_step_mpa"]) == (0.5, 0.005)
    count = 1
    for name in ("l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm"):
        count *= len(space[name])
    assert count == refs.FEM_DATASET["designs"].value


def test_paper_b_materials_sec_3_1():
    m = values(refs.MATERIALS)
    assert m["dragon-skin-30"] == {
        "c10_mpa": 0.11,
        "c20_mpa": 0.003,
        "c30_mpa": 0.0,
        "density_g_per_cm3": 1.08,
        "fit_r2": 0.9982,
        "fit_rmse_mpa": 0.0204,
    }
    assert (m["fiberglass"]["c10_mpa"], m["fiberglass"]["density_g_per_cm3"]) == (7.9, 2.40)
    assert m["fiberglass"]["thickness_mm"] == 0.1
    assert (m["kevlar"]["e_mpa"], m["kevlar"]["nu"]) == (31076.0, 0.36)
    assert m["kevlar"]["density_g_per_cm3"] == 1.67
    assert m["kevlar"]["diameter_mm"] == 0.28
    assert m["kevlar"]["modelled_radius_mm"] == m["kevlar"]["diameter_mm"] / 4


def test_paper_b_transfer_and_control_secs_4_and_5():
    assert values(refs.TRANSFER_RESULTS) == {
        "rmse_deg": 7.935,
        "mape_pct": 6.45,
        "worst": "120,6,2,2,5,8",
        "worst_rmse_deg": 19.58,
        "worst_mape_pct": 11.24,
        "n_measurements": 139,
    }
    assert values(refs.TRANSFER_LOSS) == {"fem-only": 4.8124, "refined": 0.1631}
    actuators = refs.MEASURED_ACTUATORS.value
    assert len(actuators) == 7 and actuators[0] == (100, 6, 2, 2, 5, 8)
    # Fig. 7c, the worst actuator, is the second panel after the reference (Fig. 7b).
    assert ",".join(map(str, actuators[1])) == refs.TRANSFER_RESULTS["worst"].value
    assert refs.FEM_VALIDATION["design"].value == "100,6,2,2,5,10"
    assert refs.FEM_VALIDATION["pmax_mpa"].value == 0.17
    assert values(refs.CONTROL_LOOP) == {
        "deadzone": 0.05,
        "sample_rate_hz": 100.0,
        "triangle_frequency_hz": 0.2,
    }


def test_paper_a_values():
    assert values(refs.CURLING_ACTUATOR) == {
        "rest_length_mm": 15.25,
        "max_length_mm": 18.25,
        "min_length_mm": 9.25,
        "max_elongation_pct": 19.67,
        "max_shrink_pct": 39.34,
    }
    a = values(refs.CURLING_ACTUATOR)
    assert round(100 * (a["max_length_mm"] / a["rest_length_mm"] - 1), 2) == 19.67
    assert round(100 * (1 - a["min_length_mm"] / a["rest_length_mm"]), 2) == 39.34
    ident = values(refs.CURLING_IDENTIFICATION)
    assert (ident["svr_c"], ident["svr_epsilon"]) == (100.0, 0.1)
    assert (ident["experiments"], ident["samples_per_experiment"]) == (6, 512)


# The code reads its paper values from softbend.references.


def test_the_code_compares_against_the_references():
    from softbend.control.study import PAPER_B_CONTROL
    from softbend.design import (
        FIBER_DIAMETER_MM,
        PAPER_B_FIG7_DESIGNS,
        STRAIN_LIMITING_LAYER_MM,
        TABLE1_LEVELS,
    )
    from softbend.materials.presets import (
        DRAGON_SKIN_30,
        FIBERGLASS_LAYER,
        KEVLAR_FIBER,
        KEVLAR_MODELLED_RADIUS_MM,
    )
    from softbend.pipeline.paper_b_fem import FIG2_DESIGN, FIG2_PMAX_MPA
    from softbend.pipeline.paper_b_fem_data import TABLE1_DESIGNS
    from softbend.reports.paper_b import PAPER_B_FIG4, PAPER_B_SAMPLES
    from softbend.reports.transfer_figures import PAPER_B_FINAL_LOSS
    from softbend.reports.transfer_section import PAPER_B_REFINED
    from softbend.surrogates.workflow import PAPER_B_FIG5

    assert values(refs.SURROGATES) == PAPER_B_FIG5
    assert values(refs.CONTROL_RESULTS) == PAPER_B_CONTROL
    assert values(refs.LINEAR_MODEL) == PAPER_B_FIG4
    assert PAPER_B_SAMPLES == 29577 and TABLE1_DESIGNS == 972
    assert values(refs.TRANSFER_RESULTS) == PAPER_B_REFINED
    assert values(refs.TRANSFER_LOSS) == PAPER_B_FINAL_LOSS
    assert (FIG2_DESIGN, FIG2_PMAX_MPA) == ("100,6,2,2,5,10", 0.17)
    assert {k: refs.DESIGN_SPACE[k].value for k in TABLE1_LEVELS} == TABLE1_LEVELS
    assert [str(d) for d in PAPER_B_FIG7_DESIGNS] == [
        ",".join(map(str, v)) for v in refs.MEASURED_ACTUATORS.value
    ]
    assert (FIBER_DIAMETER_MM, STRAIN_LIMITING_LAYER_MM, KEVLAR_MODELLED_RADIUS_MM) == (
        0.28,
        0.1,
        0.07,
    )
    assert DRAGON_SKIN_30.model.to_dict() == {
        "model": "yeoh",
        "c10_mpa": 0.11,
        "c20_mpa": 0.003,
        "c30_mpa": 0.0,
    }
    assert DRAGON_SKIN_30.density_t_per_mm3 == 1.08 * 1e-9
    assert FIBERGLASS_LAYER.density_t_per_mm3 == 2.40 * 1e-9
    assert (KEVLAR_FIBER.model.e_mpa, KEVLAR_FIBER.model.nu) == (31076.0, 0.36)


def test_references_imports_nothing_from_softbend_but_errors():
    text = (ROOT / "src" / "softbend" / "references.py").read_text(encoding="utf-8")
    imported = set(re.findall(r"^\s*(?:from|import) (softbend[\w.]*)", text, re.MULTILINE))
    assert imported <= {"softbend.errors"}


# Docstrings and comments cite the papers by section, figure, table or equation, never a
# document outside the repository.

_CITATION = re.compile(r"\b" + "SP" + "EC" + r"\b")


@pytest.mark.parametrize("folder", ["src", "tests", "benchmarks", "examples"])
def test_no_file_cites_a_document_outside_the_repository(folder):
    base = ROOT / folder
    if not base.is_dir():
        pytest.skip(f"no {folder}/ in this checkout")
    offenders = [
        f"{path.relative_to(ROOT)}:{number}"
        for path in sorted(base.rglob("*"))
        if path.is_file() and path.suffix in {".py", ".md", ".rst", ".txt", ".toml", ".sh"}
        for number, line in enumerate(
            path.read_text(encoding="utf-8", errors="replace").splitlines(), 1
        )
        if _CITATION.search(line)
    ]
    assert not offenders, offenders
