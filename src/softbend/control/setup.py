"""One control run's pieces from names: design, rig model, plant, controller and its parameters.

:func:`prepare_control` is what ``softbend control simulate``, ``run`` and
``serve`` share: it checks every name and value first (an unknown controller,
plant or parameter is one line listing the known names), then loads the
controllers' model and builds the plant's θ(p) and the controller. The
controllers' model (their θ(p) and paper B's virtual angle sensor) is
``model`` when given; else the plant when the plant is a saved surrogate (the
lab's refined model serves as its own soft sensor, as in paper B); else the
shipped FEM-trained MLP. A model of any actuator may be used: the design is
parsed by the model's actuator description
(:func:`~softbend.control.designs.control_design`) and its pressures converted
from the rig's MPa to the model's unit. The controller's
name and parameters come from the caller, else from a rig TOML's
``[controller]`` table (:class:`~softbend.control.rigconfig.ControllerConfig`),
else :data:`~softbend.control.factory.DEFAULT_CONTROLLER` with its defaults;
``--set NAME=VALUE`` text overrides the table's values. The simulated rig's
parameters are :class:`~softbend.control.rig.RigParams` of the design with the
settings of :func:`~softbend.control.rigs.rig_settings` applied
(:func:`~softbend.control.rigs.rig_params_for`).

The plant is parsed once (:func:`~softbend.control.plants.parse_plant`); what is
one actuator's alone (paper B's FEM, virtual lab and measurement files, the FEM's
chamber compliance, the 0–0.5 MPa span of paper B's tables) is data
(:data:`~softbend.control.plants.PLANT_ACTUATORS`,
:data:`~softbend.control.plants.PLANT_COMPLIANCES`, :data:`TABLE_SPAN_MPA`).

A model of ``softbend identify`` may play the plant
(:mod:`~softbend.control.identified_plant`): its dynamics replace the rig's
θ(p) and angle lag. Without ``model`` it is also the controllers' model (its
steady-state θ(p)); such a plant has no design, so ``design`` is refused, and
the rig's chamber is that of paper B's default design unless ``volume_mm3`` is
set.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.actuators import SFRBA, Actuator, Design
from softbend.control.controllers import Controller, ControllerModel
from softbend.control.designs import DEFAULT_DESIGN, actuator_of_design, control_design
from softbend.control.factory import CONTROLLERS, DEFAULT_CONTROLLER, controller_parameters
from softbend.control.plant_choice import PlantChoice
from softbend.control.plants import check_plant_actuator, parse_plant, plant_compliance, plant_table
from softbend.control.rig import AngleTable, RigParams
from softbend.control.rigconfig import ControllerConfig
from softbend.design import parse_sfrba
from softbend.errors import InputError, keyed
from softbend.parameters import effective_parameters, parse_assignments

if TYPE_CHECKING:
    from softbend.control.identified_plant import IdentifiedPlant
    from softbend.control.rig import AngleDynamics
    from softbend.surrogates.persistence import SavedSurrogate

__all__ = [
    "DEFAULT_DESIGN",
    "TABLE_SPAN_MPA",
    "ControlSetup",
    "beyond_support",
    "check_supply",
    "model_of_run",
    "prepare_control",
    "resolve_controller",
]


#: The top pressure of the θ(p) tables of a run, MPa, by actuator: paper B's span
#: 0–0.5 MPa as its figures always did; another actuator's, 0 to the supply.
TABLE_SPAN_MPA: dict[str, float] = {SFRBA.name: 0.5}


@dataclass(frozen=True)
class ControlSetup:
    """What a control run uses, built by :func:`prepare_control`.

    Attributes
    ----------
    design : Design
        Paper B's design, or a design of the actuator of the controller's model.
    rig_params : RigParams
        Pneumatics of the simulated rig (and the predictive controller's model).
    plant : str
        Name of the plant (:data:`~softbend.control.plants.PLANTS`) or its file, as given.
    plant_table : AngleTable
        θ(p) of the simulated actuator, degrees (pressures in MPa gauge).
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
        Where the design leaves the training ranges of the controller's model
        (``design_notes``), and where their θ(p) up to the supply leaves the
        training data.
    rig_settings : dict
        The settings of the simulated rig given (:func:`~softbend.control.rigs.rig_settings`);
        ``rig_params`` holds them all, defaults filled in.
    model_path : str
        The file of the controller's model (the shipped MLP's when none was given).
    model_from : {"model", "plant", "shipped"}
        Where it came from: the ``model`` given, the plant (a saved surrogate), or
        the shipped FEM-trained MLP.
    actuator : Actuator
        The description of the controller's model (paper B's, or the model's own).
    design_notes : list of str
        Where the design leaves the training ranges of the controller's model.
    design_outside : list of str
        The parameters of the design outside those ranges, one phrase each
        (``"l_mm 8 outside [100, 160]"``).
    identified : IdentifiedPlant, optional
        The identified dynamic model that plays the actuator (``plant`` its file);
        ``plant_table`` is then its steady-state θ(p) and :meth:`plant_dynamics`
        its dynamics.
    choice : PlantChoice, optional
        ``plant`` as parsed (:attr:`plant_choice` parses it when not given).
    """

    design: Design
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
    model_path: str = ""
    model_from: str = "shipped"
    actuator: Actuator = SFRBA
    design_notes: list[str] = field(default_factory=list)
    design_outside: list[str] = field(default_factory=list)
    identified: IdentifiedPlant | None = field(default=None, repr=False)
    choice: PlantChoice | None = field(default=None, repr=False)

    @property
    def plant_choice(self) -> PlantChoice:
        """The plant as parsed (:func:`~softbend.control.plants.parse_plant`)."""
        return self.choice if self.choice is not None else parse_plant(self.plant)

    def plant_dynamics(self) -> AngleDynamics | None:
        """A fresh dynamic model of the plant's angle for a rig, else None (θ(p) and a lag)."""
        return None if self.identified is None else self.identified.dynamics()

    @property
    def has_design(self) -> bool:
        """Whether the run has a design (not so for an identified plant without --model)."""
        return not (self.identified is not None and self.model_from == "plant")

    @property
    def design_supported(self) -> bool | None:
        """Whether the design lies in the training ranges of the controller's model
        (None when the run has no design)."""
        return not self.design_outside if self.has_design else None

    def design_support_text(self) -> str | None:
        """``"yes"`` or ``"no (l_mm 8 outside [100, 160])"``; None without a design."""
        supported = self.design_supported
        if supported is None:
            return None
        return "yes" if supported else f"no ({'; '.join(self.design_outside)})"

    @property
    def mismatch(self) -> bool:
        """Whether the plant is a saved model other than the controller's model."""
        return self.plant_choice.model_file is not None and not self.plant_is_model

    @property
    def plant_is_model(self) -> bool:
        """Whether the plant is the controller's model itself (``surrogate``, or its file)."""
        choice = self.plant_choice
        path = choice.model_file
        return (choice.kind, choice.text) == ("named", "surrogate") or (
            path is not None and _same_file(path, Path(self.model_path))
        )

    def record(self) -> dict[str, Any]:
        """The controller, its parameters, the plant, the controller's model and the design,
        for a run's summary (another actuator's design also by name, with its actuator)."""
        out: dict[str, Any] = {
            "controller": self.controller_name,
            "controller_params": dict(self.controller_params),
            "plant": self.plant,
            "model": self.model_path,
            "model_from": self.model_from,
            "design": str(self.design) if self.has_design else None,
            "design_supported": self.design_supported,
            "design_outside": list(self.design_outside),
        }
        if self.identified is not None:
            out["plant_description"] = self.identified.describe()
        if self.design.actuator.named_in_outputs:  # paper B's runs record as they always did
            out["actuator"] = self.actuator.name
            out["design_parameters"] = self.design.record()
            out["model_pressure_unit"] = self.actuator.pressure_unit
        return out


