"""One control run's pieces from names: design, rig model, plant, controller and its parameters.

:func:`prepare_control` is what ``softbend control simulate``, ``run`` and
``serve`` share: it checks every name and value first (an unknown controller,
plant or parameter is one line listing the known names), then loads the
controllers' model (default: the shipped FEM-trained MLP, paper B's virtual
angle sensor) and builds the plant's θ(p) and the controller. The controller's
name and parameters come from the caller, else from a rig TOML's
``[controller]`` table (:class:`~softbend.control.rigconfig.ControllerConfig`),
else :data:`~softbend.control.factory.DEFAULT_CONTROLLER` with its defaults;
``--set NAME=VALUE`` text overrides the table's values. The simulated rig's
parameters are :class:`~softbend.control.rig.RigParams` of the design with the
settings of :func:`~softbend.control.rigs.rig_settings` applied.
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
    "beyond_support",
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
    supported_mpa : float or None
        The largest pressure the controller's model (and a plant surrogate) were
        trained to near the design, MPa; None when they record no support.
    support_notes : list of str
        Where their θ(p) up to the supply leaves the training data.
    rig_settings : dict
        The settings of the simulated rig given (:func:`~softbend.control.rigs.rig_settings`);
        ``rig_params`` holds them all, defaults filled in.
    """

    design: SFRBADesign
    rig_params: RigParams
    plant: str
    plant_table: AngleTable
    model: ControllerModel = field(repr=False)
    controller_name: str
    controller_params: dict[str, Any]
    controller: Controller = field(repr=False)
    supported_mpa: float | None = None
    support_notes: list[str] = field(default_factory=list)
    rig_settings: dict[str, Any] = field(default_factory=dict)

    def record(self) -> dict[str, Any]:
        """The controller, its parameters, the plant and the design, for a run's summary."""
        return {
            "controller": self.controller_name,
            "controller_params": dict(self.controller_params),
            "plant": self.plant,
            "design": str(self.design),
        }


def check_supply(supply_mpa: float, command: str, field: str = "--supply") -> float:
    """A supply pressure that is a positive, plausible gauge pressure (MPa), else ValueError.

    ``field`` names the option (or setting) that gave it, for the message.
    """
    from softbend.plausibility import RANGES

    high = RANGES["pressure_mpa"].high
    if isinstance(supply_mpa, bool) or not 0.0 < supply_mpa <= high:
        raise ValueError(
            f"The '{field}' of {command} must be a gauge pressure in (0, {high:g}] MPa "
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
    strict: bool = False,
    rig_settings: Mapping[str, Any] | None = None,
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
        Supply pressure of the simulated rig, MPa gauge (``supply_gauge_mpa`` of
        ``rig_settings``, when given, replaces it: :func:`~softbend.control.rigs.rig_settings`
        refuses the two when they differ).
    command : str
        The command asking, for messages.
    strict : bool, default False
        Refuse a controller model or plant surrogate whose θ(p) of the design up
        to the supply leaves its training data's support
        (:func:`~softbend.control.plants.support_warnings`), instead of warning.
    rig_settings : mapping, optional
        Parameters of the simulated rig, ``{name: value}``: fields of
        :class:`~softbend.control.rig.RigParams` and ``tubing_mm3``, checked by
        :func:`~softbend.control.rigs.rig_settings`; the others keep their defaults
        and the chamber volume follows the design.

    Raises
    ------
    ValueError
        One line: an unknown controller, parameter or plant (listing the known
        names), a value of the wrong kind or out of range, an implausible supply, a
        design the plant has no data for; with ``strict``, a model used beyond its
        training data.
    """
    from softbend.control.rigs import rig_params_for
    from softbend.control.rigs import rig_settings as check_rig_settings
    from softbend.transfer.base import load_base_saved

    name, params, given = resolve_controller(controller, assignments, config)
    check_plant(plant, field="--plant")
    settings = check_rig_settings(values=rig_settings, table_field=f"rig_settings of {command}")
    supply_field = "--supply" if "supply_gauge_mpa" not in settings else "supply_gauge_mpa"
    supply_mpa = settings.get("supply_gauge_mpa", supply_mpa)
    check_supply(supply_mpa, command, supply_field)
    chosen = {**settings, "supply_gauge_mpa": supply_mpa}
    actuator = design if isinstance(design, SFRBADesign) else SFRBADesign.parse(design)
    rig = rig_params_for(actuator, chosen)
    if plant == "fem" and not in_table1(actuator):
        # The design's own FEM sweep (solved once, cached) gives its chamber's compliance.
        from softbend.control.fem_plant import fem_curve

        compliance = fem_curve(actuator).compliance_mm3_per_mpa(supply_mpa)
        rig = rig_params_for(actuator, chosen, compliance_mm3_per_mpa=compliance)
    saved = load_base_saved(model)
    surrogate = saved.model
    supported, notes = _support_check(saved, model, plant, actuator, supply_mpa, strict)
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
        supported_mpa=supported,
        support_notes=notes,
        rig_settings=dict(settings),
    )


def _support_check(
    saved: Any,
    model: str | Path | None,
    plant: str,
    design: SFRBADesign,
    supply_mpa: float,
    strict: bool,
) -> tuple[float | None, list[str]]:
    """The lowest supported pressure of the model and a plant surrogate, and the notes
    on where θ(p) up to the supply leaves their data; with ``strict`` any note refuses.

    A note on angles warns at once; one on pressure waits for the run, which may
    never reach it (:func:`beyond_support`).
    """
    from softbend.control.plants import plant_file, support_warnings
    from softbend.surrogates.persistence import load_surrogate

    role = f"the controller's model ({model or 'the shipped MLP'})"
    limits, notes = [], []
    for one, who in [(saved, role)] + [
        (load_surrogate(path), f"the plant ({path})")
        for path in [plant_file(plant)]
        if path is not None and path.suffix.lower() == ".json"
    ]:
        limit, pressure_note, angle_note = support_warnings(one, design, supply_mpa, role=who)
        limits += [limit] if limit is not None else []
        notes += [n for n in (pressure_note, angle_note) if n is not None]
        if angle_note is not None and not strict:
            warnings.warn(f"{angle_note}.", UserWarning, stacklevel=3)
    if strict and notes:
        raise ValueError(f"The model must hold up to the supply (--strict): {'; '.join(notes)}.")
    return (min(limits) if limits else None), notes


def beyond_support(setup: ControlSetup, max_pressure_mpa: float) -> str | None:
    """One line when a run reached past the pressure its models were trained to, else None."""
    limit = setup.supported_mpa
    if limit is None or not max_pressure_mpa > limit * (1 + 1e-9):
        return None
    return (
        f"The run reached {max_pressure_mpa:.3g} MPa, past the {limit:.3g} MPa the models "
        f"were trained to near the design {setup.design}: the angles above it are "
        "extrapolated (--strict refuses such a run)."
    )


def _flat(given: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """The given values, ``--set`` over the TOML's."""
    merged: dict[str, Any] = {}
    for origin in reversed(list(given)):
        merged.update(given[origin])
    return merged
