"""The penalty contact of :mod:`softbend.fem.contact`: the patch test and bad input."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import softbend._torch  # noqa: F401  (PyTorch before NGSolve)
from softbend.errors import InputError
from softbend.fem.options import FEMOptions

#: Block side and height, mm; the penalty's options as a PneuNet sweep takes them.
SIDE, HEIGHT = 4.0, 2.0
OPTIONS = FEMOptions(contact="on")


@functools.cache
def _block_mesh():
    """The mesh of two blocks stacked face to face (not fused), faces named (see ``_blocks``)."""
    import ngsolve as ngs
    from netgen.occ import Box, Compound, OCCGeometry, Pnt

    lower = Box(Pnt(0, 0, 0), Pnt(SIDE, SIDE, HEIGHT))
    upper = Box(Pnt(0, 0, HEIGHT), Pnt(SIDE, SIDE, 2 * HEIGHT))
    for box, interface in ((lower, "lower_top"), (upper, "upper_bottom")):
        for face in box.faces:
            c = face.center
            if abs(c.z) < 1e-9:
                face.name = "fixed"
            elif abs(c.z - 2 * HEIGHT) < 1e-9:
                face.name = "load"
            elif abs(c.z - HEIGHT) < 1e-9:
                face.name = interface
            elif abs(c.x) < 1e-9 or abs(c.x - SIDE) < 1e-9:
                face.name = "roller_x"
            else:
                face.name = "roller_y"
    mesh = ngs.Mesh(OCCGeometry(Compound([lower, upper])).GenerateMesh(maxh=1.0))
    mesh.Curve(2)
    return mesh


def _blocks():
    """Two Elastosil-like blocks stacked face to face (not fused), their space and energy.

    The lower block stands on ``fixed`` (``u_z = 0``); every side face is a
    roller (no normal displacement), so both blocks are in uniaxial strain and
    the upper one is held only by the contact. The pressure ``p`` pushes down
    on ``load`` (the top).
    """
    import ngsolve as ngs

    from softbend.fem.mechanics import solid_energy
    from softbend.materials.models import NeoHookean

    mesh = _block_mesh()
    fes = ngs.VectorH1(
        mesh, order=2, dirichletx="roller_x", dirichlety="roller_y", dirichletz="fixed"
    )
    u = fes.TrialFunction()
    pressure = ngs.Parameter(0.0)
    form = ngs.BilinearForm(fes, symmetric=True, symmetric_storage=True)
    F = ngs.Id(3) + ngs.Grad(u)
    form += ngs.Variation(solid_energy(F, NeoHookean(c10_mpa=0.1), 20.0) * ngs.dx)
    normal = ngs.specialcf.normal(3)
    form += ngs.Variation(pressure * ngs.InnerProduct(u.Trace(), normal) * ngs.ds("load"))
    return mesh, fes, form, pressure


def _mean_uz(mesh, gfu, face: str) -> float:
    import ngsolve as ngs

    region = mesh.Boundaries(face)
    area = ngs.Integrate(ngs.CoefficientFunction(1.0), mesh, definedon=region)
    return float(ngs.Integrate(gfu[2], mesh, definedon=region)) / area


@pytest.fixture(scope="module")
def pressed():
    """The blocks pressed at 10, 30 and 50 kPa through the contact code, one row each."""
    import ngsolve as ngs

    from softbend.fem.contact import PenaltyContact
    from softbend.fem.newton import EnergySolver

    mesh, fes, form, pressure = _blocks()
    k = OPTIONS.contact_penalty_mpa_per_mm
    contact = PenaltyContact(fes, "upper_bottom", "lower_top", penalty_mpa_per_mm=k, maxdist_mm=0.5)
    gfu = ngs.GridFunction(fes)
    solver = EnergySolver(form, gfu, fes.FreeDofs(), rtol=1e-10)
    rows = []
    for p in (0.01, 0.03, 0.05):
        pressure.Set(p)
        contact.update(gfu, form)
        solver.forget_factorization()
        solver.solve(p * SIDE * SIDE)
        force = contact.force_n(gfu)
        depth = _mean_uz(mesh, gfu, "lower_top") - _mean_uz(mesh, gfu, "upper_bottom")
        rows.append((p, force, depth, contact.mean_depth_mm(gfu), contact.energy_mj(gfu)))
    return rows, k


def test_patch_the_contact_transmits_the_applied_pressure_within_one_percent(pressed):
    rows, _ = pressed
    for p, force, _, _, _ in rows:
        assert force[2] / SIDE**2 == pytest.approx(p, rel=0.01)
        assert abs(force[0]) + abs(force[1]) < 0.01 * p * SIDE**2  # no shear: frictionless


def test_patch_interpenetration_is_pressure_over_penalty_and_within_the_tolerance(pressed):
    rows, k = pressed
    for p, _, depth, mean_depth, energy in rows:
        assert depth == pytest.approx(p / k, rel=0.01)
        assert mean_depth == pytest.approx(p / k, rel=0.01)
        assert 0.0 < depth <= OPTIONS.contact_tolerance_mm
        # Energy of the penalty: ½ k d² over the face.
        assert energy == pytest.approx(0.5 * k * depth**2 * SIDE**2, rel=0.02)


def test_a_stiffer_penalty_overlaps_less_and_transmits_the_same():
    import ngsolve as ngs

    from softbend.fem.contact import PenaltyContact
    from softbend.fem.newton import EnergySolver

    _, fes, form, pressure = _blocks()
    contact = PenaltyContact(
        fes, "upper_bottom", "lower_top", penalty_mpa_per_mm=500.0, maxdist_mm=0.5
    )
    gfu = ngs.GridFunction(fes)
    pressure.Set(0.05)
    contact.update(gfu, form)
    EnergySolver(form, gfu, fes.FreeDofs(), rtol=1e-10).solve(0.05 * SIDE**2)
    assert contact.force_n(gfu)[2] == pytest.approx(0.05 * SIDE**2, rel=0.01)
    # Ten times stiffer: ten times less overlap (the rollers make the pressure
    # a little uneven near the edges, which the mean weights in).
    assert contact.mean_depth_mm(gfu) == pytest.approx(0.05 / 500.0, rel=0.03)


def test_faces_the_mesh_lacks_are_refused_by_name():
    from softbend.fem.contact import PenaltyContact

    _, fes, _, _ = _blocks()
    with pytest.raises(InputError, match=r"minion.*upper_bottom"):
        PenaltyContact(fes, "upper_bottom", "nowhere", penalty_mpa_per_mm=50.0, maxdist_mm=1.0)


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"contact": "yes"}, "contact"),
        ({"contact_penalty_mpa_per_mm": 0.0}, "contact_penalty_mpa_per_mm"),
        ({"contact_tolerance_mm": -1.0}, "contact_tolerance_mm"),
    ],
)
def test_bad_contact_options_are_refused_by_name(change, key):
    with pytest.raises(InputError, match=key):
        FEMOptions(**change)


def test_options_without_contact_digest_as_before_contact_existed():
    plain = FEMOptions()
    assert "contact" not in plain.to_dict()
    assert plain.replace(contact_penalty_mpa_per_mm=10.0).digest() == plain.digest()
    on = plain.replace(contact="on")
    assert on.to_dict()["contact_penalty_mpa_per_mm"] == 50.0
    assert on.digest() != plain.digest()
    assert np.isfinite(on.contact_tolerance_mm)


@pytest.mark.parametrize("turn_deg", [0.0, 60.0, 120.0])
@pytest.mark.parametrize("opening_mm", [-0.01, 0.1])
def test_penalty_energy_is_the_same_after_a_rigid_rotation(turn_deg, opening_mm):
    """The overlap is measured along the deformed normal, so a rigid turn changes nothing.

    The upper block is moved ``opening_mm`` off the lower one (negative: into
    it) and both are turned by ``turn_deg`` about y. Along the undeformed normal
    an opening of 0.1 mm turned past 90° would read as an overlap of
    ``0.1 |cos θ|`` mm.
    """
    import math

    import ngsolve as ngs

    from softbend.fem.contact import PenaltyContact

    _, fes, form, _ = _blocks()
    k = OPTIONS.contact_penalty_mpa_per_mm
    contact = PenaltyContact(fes, "upper_bottom", "lower_top", penalty_mpa_per_mm=k, maxdist_mm=0.5)
    theta = math.radians(turn_deg)
    c, s = math.cos(theta), math.sin(theta)
    lift = ngs.IfPos(ngs.z - HEIGHT, opening_mm, 0.0)  # the upper block only
    x, z = ngs.x, ngs.z + lift
    gfu = ngs.GridFunction(fes)
    # Set per block: the displacement jumps across the interface (two blocks, not fused).
    gfu.Set(ngs.CF((c * x + s * z - ngs.x, 0.0, -s * x + c * z - ngs.z)))
    contact.update(gfu, form)
    expected = 0.5 * k * opening_mm**2 * SIDE**2 if opening_mm < 0 else 0.0
    assert contact.energy_mj(gfu) == pytest.approx(expected, rel=0.02, abs=1e-9)