def check_supply(supply_mpa: float, given: str | None = None) -> float:
    """A supply pressure that is a positive, plausible gauge pressure (MPa), else InputError.

    ``given``, when the value was typed otherwise (``"20 psi (0.138 MPa)"``), is what the
    message says was got.
    """
    from softbend._validation import must_be
    from softbend.plausibility import RANGES

    high = RANGES["pressure_mpa"].high
    if isinstance(supply_mpa, bool) or not 0.0 < supply_mpa <= high:
        requirement = (
            f"a gauge pressure in (0, {high:g}] MPa ({high:g} MPa bursts any silicone "
            "actuator; a value in another unit takes its suffix, e.g. 200kPa)"
        )
        if given is not None:
            raise InputError(f"must be {requirement}; got {given}", key="supply_mpa")
        raise InputError(must_be(requirement, supply_mpa), key="supply_mpa")
    return float(supply_mpa)


def resolve_controller(
    controller: str | None = None,
    assignments: Sequence[str] = (),
    config: ControllerConfig | None = None,
) -> tuple[str, dict[str, Any]]:
    """The controller's name and its parameters as used.

    Parameters
    ----------
    controller : str, optional
        The controller asked for; default: the ``config``'s, else
        :data:`~softbend.control.factory.DEFAULT_CONTROLLER`.
    assignments : sequence of str
        ``NAME=VALUE`` text of its parameters, parsed by each parameter's kind
        and checked; it overrides the ``config``'s values.
    config : ControllerConfig, optional
        A rig TOML's [controller] table (checked when it was read); its
        parameters apply when it names the same controller as ``controller`` (or
        ``controller`` is not given); for another controller they are left out,
        with a warning.

    Returns
    -------
    name : str
    params : dict
        Every public parameter: the value given (``assignments`` over the
        ``config``'s), else its default.

    Raises
    ------
    UnknownNameError
        An unknown controller or parameter; the message lists the known names.
    ParameterValueError
        An ``assignments`` value that is not of the parameter's kind or out of its range.
    """
    chosen = controller if controller is not None else (config.name if config else None)
    chosen = DEFAULT_CONTROLLER if chosen is None else chosen
    with keyed("controller"):
        entry = CONTROLLERS.get(chosen)
    with keyed("assignments"):
        texts = parse_assignments(assignments)
    with keyed("assignments"):
        typed = controller_parameters(chosen, texts, from_text=True)
    from_set = {k: typed[k] for k in texts}
    from_toml = config.as_dict() if config is not None and config.name == chosen else {}
    if config is not None and config.name != chosen and config.as_dict():
        warnings.warn(
            f"The [controller] of the rig config sets parameters of {config.name!r}, but "
            f"--controller is {chosen!r}: they are not used ({chosen!r} runs with its "
            "defaults and --set).",
            stacklevel=2,
        )
    return chosen, effective_parameters(entry, {**from_toml, **from_set})


