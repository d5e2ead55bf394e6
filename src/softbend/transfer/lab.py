"""A virtual lab: labelled-synthetic measurements of real-looking actuators (paper B §4.2–4.3).

Paper B's measurements are not public. The virtual lab produces measurements
of the seven actuators of paper B Fig. 7 the way their rig did (pressure set
from 0 in 0.01 MPa increments, each reading at a stable state, the angle read
from a camera), with a *reality gap* between the lab and the simulations the
surrogates were trained on:

* **Elastomer.** The lab's silicone is the shipped Dragon Skin 30 tensile test
  (:func:`softbend.materials.load_shipped`) with its own Yeoh fit over the
  working range (stretch <= 3 by default), not paper B's constants. It is softer
  than paper B's fit at small strains and stiffer at large ones, so a
  simulation-trained model drifts as the pressure rises, as paper B saw.
* **Fabrication.** Each actuator's wall ``t`` and bottom layer ``b`` are off
  nominal by a seeded uniform error (default +/-0.2 mm); the file records the
  nominal design, as a lab would.
* **Hysteresis.** Rate-independent: the loading branch lies below the elastic
  curve and the unloading branch above it by ``h·4s(1 - s)`` of the angle,
  ``s = p/p_top``; the branches meet at 0 and at the top pressure and differ by
  at most ``2h`` (default h = 0.02: 4 %, paper B measured < 5 %).
* **Camera.** Gaussian reading noise (default 1°).

The elastic curve is the finite-element model of the actuator as built (or,
for fast checks, the analytical model). Every file the lab writes says that it
is synthetic and lists the gap's parameters in its header.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from softbend._validation import check_choice, check_int, check_range, must_be
from softbend.actuators import Design
from softbend.design import PAPER_B_FIG7_DESIGNS, PARAMETERS, sfrba_design
from softbend.errors import ConvergenceError, InputError, keyed
from softbend.limits import check_limit
from softbend.materials.fit import fit_model
from softbend.materials.models import Yeoh
from softbend.materials.presets import DRAGON_SKIN_30, Material
from softbend.materials.tensile import load_shipped, shipped_tensile_tests
from softbend.models import BendingModel, default_pressures_mpa
from softbend.parameters import Range
from softbend.references import FEM_VALIDATION
from softbend.registry import Registry
from softbend.transfer.measurements import Measurements

__all__ = [
    "LAB_ACTUATORS",
    "LAB_MODELS",
    "VirtualLab",
    "actuator_id",
    "shipped_measurements",
    "shipped_measurements_path",
]

#: The seven actuators of paper B Fig. 7 (:data:`softbend.design.PAPER_B_FIG7_DESIGNS`).
LAB_ACTUATORS: tuple[Design, ...] = PAPER_B_FIG7_DESIGNS


def _fem_model(elastomer: Material) -> BendingModel:
    from softbend.fem import FEMModel, FEMOptions

    return FEMModel(FEMOptions(elastomer=elastomer))


def _analytical_model(elastomer: Material) -> BendingModel:
    from softbend.analytical import AnalyticalModel

    return AnalyticalModel(material=elastomer)


#: Bending models that can play the lab's actuators: ``factory(elastomer) -> BendingModel``.
#: The lab's ``plant`` setting (``softbend lab measure --plant``) names one.
LAB_MODELS: Registry[Callable[[Material], BendingModel]] = Registry("lab model")
LAB_MODELS.register("fem", _fem_model)
LAB_MODELS.register("analytical", _analytical_model)


def actuator_id(design: Design) -> str:
    """The design as ``"l,r,t,b,phi,lc"`` with ``%g`` numbers, e.g. ``"100,6,2,2,5,8"``."""
    return ",".join(f"{getattr(design, name):g}" for name in PARAMETERS)


#: CSV column of each design parameter (the measurement files' names).
_COLUMNS = dict(zip(PARAMETERS, ("l", "r", "t", "b", "phi", "lc"), strict=True))

#: The range of each numeric setting.
_BOUNDS: dict[str, Range] = {
    "elastomer_max_stretch": Range(1.0, 50.0, low_inclusive=False, high_inclusive=False),
    "fabrication_error_mm": Range(0.0, 1.0, "mm", high_inclusive=False),
    "hysteresis": Range(0.0, 0.25, high_inclusive=False),
    "pressure_step_mpa": Range(0.0, 0.1, "MPa", low_inclusive=False),
    "pmax_mpa": Range(0.0, 1.0, "MPa", low_inclusive=False),
    "camera_noise_deg": Range(0.0, 90.0, "deg"),
    "max_angle_deg": Range(0.0, 300.0, "deg", low_inclusive=False),
}


def _checked_settings(settings: Mapping[str, object]) -> dict[str, Any]:
    """The settings of a :class:`VirtualLab` given, checked; an error is keyed by the setting.

    Only the settings given are checked (the lab's own defaults need none).
    """
    out: dict[str, Any] = dict(settings)
    if "actuators" in settings:
        given = settings["actuators"]
        actuators = tuple(given) if isinstance(given, Iterable) else ()
        if not actuators or not all(
            isinstance(a, Design) and a.actuator.analytical for a in actuators
        ):
            raise InputError(
                must_be(
                    "a non-empty sequence of designs of an actuator with an analytical model "
                    "(paper B's)",
                    given,
                ),
                key="actuators",
            )
        ids = [actuator_id(a) for a in actuators]
        repeated = sorted({i for i in ids if ids.count(i) > 1})
        if repeated:
            raise InputError(
                f"must be distinct designs; got {', '.join(repeated)} more than once",
                key="actuators",
            )
        out["actuators"] = actuators
    if "plant" in settings:
        with keyed("plant"):
            LAB_MODELS.check(settings["plant"])
    if "elastomer" in settings:
        check_choice(settings["elastomer"], "elastomer", shipped_tensile_tests())
    for key, bounds in _BOUNDS.items():
        if key in settings:
            out[key] = check_range(
                settings[key],
                key,
                low=bounds.low,
                high=bounds.high,
                low_inclusive=bounds.low_inclusive,
                high_inclusive=bounds.high_inclusive,
            )
    if "unloading" in settings and not isinstance(settings["unloading"], bool):
        raise InputError(must_be("True or False", settings["unloading"]), key="unloading")
    if "cycles" in settings:
        cycles = out["cycles"] = check_int(settings["cycles"], "cycles", low=1)
        with keyed("cycles"):
            check_limit("cycles", cycles, "the count")
    if "seed" in settings:
        out["seed"] = check_int(settings["seed"], "seed", low=0)
    if settings.get("material") is not None:
        from softbend.materials.choice import material_from_spec

        for key in ("elastomer", "elastomer_max_stretch"):
            if key in settings and settings[key] != getattr(VirtualLab, key):
                raise InputError(
                    f"gives the lab's silicone whole, so {key} ({settings[key]!r}) would not "
                    f"be used; give one of material and {key}",
                    key="material",
                )
        with keyed("material"):
            out["_material"] = material_from_spec(str(settings["material"]))
    if "pmax_mpa" in out or "pressure_step_mpa" in out:
        with keyed("pmax_mpa"):  # a whole number of steps
            default_pressures_mpa(
                out.get("pmax_mpa", VirtualLab.pmax_mpa),
                out.get("pressure_step_mpa", VirtualLab.pressure_step_mpa),
            )
    return out


@dataclass(frozen=True)
class VirtualLab:
    """Settings of the virtual lab; :meth:`measure` runs it.

    Parameters
    ----------
    actuators : tuple of Design
        Nominal designs measured, default :data:`LAB_ACTUATORS` (paper B Fig. 7).
    plant : str
        Model of the actuators as built, a name of :data:`LAB_MODELS`: the 3D FEM
        (``"fem"``, default) or the analytical model (``"analytical"``: seconds
        instead of minutes, for checks).
    elastomer : str
        Shipped tensile test the lab's silicone is fitted to (Yeoh), default
        ``"dragon-skin-30"``.
    elastomer_max_stretch : float
        Largest stretch of the tensile test used by the fit, > 1 (default 3: the
        working range of the walls).
    material : str, optional
        The lab's silicone given whole instead: a preset name or the ``fit.json``
        of ``softbend materials fit`` (``PATH#MODEL`` for one of its models;
        :func:`softbend.materials.material_from_spec`). ``elastomer`` and
        ``elastomer_max_stretch`` are then not used, and must be left at their
        defaults (another value is refused: it would be dropped).
    fabrication_error_mm : float
        Half-width of the uniform error of ``t`` and ``b``, mm, in [0, 1).
    hysteresis : float
        ``h``: half the largest relative gap between the loading and unloading
        branches, in [0, 0.25).
    camera_noise_deg : float
        Standard deviation of the angle reading, degrees, in [0, 90] (a larger
        spread would read angles no actuator reaches).
    pressure_step_mpa : float
        Increment of the set pressure, MPa (paper B: 0.01).
    pmax_mpa : float
        Highest pressure set, MPa (paper B went to 0.17, some actuators beyond 0.2).
    max_angle_deg : float
        The lab stops raising the pressure of an actuator once its angle passes
        this, degrees, in (0, 300].
    unloading : bool
        Also read the unloading branch, from the top pressure back to 0.
    cycles : int
        Inflation (and deflation) cycles per actuator, >= 1 and at most the
        ``cycles`` limit of :mod:`softbend.limits` (1000 unless raised).
    seed : int
        Seed of the fabrication errors and the camera noise, >= 0.

    Raises
    ------
    InputError
        A setting out of its range, keyed by its name;
        :class:`~softbend.errors.LimitError` for ``cycles`` over its limit.
    """

    actuators: tuple[Design, ...] = LAB_ACTUATORS
    plant: str = "fem"
    elastomer: str = "dragon-skin-30"
    elastomer_max_stretch: float = 3.0
    material: str | None = None
    fabrication_error_mm: float = 0.2
    hysteresis: float = 0.02
    camera_noise_deg: float = 1.0
    pressure_step_mpa: float = FEM_VALIDATION["pressure_step_mpa"].value
    pmax_mpa: float = 0.25
    max_angle_deg: float = 270.0
    unloading: bool = False
    cycles: int = 1
    seed: int = 0
    _material: Material | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        settings = {
            key: getattr(self, key)
            for key in (
                "actuators",
                "plant",
                "elastomer",
                "material",
                *_BOUNDS,
                "unloading",
                "cycles",
                "seed",
            )
        }
        # A bad material spec is refused here, keyed 'material'; a good one is kept.
        for key, value in _checked_settings(settings).items():
            object.__setattr__(self, key, value)

    # -- the gap -----------------------------------------------------------------

    def elastomer_material(self) -> Material:
        """The lab's silicone: ``material`` if given, else a Yeoh fit of the shipped tensile
        test (density of DS30)."""
        if self._material is None and self.material is not None:
            from softbend.materials.choice import material_from_spec

            with keyed("material"):
                chosen = material_from_spec(str(self.material))
            object.__setattr__(self, "_material", chosen)
        if self._material is None:
            test = load_shipped(self.elastomer)
            fit = fit_model(
                "yeoh",
                test.stretch,
                test.engineering_stress_mpa,
                max_stretch=self.elastomer_max_stretch,
            )
            material = Material(
                name=f"{self.elastomer} (virtual lab fit)",
                model=fit.model,
                density_t_per_mm3=DRAGON_SKIN_30.density_t_per_mm3,
                source=(
                    f"Yeoh fit of the shipped {self.elastomer} tensile test, stretch <= "
                    f"{self.elastomer_max_stretch:g} ({fit.n_points} points, RMSE "
                    f"{fit.rmse_mpa:.3g} MPa)"
                ),
            )
            object.__setattr__(self, "_material", material)
        return self._material  # type: ignore[return-value]

    def as_built(self) -> tuple[Design, ...]:
        """Each actuator as fabricated: ``t`` and ``b`` off nominal by the seeded error."""
        rng = np.random.default_rng([self.seed, 0])
        built = []
        for design in self.actuators:
            dt, db = rng.uniform(-self.fabrication_error_mm, self.fabrication_error_mm, size=2)
            values = design.as_dict()
            values.update(t_mm=round(design.t_mm + dt, 4), b_mm=round(design.b_mm + db, 4))
            built.append(sfrba_design(**values))
        return tuple(built)

    def plant_model(self) -> BendingModel:
        """The bending model of the actuators as built, with the lab's elastomer."""
        with keyed("plant"):
            factory = LAB_MODELS.get(self.plant)
        return factory(self.elastomer_material())

    def metadata(self) -> dict[str, str]:
        """Header lines of the lab's files: synthetic, the gap's parameters, the material."""
        material = self.elastomer_material()
        values = {
            k: v
            for k, v in asdict(self).items()
            if k not in ("actuators", "_material")
            # the material given whole replaces the shipped test's fit
            and not (k == "material" and v is None)
            and not (k.startswith("elastomer") and self.material is not None)
        }
        meta = {
            "synthetic": "true",
            "note": "virtual-lab measurements (labelled-synthetic), not of a real actuator",
            "generator": "softbend.transfer.VirtualLab",
        }
        meta.update({f"lab.{k}": str(v) for k, v in values.items()})
        model = material.model
        meta["lab.elastomer_model"] = (
            f"Yeoh c10={model.c10_mpa:.5g} c20={model.c20_mpa:.5g} c30={model.c30_mpa:.5g} MPa"
            if isinstance(model, Yeoh)
            else " ".join(f"{k}={v}" for k, v in model.to_dict().items())
        )
        meta["lab.material_source"] = material.source
        meta["lab.as_built"] = "; ".join(
            f"{actuator_id(n)} -> t={b.t_mm:g} b={b.b_mm:g} mm"
            for n, b in zip(self.actuators, self.as_built(), strict=True)
        )
        return meta

    # -- the measurement ---------------------------------------------------------

    def measure(
        self,
        model: BendingModel | None = None,
        *,
        progress: Callable[[int, int, str], None] | None = None,
    ) -> Measurements:
        """Measure every actuator; returns labelled-synthetic :class:`Measurements`.

        Parameters
        ----------
        model : BendingModel, optional
            The elastic model of the actuators as built; default :meth:`plant_model`.
        progress : callable, optional
            ``progress(done, total, actuator_id)`` after each actuator.

        Returns
        -------
        Measurements
            Rows in the order measured, with ``actuator_id`` (the nominal design),
            ``cycle`` and ``direction``; :meth:`metadata` as the file header.

        Raises
        ------
        ConvergenceError
            The model stopped before an actuator's second pressure step.
        InputError
            Key ``max_angle_deg``: it stops an actuator before its second reading.
        """
        model = self.plant_model() if model is None else model
        grid = default_pressures_mpa(self.pmax_mpa, self.pressure_step_mpa)
        noise_rng = np.random.default_rng([self.seed, 1])
        frames = []
        for done, (nominal, built) in enumerate(
            zip(self.actuators, self.as_built(), strict=True), start=1
        ):
            sweep = model.sweep(built, grid)
            reached = sweep.pressure_mpa[sweep.converged]
            angle = sweep.angle_deg[sweep.converged]
            keep = np.cumprod(angle <= self.max_angle_deg).astype(bool)
            pressures, elastic = reached[keep], angle[keep]
            if reached.size < 2:
                raise ConvergenceError(
                    f"The virtual lab could not load actuator {actuator_id(nominal)}: its "
                    f"{model.name} model stopped before its second pressure step",
                    pressure_mpa=float(reached.max(initial=0.0)),
                )
            if pressures.size < 2:
                raise InputError(
                    f"({self.max_angle_deg:g}°) stops actuator {actuator_id(nominal)} before "
                    f"its second reading: it bends {float(angle[1]):.4g}° at "
                    f"{float(reached[1]):g} MPa; raise it, or lower the pressure step",
                    key="max_angle_deg",
                )
            frames.extend(self._readings(nominal, pressures, elastic, noise_rng))
            if progress is not None:
                progress(done, len(self.actuators), actuator_id(nominal))
        frame = pd.concat(frames, ignore_index=True)
        return Measurements.from_frame(
            frame, metadata=self.metadata(), source=f"virtual lab ({self.plant}, seed {self.seed})"
        )

    def _readings(
        self,
        nominal: Design,
        pressures: np.ndarray,
        elastic: np.ndarray,
        rng: np.random.Generator,
    ) -> list[pd.DataFrame]:
        s = pressures / pressures[-1]
        bump = 4.0 * s * (1.0 - s)
        branches = [("loading", pressures, elastic * (1.0 - self.hysteresis * bump))]
        if self.unloading:
            back = slice(-2, None, -1)  # from below the top back to 0
            branches.append(
                ("unloading", pressures[back], (elastic * (1.0 + self.hysteresis * bump))[back])
            )
        out = []
        for cycle in range(1, self.cycles + 1):
            for direction, p, true_angle in branches:
                reading = true_angle + rng.normal(0.0, self.camera_noise_deg, size=p.size)
                row: dict[str, Any] = {
                    _COLUMNS[name]: getattr(nominal, name) for name in PARAMETERS
                }
                out.append(
                    pd.DataFrame(
                        {
                            **{k: np.full(p.size, float(v)) for k, v in row.items()},
                            "pressure_mpa": p,
                            "angle_deg": reading,
                            "actuator_id": actuator_id(nominal),
                            "cycle": cycle,
                            "direction": direction,
                        }
                    )
                )
        return out


def shipped_measurements_path() -> Path:
    """Path of the shipped virtual-lab readings (``softbend/data/transfer/virtual_lab.csv``)."""
    from importlib import resources

    return Path(str(resources.files("softbend") / "data" / "transfer" / "virtual_lab.csv"))


def shipped_measurements() -> Measurements:
    """The default virtual lab's measurements as shipped (``softbend lab measure``, seed 0, FEM).

    120 labelled-synthetic readings of the seven actuators of paper B Fig. 7;
    ``softbend lab measure --out virtual_lab.csv`` makes them again (about two
    CPU minutes). The file: :func:`shipped_measurements_path`.
    """
    from softbend.transfer.measurements import load_measurements

    return load_measurements(shipped_measurements_path())
