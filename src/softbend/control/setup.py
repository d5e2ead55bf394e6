"""One control run's pieces from names: design, rig model, plant, controller and its parameters.

:func:`prepare_control` is what ``softbend control simulate``, ``run`` and
``serve`` share: it checks every name and value first (an unknown controller,
plant or parameter is one line listing the known names), then loads the
controllers' model (default: the shipped FEM-trained MLP, paper B's virtual
angle sensor) and builds the plant's θ(p) and the controller. The controller's
name and parameters come from the caller, else from a rig TOML's
``[controller]`` table (:class:`~softbend.control.rigconfig.ControllerConfig`),
else :data:`~softbend.control.factory.DEFAULT_CONTROLLER` with its defaults;
``--set NAME=VALUE`` text overrides the table's values.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softbend.control.controllers import Controller
from softbend.control.factory import (
    CONTROLLERS,
    DEFAULT_CONTROLLER,
    ControllerModel,
    build_controller,
    controller_parameters,
)
from softbend.control.plants import check_plant, in_table1, plant_table
from softbend.control.rig import AngleTable, RigParams
from softbend.control.rigconfig import ControllerConfig
from softbend.design import SFRBADesign
from softbend.parameters import parse_assignments

__all__ = [
    "DEFAULT_DESIGN",
    "ControlSetup",
    "check_supply",
    "prepare_control",
    "resolve_controller",
]

#: The actuator of paper B's control experiments (l, r, t, b, phi, lc in mm and degrees).
DEFAULT_DESIGN = "100,6,2,2,5,8"

_TOML = "[controller] of the rig config"


@dataclass(frozen=True)
class ControlSetup:
    """What a control run uses, built by :func:`prepare_control`.

    Attributes
    ----------
    design : SFRBADesign
    rig_params : RigParams
        Pneumatics of the simulated rig (and the predictive controller's model).
    plant : str
        Name of the plant (:data:`~softbend.control.plants.PLANTS`).
    plant_table : AngleTable
        θ(p) of the simulated actuator, degrees.
    model : ControllerModel
        The controller's θ(p) table and virtual sensor.
    controller_name : str
    controller_params : dict
        Every public parameter of the controller, as used (defaults filled in).
    controller : Controller
    """

    design: SFRBADesign
    rig_params: RigParams
    plant: str
    plant_table: AngleTable
    model: ControllerModel = field(repr=False)
    controller_name: str
    controller_params: dict[str, Any]
    controller: Controller = field(repr=False)

    def record(self) -> dict[str, Any]:
        """The controller, its parameters, the plant and the design, for a run's summary."""
        return {
            "controller": self.controller_name,
            "controller_params": dict(self.controller_params),
            "plant": self.plant,
            "design": str(self.design),
        }


def check_supply(supply_mpa: float, command: str) -> float:
    """A supply pressure that is a positive, plausible gauge pressure (MPa), else ValueError."""
    from softbend.plausibility import RANGES

    high = RANGES["pressure_mpa"].high
    if isinstance(supply_mpa, bool) or not 0.0 < supply_mpa <= high:
        raise ValueError(
            f"The '--supply' of {command} must be a gauge pressure in (0, {high:g}] MPa "
            f"({high:g} MPa bursts any silicone actuator; a value in kPa must be divided by "
            f"1000). Got {supply_mpa!r} instead."
        )
    return float(supply_mpa)


def resolve_controller(
    name: str | None = None,
    assignments: Sequence[str] = (),
    config: ControllerConfig | None = None,
) -> tuple[str, dict[str, Any], dict[str, Any]]:
    """The controller's name, its parameters as used, and those given (with their origin).

    Parameters
    ----------
    name : str, optional
        The controller asked for (``--controller``); default: the ``config``'s, else
        :data:`~softbend.control.factory.DEFAULT_CONTROLLER`.
    assignments : sequence of str
        ``NAME=VALUE`` text (``--set``), parsed by each parameter's kind; it overrides
        the ``config``'s values.
    config : ControllerConfig, optional
        A rig TOML's [controller] table; its parameters apply when it names the same
        controller as ``name`` (or ``name`` is not given); for another controller
        they are left out, with a warning.

    Returns
    -------
    name : str
    params : dict
        Every public parameter (defaults filled in).
    given : dict
        ``{"--set": {...}, "[controller] of the rig config": {...}}``, the values given.

    Raises
    ------
    UnknownNameError
        An unknown controller or parameter; the message lists the known names.
    ParameterValueError
        A ``--set`` value that is not of the parameter's kind.
    """
    chosen = name if name is not None else (config.name if config else DEFAULT_CONTROLLER)
    CONTROLLERS.check(chosen, field="--controller" if name is not None else _TOML)
    texts = parse_assignments(assignments, "--set")
    typed = controller_parameters(chosen, texts, field="--set", from_text=True)
    from_set = {k: typed[k] for k in texts}
    from_toml = config.as_dict() if config is not None and config.name == chosen else {}
    if config is not None and config.name != chosen and config.as_dict():
        warnings.warn(
            f"The {_TOML} sets parameters of {config.name!r}, but --controller is {chosen!r}: "
            f"they are not used ({chosen!r} runs with its defaults and --set).",
            stacklevel=2,
        )
    given = {origin: v for origin, v in (("--set", from_set), (_TOML, from_toml)) if v}
    params = controller_parameters(chosen, {**from_toml, **from_set})
    return chosen, params, given


def prepare_control(
    *,
    controller: str | None = None,
    assignments: Sequence[str] = (),
    config: ControllerConfig | None = None,
    design: str | SFRBADesign = DEFAULT_DESIGN,
    model: str | Path | None = None,
    plant: str = "surrogate",
    supply_mpa: float = 0.2,
    command: str = "prepare_control",
) -> ControlSetup:
    """Check the names and values of a control run, then build its plant and controller.

    Parameters
    ----------
    controller, assignments, config
        The controller and its parameters (see :func:`resolve_controller`).
    design : str or SFRBADesign
        The actuator, ``"l,r,t,b,phi,lc"`` (mm, degrees).
    model : path, optional
        A saved surrogate for the controller's θ(p) (default: the shipped FEM-trained MLP).
    plant : str
        The actuator's θ(p): a name of :data:`~softbend.control.plants.PLANTS`, or a
        saved surrogate ``.json`` / measurements ``.csv`` of the lab's own actuator
        (:func:`~softbend.control.plants.plant_table`).
    supply_mpa : float, default 0.2
        Supply pressure of the simulated rig, MPa gauge.
    command : str
        The command asking, for messages.

    Raises
    ------
    ValueError
        One line: an unknown controller, parameter or plant (listing the known
        names), a value of the wrong kind or out of range, an implausible supply, a
        design the plant has no data for.
    """
    from softbend.transfer.base import load_base

    name, params, given = resolve_controller(controller, assignments, config)
    check_plant(plant, field="--plant")
    check_supply(supply_mpa, command)
    actuator = design if isinstance(design, SFRBADesign) else SFRBADesign.parse(design)
    rig = RigParams.for_design(actuator, supply_gauge_mpa=supply_mpa)
    if plant == "fem" and not in_table1(actuator):
        # The design's own FEM sweep (solved once, cached) gives its chamber's compliance.
        from softbend.control.fem_plant import fem_curve

        compliance = fem_curve(actuator).compliance_mm3_per_mpa(supply_mpa)
        rig = RigParams.for_design(
            actuator, supply_gauge_mpa=supply_mpa, compliance_mm3_per_mpa=compliance
        )
    surrogate = load_base(model)
    controller_model = ControllerModel.from_surrogate(surrogate, actuator, rig)
    actuator_table = plant_table(plant, actuator, controller_model.angle_table, field="--plant")
    origin = " and ".join(given) or "make_controller"
    built = build_controller(name, controller_model, _flat(given), field=origin)
    return ControlSetup(
        design=actuator,
        rig_params=rig,
        plant=plant,
        plant_table=actuator_table,
        model=controller_model,
        controller_name=name,
        controller_params=params,
        controller=built,
    )


def _flat(given: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """The given values, ``--set`` over the TOML's."""
    merged: dict[str, Any] = {}
    for origin in reversed(list(given)):
        merged.update(given[origin])
    return merged