def model_of_run(model: str | Path | None, plant: str | PlantChoice) -> tuple[Path | None, str]:
    """The file of the controllers' model of a run, and where it came from.

    ``model`` when given (``"model"``); else the plant when it is a saved
    model (``"plant"``: the model that plays the actuator is its own soft
    sensor, as paper B ran its refined model); else None, the shipped
    FEM-trained MLP (``"shipped"``).
    """
    if model is not None:
        return Path(model), "model"
    path = parse_plant(plant).model_file
    return (path, "plant") if path is not None else (None, "shipped")


def prepare_control(
    *,
    controller: str | None = None,
    assignments: Sequence[str] = (),
    config: ControllerConfig | None = None,
    design: str | Design | None = None,
    model: str | Path | None = None,
    plant: str | PlantChoice = "surrogate",
    supply_mpa: float = 0.2,
    strict: bool = False,
    rig_settings: Mapping[str, Any] | None = None,
    simulated: bool = True,
) -> ControlSetup:
    """Check the names and values of a control run, then build its plant and controller.

    Parameters
    ----------
    controller, assignments, config
        The controller and its parameters (see :func:`resolve_controller`).
    design : str, Design, optional
        The actuator's design, parsed by the actuator of the controller's model:
        paper B's ``"l,r,t,b,phi,lc"`` (mm, degrees; default
        :data:`~softbend.control.designs.DEFAULT_DESIGN`), or ``"A=1,B=2,..."``
        by another actuator's parameter names, in its units (required then).
    model : path, optional
        A saved surrogate for the controller's θ(p) and virtual sensor, of any
        actuator. Default: the plant, when the plant is a saved surrogate; else
        the shipped FEM-trained MLP.
    plant : str or PlantChoice
        The actuator's θ(p): a name of :data:`~softbend.control.plants.PLANTS`, or a
        saved surrogate ``.json`` / measurements ``.csv`` of the lab's own actuator
        (:func:`~softbend.control.plants.plant_table`), or a model of ``softbend
        identify`` (``.json``) whose dynamics play the actuator (one pressure input,
        an angle output, a known time unit; else an InputError keyed ``plant``),
        parsed once (:func:`~softbend.control.plants.parse_plant`). A
        saved surrogate and ``model`` must describe the same design parameters
        (their pressure units may differ).
    supply_mpa : float, default 0.2
        Supply pressure of the simulated rig, MPa gauge (``supply_gauge_mpa`` of
        ``rig_settings``, when given, replaces it: :func:`~softbend.control.rigs.rig_settings`
        refuses the two when they differ).
    strict : bool, default False
        Refuse a design outside the training ranges of the controller's model,
        and a controller model or plant surrogate whose θ(p) of the design up
        to the supply leaves its training data's support
        (:func:`~softbend.control.plants.support_warnings`), instead of warning.
    rig_settings : mapping, optional
        Parameters of the simulated rig, ``{name: value}``: fields of
        :class:`~softbend.control.rig.RigParams` and ``tubing_mm3``, checked by
        :func:`~softbend.control.rigs.rig_settings`; the others keep their defaults
        and the chamber volume follows the design (another actuator's: its
        description's, else ``volume_mm3`` must be given).
    simulated : bool, default True
        Whether the rig is simulated. On hardware only the ``predictive`` controller
        models the pneumatics: another actuator's chamber is then not required.

    Raises
    ------
    ValueError
        One line: an unknown controller, parameter or plant (listing the known
        names), a value of the wrong kind or out of range, an implausible supply, a
        design the plant has no data for or that is not one of the model's
        actuator, a chamber volume unknown; with ``strict``, a model used beyond
        its training data.
    """
    from softbend.control.rigs import has_cavity, rig_params_for
    from softbend.control.rigs import rig_settings as check_rig_settings
    from softbend.transfer.base import load_base_saved, shipped_base_path

    name, params = resolve_controller(controller, assignments, config)
    with keyed("plant"):
        choice = parse_plant(plant)
    with keyed("rig_settings"):
        settings = check_rig_settings(values=rig_settings)
    if "supply_gauge_mpa" in settings:  # held by rig_settings to the same (0, 2] MPa
        supply_mpa = settings["supply_gauge_mpa"]
    else:
        supply_mpa = check_supply(supply_mpa)
    chosen = {**settings, "supply_gauge_mpa": supply_mpa}
    identified = choice.identified()
    if identified is not None and model is None:
        return _identified_setup(identified, name, params, design, settings, chosen, supply_mpa)
    model_path, model_from = model_of_run(model, choice)
    saved = load_base_saved(model_path)
    label = str(model_path) if model_path is not None else str(shipped_base_path())
    source = "the shipped MLP" if model_path is None else f"the model {model_path}"
    actuator = saved.actuator
    with keyed("design"):
        actuator_design = control_design(design, actuator, source=source)
    plant_path = choice.surrogate_file
    shared = (
        plant_path is not None and model_path is not None and _same_file(plant_path, model_path)
    )
    if plant_path is not None and not shared:
        _check_same_parameters(plant_path, actuator, model_path)
    with keyed("plant"):
        check_plant_actuator(choice, actuator_design)
    if simulated or name == "predictive" or has_cavity(actuator_design):
        # a plant's own chamber (an FEM sweep of the design, solved once) where it gives one
        compliance = plant_compliance(choice, actuator_design, supply_mpa)
        derived = {} if compliance is None else {"compliance_mm3_per_mpa": compliance}
        rig = rig_params_for(actuator_design, chosen, **derived)
    else:  # hardware: its pneumatics are what they are, and no controller models them
        rig = RigParams(**chosen)
    surrogate = saved.model
    design_notes, outside = _design_check(model_path, label, actuator_design, strict)
    supported, notes = _support_check(
        saved, model_path, plant_path, shared, actuator_design, supply_mpa, strict
    )
    pmax = TABLE_SPAN_MPA.get(actuator.name, supply_mpa)
    controller_model = ControllerModel.from_surrogate(
        surrogate, actuator_design, rig, pmax_mpa=pmax
    )
    if identified is None:
        with keyed("plant"):
            actuator_table = plant_table(
                choice, actuator_design, controller_model.angle_table, pmax_mpa=pmax
            )
    else:  # the rig steps its dynamics; its steady state is the plant's θ(p) on record
        actuator_table = identified.angle_table(supply_mpa, check=False)
    built = CONTROLLERS.get(name)(controller_model, **params)  # checked by resolve_controller
    return ControlSetup(
        design=actuator_design,
        rig_params=rig,
        plant=choice.text,
        plant_table=actuator_table,
        model=controller_model,
        controller_name=name,
        controller_params=params,
        controller=built,
        supported_mpa=supported,
        support_notes=[*design_notes, *notes],
        rig_settings=dict(settings),
        model_path=label,
        model_from=model_from,
        actuator=actuator,
        design_notes=design_notes,
        design_outside=outside,
        identified=identified,
        choice=choice,
    )


