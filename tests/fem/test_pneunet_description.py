"""The PneuNet family's description: parameters, reference, checked designs (no NGSolve)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from softbend.actuators import ACTUATORS, Design
from softbend.errors import InputError
from softbend.fem.families import FEM_FAMILIES, get_family
from softbend.fem.pneunet.description import (
    PNEUNET,
    REFERENCE,
    cavity_volume_mm3,
    length_mm,
    pneunet_options,
)


@pytest.fixture(scope="module")
def family():
    return get_family("pneunet")


def test_the_pneunet_is_registered_as_an_actuator_and_an_fem_family(family):
    assert "pneunet" in ACTUATORS.names() and "pneunet" in FEM_FAMILIES.names()
    assert ACTUATORS.get("pneunet") is PNEUNET and PNEUNET.fem_family == "pneunet"
    assert family.actuator is PNEUNET and family.names == tuple(REFERENCE)
    assert "sfrba" in FEM_FAMILIES.names()  # paper B's family unchanged beside it


def test_the_reference_is_a_checked_design_inside_its_ranges(family):
    design = family.parse(None)
    assert isinstance(design, Design) and design.actuator.fem_family == "pneunet"
    assert design.as_dict() == REFERENCE
    codes = [[design.values[n] for n in PNEUNET.names]]
    assert PNEUNET.constraints_met(codes).all()
    for parameter in PNEUNET.parameters:
        assert parameter.low <= REFERENCE[parameter.name] <= parameter.high


def test_a_partial_design_takes_the_reference_for_what_it_leaves_out(family):
    design = family.parse("n_chambers=7, wall_mm=1.5")
    assert design.n_chambers == 7 and design.wall_mm == 1.5
    assert design.gap_mm == REFERENCE["gap_mm"]
    assert design.design_id != family.parse("").design_id


@pytest.mark.parametrize(
    ("text", "key", "needle"),
    [
        ("n_chambers=0", "n_chambers", "whole number of chambers >= 1"),
        ("n_chambers=2.5", "n_chambers", "whole number of chambers >= 1"),
        ("gap_mm=0", "gap_mm", "> 0 mm"),
        ("base_mm=-1", "base_mm", "> 0 mm"),
        ("wall_mm=4", "wall_mm", "< chamber_length_mm / 2 = 4 mm"),
        ("outer_wall_mm=8", "outer_wall_mm", "< chamber_width_mm / 2"),
        ("outer_wall_mm=5,chamber_height_mm=5", "outer_wall_mm", "< chamber_height_mm = 5"),
        ("wall_mm=inf", "wall_mm", "finite"),
        ("wall_mm=x", "wall_mm", "a number"),
        ("chambers=5", "design", "not a parameter of the pneunet family"),
    ],
)
def test_a_bad_design_is_one_error_naming_the_parameter(family, text, key, needle):
    with pytest.raises(InputError) as caught:
        family.parse(text)
    assert caught.value.key == key and needle in str(caught.value)


def test_derived_dimensions_are_the_closed_forms(family):
    design = family.parse("")
    # 5 cavities of (8 - 2.4) × (15 - 4) × (25 - 2) mm
    assert cavity_volume_mm3(design) == pytest.approx(5 * 5.6 * 11.0 * 23.0)
    assert length_mm(design, 3.0) == pytest.approx(3.0 + 5 * 8.0 + 4 * 2.5)


def test_the_family_options_are_the_pneunet_defaults_with_overrides(family):
    options = family.options(maxh_mm=2.0)
    assert options.maxh_mm == 2.0 and options.gravity == "none"
    assert options.elastomer.name == "Elastosil M4601"
    assert pneunet_options().maxh_mm == family.maxh_mm


def test_the_element_size_is_capped_by_the_thinnest_wall(family):
    from softbend.fem.pneunet.geometry import WALL_ELEMENT_RATIO, element_size_mm

    assert element_size_mm(family.parse(""), family.maxh_mm) == family.maxh_mm
    thin = family.parse("wall_mm=0.8")
    assert element_size_mm(thin, 3.0) == pytest.approx(WALL_ELEMENT_RATIO * 0.8)
    assert element_size_mm(thin, 1.0) == 1.0


def test_a_too_fine_mesh_is_refused_before_meshing(family):
    with pytest.raises(InputError) as caught:
        family.check_mesh(family.parse(""), family.options(maxh_mm=0.2))
    assert caught.value.key == "maxh_mm"


def test_the_description_and_registry_import_without_ngsolve():
    code = (
        "import sys\nsys.modules['ngsolve'] = None\nsys.modules['netgen'] = None\n"
        "from softbend.actuators import get_actuator\n"
        "from softbend.fem.families import get_family\n"
        "assert get_actuator('pneunet').fem_family == 'pneunet'\n"
        "get_family('pneunet').parse('n_chambers=4')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, done.stderr
