"""Every numeric parameter of a controller and every setting of the simulated rig has a range.

The ranges are declared once (``softbend.parameters.declare_ranges``) on the
controller classes and on RigParams; the registered classes, ``--set``,
``--rig-param``, a rig TOML and the constructors all hold values to those
declarations. A value at either end of a range is accepted everywhere and a
short run with it gives finite scores or null ones with a reason.
"""

from __future__ import annotations

import inspect
import math
from dataclasses import fields

import pytest

from softbend.control.controllers import BangBang, ControllerModel, PressurePI, PressureRelay
from softbend.control.experiments import run_metrics, simulate, summary_metrics
from softbend.control.factory import CONTROLLERS, build_controller
from softbend.control.predictive import PneumaticCurves, PredictivePulse
from softbend.control.rig import RIG_RANGES, TUBING_RANGE, RigParams, SimulatedRig
from softbend.control.rigconfig import simulation_settings_entry
from softbend.control.rigs import rig_params_for, rig_settings
from softbend.design import sfrba_design
from softbend.parameters import Range, declared_ranges, public_parameters

BUILT_IN = ("bang-bang", "bang-bang-closed", "pressure-pi", "pressure-relay", "predictive")
#: Parameters without a unit: ratios and weights.
DIMENSIONLESS = {"critical_ratio", "polytropic_exponent", "observer_gain"}
DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)


def _numeric(parameter: inspect.Parameter) -> bool:
    """A parameter whose default or annotation is a number (not a boolean)."""
    default = parameter.default
    if isinstance(default, bool):
        return False
    if isinstance(default, int | float):
        return True
    note = str(parameter.annotation)
    return any(word in note for word in ("float", "int"))


def undeclared(entry, *, keyword_only: bool = True) -> list[str]:
    """The numeric public parameters of ``entry`` without a declared Range."""
    known, _ = public_parameters(entry, keyword_only=keyword_only)
    ranges = declared_ranges(entry)
    return [name for name, p in known.items() if _numeric(p) and name not in ranges]


def test_every_numeric_controller_parameter_has_a_declared_range():
    names = [n for n, f in CONTROLLERS.items() if f.__module__.startswith("softbend.")]
    assert set(BUILT_IN) <= set(names)
    for name in names:
        assert undeclared(CONTROLLERS.get(name)) == [], name


def test_every_rig_setting_has_a_declared_range():
    assert undeclared(simulation_settings_entry) == []
    known, _ = public_parameters(simulation_settings_entry)
    assert set(known) == {f.name for f in fields(RigParams)} | {"tubing_mm3"}
    assert undeclared(RigParams, keyword_only=False) == []


def test_a_parameter_without_a_range_is_caught():
    def toy(model, *, gain: float = 1.0, rate: int = 3, name: str = "x", on: bool = True):
        """A factory that declares nothing."""

    assert undeclared(toy) == ["gain", "rate"]


@pytest.mark.parametrize(
    "ranges",
    [declared_ranges(CONTROLLERS.get(n)) for n in BUILT_IN]
    + [declared_ranges(simulation_settings_entry)],
)
def test_each_range_has_its_unit_and_why(ranges):
    for name, declared in ranges.items():
        assert isinstance(declared, Range)
        assert declared.why, name
        assert declared.unit or name in DIMENSIONLESS, name
        assert math.isfinite(declared.low) and math.isfinite(declared.high), name


def test_one_source_of_truth():
    # the registry holds the classes themselves; the rig settings declare RigParams's ranges
    for name, cls in (
        ("bang-bang", BangBang), ("pressure-pi", PressurePI),
        ("pressure-relay", PressureRelay), ("predictive", PredictivePulse),
    ):  # fmt: skip
        assert CONTROLLERS.get(name) is cls
    assert declared_ranges(CONTROLLERS.get("bang-bang-closed")) == declared_ranges(BangBang)
    settings = declared_ranges(simulation_settings_entry)
    assert {k: settings[k] for k in RIG_RANGES} == declared_ranges(RigParams) == RIG_RANGES
    assert settings["tubing_mm3"] == TUBING_RANGE


def _ends(declared: Range, integer: bool = False) -> list[float]:
    """The two ends of a range, or just inside an open end."""
    low = declared.low if declared.low_inclusive else declared.low + 1e-6 * declared.high
    high = declared.high if declared.high_inclusive else declared.high * (1 - 1e-6)
    return [int(low), int(high)] if integer else [low, high]


def _cases():
    for name in BUILT_IN:
        for key, declared in declared_ranges(CONTROLLERS.get(name)).items():
            for value in _ends(declared):
                yield pytest.param(name, key, value, id=f"{name}-{key}={value:g}")


@pytest.mark.parametrize(("name", "key", "value"), list(_cases()))
def test_each_end_of_a_controller_range_is_accepted_and_runs(table, name, key, value):
    model = ControllerModel(table, table, RigParams())
    controller = build_controller(name, model, {key: value})
    run = simulate(SimulatedRig(table, RigParams(), seed=0), controller, "step:90:0.1", 0.4)
    _finite_or_explained(run)


def _rig_cases():
    for key, declared in declared_ranges(simulation_settings_entry).items():
        for value in _ends(declared, integer=key == "sensor_bits"):
            yield pytest.param(key, value, id=f"{key}={value:g}")


@pytest.mark.parametrize(("key", "value"), list(_rig_cases()))
def test_each_end_of_a_rig_range_is_accepted_and_runs(table, key, value):
    assert rig_settings(values={key: value}) == {key: value}
    params = rig_params_for(DESIGN, {key: value})
    duration = 0.05 if key == "step_s" else 0.4  # 1e-5 s steps: 5000 of them
    run = simulate(SimulatedRig(table, params, seed=0), BangBang(table), "step:90:0.01", duration)
    _finite_or_explained(run)


def _finite_or_explained(run):
    reasons: dict[str, str] = {}
    values, undefined = summary_metrics(run_metrics(run, reasons=reasons), reasons)
    for name, value in values.items():
        if value is None:
            assert undefined[name] and "\n" not in undefined[name], name
        else:
            assert math.isfinite(value), name


@pytest.mark.parametrize(
    "changes",
    [
        {"inlet_conductance_m3_s_pa": 1e-12, "outlet_conductance_m3_s_pa": 1e-12,
         "volume_mm3": 1e8, "compliance_mm3_per_mpa": 1e9},
        {"inlet_conductance_m3_s_pa": 1e-7, "outlet_conductance_m3_s_pa": 1e-7,
         "volume_mm3": 1.0, "compliance_mm3_per_mpa": 0.0},
        {"supply_gauge_mpa": 2.0, "critical_ratio": 0.95, "polytropic_exponent": 1.4},
    ],
)  # fmt: skip
def test_the_predictive_model_is_finite_and_quick_at_the_ends(table, changes):
    import time

    params = RigParams(**changes)
    start = time.perf_counter()
    curves = PneumaticCurves(params)
    assert time.perf_counter() - start < 5.0
    for series in (curves.fill_t, curves.fill_p, curves.vent_t, curves.vent_p):
        assert len(series) >= 2 and all(math.isfinite(v) for v in series)
    controller = PredictivePulse(table, params)
    run = simulate(SimulatedRig(table, params, seed=0), controller, "step:90:0.1", 0.3)
    _finite_or_explained(run)