def _identified_setup(
    identified: IdentifiedPlant,
    name: str,
    params: dict[str, Any],
    design: str | Design | None,
    settings: dict[str, Any],
    chosen: dict[str, Any],
    supply_mpa: float,
) -> ControlSetup:
    """An identified plant that is also the controller's model: its steady-state θ(p).

    Such a plant has no design: a ``design`` is refused (it would be for the
    controller's model of ``--model``). The rig's chamber is paper B's default
    design's unless ``volume_mm3`` is set.
    """
    from softbend.control.rigs import rig_params_for

    if design is not None:
        raise InputError(
            "must not be given with an identified --plant and no --model: the identified "
            f"model {identified.path} is of one actuator, with no design parameters (give "
            "--model, a saved surrogate, for a controller's model of a design)",
            key="design",
        )
    rig = rig_params_for(parse_sfrba(DEFAULT_DESIGN), chosen)
    with keyed("plant"):
        table = identified.angle_table(supply_mpa)
    controller_model = ControllerModel(table, table, rig)
    built = CONTROLLERS.get(name)(controller_model, **params)  # checked by resolve_controller
    return ControlSetup(
        design=parse_sfrba(DEFAULT_DESIGN),
        rig_params=rig,
        plant=str(identified.path),
        plant_table=table,
        model=controller_model,
        controller_name=name,
        controller_params=params,
        controller=built,
        rig_settings=dict(settings),
        model_path=str(identified.path),
        model_from="plant",
        identified=identified,
    )


def _same_file(a: Path, b: Path) -> bool:
    """Whether two paths name the same file."""
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and a.samefile(b))
    except OSError:
        return False


def _check_same_parameters(plant_path: Path, actuator: Actuator, model_path: Path | None) -> None:
    """A plant surrogate must be of an actuator with the controller's model's parameters."""
    from softbend.surrogates.persistence import load_surrogate

    other = load_surrogate(plant_path).actuator
    if other.names != actuator.names:
        raise ValueError(
            f"The plant {plant_path} is a model of the actuator {other.name} "
            f"({', '.join(other.names)}), the controller's model {model_path or 'the shipped MLP'} "
            f"of {actuator.name} ({', '.join(actuator.names)}): a plant and a controller's "
            "model must describe the same design parameters."
        )


def _design_check(
    model_path: Path | None,
    label: str,
    design: Design,
    strict: bool,
) -> tuple[list[str], list[str]]:
    """Where ``design`` leaves the training ranges of the controller's model: a warning
    (naming the model and the parameters), or with ``strict`` a refusal.

    Returns the note (none when the design lies inside) and the phrases, one per
    parameter outside (``"l_mm 8 outside [100, 160]"``)."""
    from softbend.surrogates.predict import predict_angles
    from softbend.transfer.base import shipped_base_path

    path = shipped_base_path() if model_path is None else model_path
    outside = predict_angles(path, design.as_array(), [0.0]).outside_training_ranges
    names = set(actuator_of_design(design).names)
    phrases = [phrase for phrase in outside if phrase.split(" ", 1)[0] in names]
    if not phrases:
        return [], []
    note = (
        f"The design {design} lies outside the training ranges of the controller's model "
        f"{label}: {'; '.join(phrases)}; its θ(p) there is an extrapolation"
    )
    if strict:
        raise ValueError(f"The design must lie in its model's training data (--strict): {note}.")
    warnings.warn(f"{note} (--strict refuses it).", UserWarning, stacklevel=3)
    return [note], phrases


def _support_check(
    saved: SavedSurrogate,
    model: Path | None,
    plant: Path | None,
    shared: bool,
    design: Design,
    supply_mpa: float,
    strict: bool,
) -> tuple[float | None, list[str]]:
    """The lowest supported pressure of the model and a plant surrogate, and the notes
    on where θ(p) up to the supply leaves their data; with ``strict`` any note refuses.

    ``plant`` is the file of a plant surrogate (None when there is none); when it is the
    controller's model (``shared``) it is checked once, named as both. A note on
    angles warns at once; one on pressure waits for the run, which may never reach it
    (:func:`beyond_support`).
    """
    from softbend.control.plants import support_warnings
    from softbend.surrogates.persistence import load_surrogate

    role = (
        f"the plant and controller's model ({model})"
        if shared
        else f"the controller's model ({model or 'the shipped MLP'})"
    )
    limits, notes = [], []
    checked = [(saved, role)]
    if plant is not None and not shared:
        checked.append((load_surrogate(plant), f"the plant ({plant})"))
    for one, who in checked:
        limit, pressure_note, angle_note = support_warnings(one, design, supply_mpa, role=who)
        limits += [limit] if limit is not None else []
        notes += [n for n in (pressure_note, angle_note) if n is not None]
        if angle_note is not None and not strict:
            warnings.warn(f"{angle_note}.", UserWarning, stacklevel=3)
    if strict and notes:
        raise ValueError(f"The model must hold up to the supply (--strict): {'; '.join(notes)}.")
    return (min(limits) if limits else None), notes


def beyond_support(setup: ControlSetup, max_pressure_mpa: float) -> str | None:
    """One line when a run reached past the pressure its models were trained to, else None.

    The pressures are in MPa for paper B's actuator, in the model's unit for another.
    """
    limit = setup.supported_mpa
    if limit is None or not max_pressure_mpa > limit * (1 + 1e-9):
        return None
    actuator = actuator_of_design(setup.design)
    scale, unit = 1.0 / actuator.to_mpa, actuator.pressure_unit  # from MPa to the model's unit
    reached = f"{max_pressure_mpa * scale:.3g} {unit}"
    trained = f"{limit * scale:.3g} {unit}"
    return (
        f"The run reached {reached}, past the {trained} the models "
        f"were trained to near the design {setup.design}: the angles above it are "
        "extrapolated (--strict refuses such a run)."
    )
