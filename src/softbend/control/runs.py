"""Control runs as the command line asks for them: simulated, in the loop on a rig, or served.

- :func:`simulate_control`: a controller on the simulated rig in simulated time,
  scored as paper B's Fig. 9 (``softbend control simulate``);
- :func:`plan_loop` then :meth:`LoopPlan.run`: the controller in the
  fixed-period, safety-checked loop on a rig of :data:`~softbend.control.rigs.RIGS`,
  with its tick log (``softbend control run``);
- :func:`simulated_server`: the simulated rig behind a Modbus TCP server
  (``softbend control serve``).

Each returns, with its results, the summary that the command writes as JSON:
the effective controller name and parameters (``controller_params``) included.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._validation import check_range, must_be
from softbend.control.budget import LOOP_BYTES_PER_TICK, SIMULATE_BYTES_PER_STEP, check_run_size
from softbend.control.experiments import ControlRun, Reference, parse_reference
from softbend.control.rig import Rig
from softbend.control.rigconfig import RigConfig, load_rig_config
from softbend.control.rigs import (
    DEFAULT_RIG,
    HARDWARE_RIGS,
    RIGS,
    RigSetup,
    make_rig,
    rig_settings,
)
from softbend.control.setup import (
    ControlSetup,
    beyond_support,
    check_supply,
    prepare_control,
)
from softbend.errors import InputError, keyed

if TYPE_CHECKING:
    from softbend.control.loop import LoopRun
    from softbend.control.modbus_server import SimulatedModbusServer
    from softbend.control.plant_choice import PlantChoice

__all__ = [
    "LoopPlan",
    "LoopResult",
    "Simulation",
    "plan_loop",
    "simulate_control",
    "simulated_server",
]


@dataclass(frozen=True)
class Simulation:
    """A run of :func:`simulate_control`: the run and its summary (``metrics.json``)."""

    setup: ControlSetup = field(repr=False)
    run: ControlRun = field(repr=False)
    summary: dict[str, Any]


def simulate_control(
    *,
    reference: str = "step:90",
    controller: str | None = None,
    assignments: Sequence[str] = (),
    design: str | None = None,
    model: str | Path | None = None,
    plant: str | PlantChoice = "surrogate",
    duration_s: float = 10.0,
    supply_mpa: float | None = None,
    rig_assignments: Sequence[str] = (),
    seed: int = 0,
    strict: bool = False,
    rig_from: str | Path | None = None,
) -> Simulation:
    """Run a controller on the simulated rig of ``design`` and score it (synthetic).

    Parameters are those of :func:`~softbend.control.setup.prepare_control` (``design``
    default: paper B's (100,6,2,2,5,8); ``model`` default: the plant when it is a saved
    surrogate, else the shipped MLP), plus the
    ``reference`` spec (:func:`~softbend.control.experiments.parse_reference`,
    degrees), ``duration_s`` (s), ``seed`` (sensor and camera noise) and
    ``rig_assignments``: ``NAME=VALUE`` settings of the simulated rig
    (``--rig-param``, :func:`~softbend.control.rigs.rig_settings`; ``supply_mpa``,
    default 0.2 MPa, is its ``supply_gauge_mpa``). A run
    that reaches a pressure past what the models were trained to near the
    design warns (:func:`~softbend.control.setup.beyond_support`) and says so in
    the summary's ``support``; with ``strict`` the run is refused before it starts
    when the supply lies past it. ``rig_from``, a model saved by ``softbend
    identify``, sets the rig's ``angle_time_constant_s`` and ``valve_delay_s``
    from its step reading (:func:`~softbend.control.identified_plant.rig_settings_from`;
    ``rig_assignments`` win); the summary's ``rig_from`` says where they came from.
    ``plant`` may be such a model too: its dynamics then play the actuator
    (:mod:`softbend.control.identified_plant`).
    """
    from softbend.control.experiments import run_metrics, simulate, summary_metrics
    from softbend.control.rig import RigParams, SimulatedRig

    ref = parse_reference(reference)
    simulated, origin = _rig_settings(rig_assignments, {}, supply_mpa, rig_from)
    check_run_size(
        duration_s, simulated.get("step_s", RigParams.step_s), SIMULATE_BYTES_PER_STEP,
        what="A simulated run", unit="rig steps",
    )  # fmt: skip
    setup = prepare_control(
        controller=controller, assignments=assignments, design=design, model=model,
        plant=plant, rig_settings=simulated, strict=strict,
    )  # fmt: skip
    rig = SimulatedRig(
        setup.plant_table, setup.rig_params, seed=seed, dynamics=setup.plant_dynamics()
    )
    run = simulate(rig, setup.controller, ref, duration_s, seed=seed)
    reached = float(np.max(run.pressure_mpa))
    beyond = beyond_support(setup, reached)
    if beyond is not None:
        warnings.warn(beyond, UserWarning, stacklevel=2)
    reasons: dict[str, str] = {}
    metrics, undefined = summary_metrics(run_metrics(run, reasons=reasons), reasons)
    summary = {
        "synthetic": True,
        "reference": reference,
        **setup.record(),
        "duration_s": duration_s,
        "seed": seed,
        "rig": setup.rig_params.as_dict(),
        "rig_settings": dict(setup.rig_settings),
        **({"rig_from": origin} if origin is not None else {}),
        "metrics": metrics,
        "undefined_metrics": undefined,
        "support": {
            "supported_mpa": setup.supported_mpa,
            "max_pressure_mpa": reached,
            "beyond": beyond is not None,
            "notes": list(setup.support_notes),
        },
    }
    return Simulation(setup=setup, run=run, summary=summary)


@dataclass(frozen=True)
class LoopResult:
    """A loop run: the :class:`~softbend.control.loop.LoopRun` and its summary (``run.json``)."""

    loop: LoopRun = field(repr=False)
    summary: dict[str, Any]

    def control_run(self) -> ControlRun:
        """The run as a :class:`~softbend.control.experiments.ControlRun` (for its figure)."""
        return self.loop.control_run()


@dataclass(frozen=True)
class LoopPlan:
    """A checked loop run, ready to start: :func:`plan_loop` builds it.

    Attributes
    ----------
    setup : ControlSetup
    rig : str
        Name of the rig (:data:`~softbend.control.rigs.RIGS`).
    rig_setup : RigSetup
    reference_spec : str
    reference : Reference
    duration_s, period_s, sensor_period_s : float
        Run time, loop tick and sensor period, s.
    seed : int
    """

    setup: ControlSetup = field(repr=False)
    rig: str
    rig_setup: RigSetup = field(repr=False)
    reference_spec: str
    reference: Reference
    duration_s: float
    period_s: float
    sensor_period_s: float
    seed: int
    rig_from: dict[str, Any] | None = None

    @property
    def ticks(self) -> int:
        """Ticks of the loop."""
        return max(1, round(self.duration_s / self.period_s))

    def make_rig(self) -> Rig:
        """The rig of the run, built (a hardware rig connected) by its factory."""
        return make_rig(self.rig, self.rig_setup)

    def run(
        self,
        log_path: Path | None = None,
        progress: Callable[[int, int], None] | None = None,
        *,
        device: Rig | None = None,
    ) -> LoopResult:
        """Run the loop on ``device`` (default: :meth:`make_rig`), logging every tick to
        ``log_path``; the rig is closed at the end, whatever happens."""
        from softbend.control.loop import run_loop

        device = self.make_rig() if device is None else device
        try:
            if log_path is not None:
                Path(log_path).parent.mkdir(parents=True, exist_ok=True)
            result = run_loop(
                device, self.setup.controller, self.reference, self.duration_s,
                period_s=self.period_s, sensor_period_s=self.sensor_period_s,
                limits=self.rig_setup.config.safety, log_path=log_path, progress=progress,
            )  # fmt: skip
        finally:
            device.close()
        reached = self._reached(result)
        beyond = beyond_support(self.setup, reached)
        if beyond is not None:
            warnings.warn(beyond, UserWarning, stacklevel=2)
        return LoopResult(loop=result, summary=self._summary(device, result, reached, beyond))

    @staticmethod
    def _reached(result: LoopRun) -> float:
        """The largest pressure read in the run, MPa (0 when no reading was logged)."""
        measured = result.control_run().measured_mpa
        finite = measured[np.isfinite(measured)]
        return float(finite.max()) if finite.size else 0.0

    def _summary(
        self, device: Rig, result: LoopRun, reached: float, beyond: str | None
    ) -> dict[str, Any]:
        from softbend.control.experiments import summary_metrics

        synthetic = bool(getattr(device, "synthetic", False))
        record = self.setup.record()
        reasons: dict[str, str] = {}
        metrics, undefined = summary_metrics(result.metrics(reasons), reasons)
        summary = {
            "synthetic": synthetic,
            "rig": self.rig,
            "where": getattr(device, "where", self.rig),
            "reference": self.reference_spec,
            **record,
            "plant": record["plant"] if synthetic else "the rig",
            "duration_s": self.duration_s,
            "period_s": self.period_s,
            "sensor_period_s": self.sensor_period_s,
            "seed": self.seed,
            "completed": result.completed,
            "stop_reason": result.stop_reason,
            "fault_kind": result.fault_kind,
            "vented": result.vented,
            "jitter": result.jitter(),
            "metrics": metrics,
            "undefined_metrics": undefined,
            "rig_config": self.rig_setup.config.to_toml(),
            "rig_params": self.setup.rig_params.as_dict() if synthetic else None,
            "rig_settings": dict(self.setup.rig_settings) if synthetic else None,
            **({"rig_from": self.rig_from} if self.rig_from is not None else {}),
            "support": {
                "supported_mpa": self.setup.supported_mpa,
                "max_pressure_mpa": reached,
                "beyond": beyond is not None,
                "notes": list(self.setup.support_notes),
            },
        }
        trips = getattr(device, "round_trips_s", None)
        if trips is not None:
            summary["round_trip_ms"] = _percentiles_ms(trips)
        return summary


def plan_loop(
    *,
    rig: str = DEFAULT_RIG,
    config: str | Path | None = None,
    reference: str = "step:90",
    controller: str | None = None,
    assignments: Sequence[str] = (),
    design: str | None = None,
    model: str | Path | None = None,
    plant: str | PlantChoice = "surrogate",
    duration_s: float = 10.0,
    period_s: float | None = None,
    sensor_period_s: float | None = None,
    supply_mpa: float | None = None,
    rig_assignments: Sequence[str] = (),
    seed: int = 0,
    strict: bool = False,
    rig_from: str | Path | None = None,
) -> LoopPlan:
    """Check a loop run and build its controller; the rig is built by :meth:`LoopPlan.run`.

    Parameters
    ----------
    rig : str
        A name of :data:`~softbend.control.rigs.RIGS` (``sim``, ``sim-realtime``, ``modbus``).
    config : path, optional
        A rig TOML: its [safety] and [loop] apply to every rig, its connection and
        register map to ``modbus``, its [controller] when ``controller`` is not given
        or the same, its [simulation] to a simulated rig (``rig_assignments``
        override it).
    rig_assignments : sequence of str
        ``NAME=VALUE`` settings of a simulated rig (``--rig-param``); refused with a
        hardware rig (:data:`~softbend.control.rigs.HARDWARE_RIGS`).
    period_s, sensor_period_s : float, optional
        Loop tick and sensor period, s (default: the config's).
    strict : bool, default False
        Refuse, before any valve moves, a controller model or plant surrogate whose θ(p)
        of the design up to the supply leaves its training data (else a run that reached
        past it warns, and its summary's ``support`` says so).
    others
        As :func:`simulate_control`.
    """
    with keyed("rig"):
        RIGS.check(rig)
    if rig in HARDWARE_RIGS and rig_from is not None:
        raise InputError(
            f"sets the simulated rig, but the rig {rig} is hardware (its pneumatics are what "
            f"they are): drop it, or use the rig sim or sim-realtime; got {str(rig_from)!r}",
            key="rig_from",
        )
    if rig in HARDWARE_RIGS and rig_assignments:
        raise InputError(
            f"set the simulated rig, but the rig {rig} is hardware (its pneumatics are what "
            f"they are): drop them, or use the rig sim or sim-realtime; got "
            f"{list(rig_assignments)!r}",
            key="rig_assignments",
        )
    ref = parse_reference(reference)
    settings = load_rig_config(config) if config is not None else RigConfig()
    tick = settings.period_s if period_s is None else period_s
    sensor = settings.sensor_period_s if sensor_period_s is None else sensor_period_s
    table = dict(settings.simulation) if rig not in HARDWARE_RIGS else {}
    simulated, origin = _rig_settings(rig_assignments, table, supply_mpa, rig_from)
    check_range(tick, "period_s", low=0.0, high=1.0, high_inclusive=True)
    check_range(
        sensor, "sensor_period_s", low=tick, high=10.0,
        low_inclusive=True, high_inclusive=True,
    )  # fmt: skip
    check_run_size(duration_s, tick, LOOP_BYTES_PER_TICK, what="A loop run", unit="ticks")
    setup = prepare_control(
        controller=controller, assignments=assignments, config=settings.controller,
        design=design, model=model, plant=plant, rig_settings=simulated,
        strict=strict, simulated=rig not in HARDWARE_RIGS,
    )  # fmt: skip
    rig_setup = RigSetup(
        config=settings, config_path=None if config is None else Path(config),
        plant_table=setup.plant_table, params=setup.rig_params, seed=seed,
        dynamics=setup.plant_dynamics(),
    )  # fmt: skip
    return LoopPlan(
        setup=setup, rig=rig, rig_setup=rig_setup, reference_spec=reference, reference=ref,
        duration_s=duration_s, period_s=tick, sensor_period_s=sensor, seed=seed,
        rig_from=origin,
    )  # fmt: skip


def simulated_server(
    *,
    config: str | Path | None = None,
    host: str = "127.0.0.1",
    port: int | None = None,
    design: str | None = None,
    model: str | Path | None = None,
    plant: str | PlantChoice = "surrogate",
    supply_mpa: float | None = None,
    rig_assignments: Sequence[str] = (),
    seed: int = 0,
    rig_from: str | Path | None = None,
) -> SimulatedModbusServer:
    """The simulated rig of ``design`` behind a Modbus TCP server (not started).

    The register map is the ``config``'s (default: the built-in map); ``port``
    defaults to the config's, else 5020. The rig's parameters are the config's
    [simulation] table with ``rig_assignments`` (``--rig-param NAME=VALUE``) and
    ``supply_mpa`` over it (:func:`~softbend.control.rigs.rig_settings`), and the
    lag and delay of ``rig_from`` (an identified model) under them.
    """
    from softbend.control.modbus_server import SimulatedModbusServer
    from softbend.control.rig import SimulatedRig

    settings = load_rig_config(config) if config is not None else RigConfig()
    listen = port if port is not None else (settings.connection.port if config else 5020)
    if not host.strip():
        raise InputError(
            must_be("an address to listen on (e.g. 127.0.0.1 or 0.0.0.0)", host), key="host"
        )
    if not 0 <= listen <= 65535:
        raise InputError(must_be("an integer in [0, 65535]", listen), key="port")
    table = dict(settings.simulation)
    simulated, _ = _rig_settings(rig_assignments, table, supply_mpa, rig_from)
    setup = prepare_control(design=design, model=model, plant=plant, rig_settings=simulated)
    rig = SimulatedRig(
        setup.plant_table, setup.rig_params, seed=seed, dynamics=setup.plant_dynamics()
    )
    return SimulatedModbusServer(rig, settings, host=host, port=listen)


def _rig_settings(
    rig_assignments: Sequence[str],
    table: dict[str, Any],
    supply_mpa: float | None,
    rig_from: str | Path | None = None,
) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """The simulated rig's settings, and where those of ``rig_from`` came from (else None).

    ``supply_mpa`` is checked as a gauge pressure first; the settings given
    (``rig_assignments``, ``table``) win over those of ``rig_from``.
    """
    if supply_mpa is not None:
        check_supply(supply_mpa)
    given = rig_settings(rig_assignments, table, supply_mpa=supply_mpa)
    if rig_from is None:
        return given, None
    from softbend.control.identified_plant import rig_settings_from

    derived, record = rig_settings_from(rig_from)
    used = {k: v for k, v in derived.items() if k not in given}
    record["used"] = sorted(used)
    record["overridden"] = sorted(set(derived) - set(used))
    return {**used, **given}, record


def _percentiles_ms(values: list[float]) -> dict[str, float]:
    """The median and 99th percentile of durations in s, as ms (empty for none)."""
    import numpy as np

    if not values:
        return {}
    ms = np.asarray(values) * 1e3
    return {"p50": float(np.percentile(ms, 50)), "p99": float(np.percentile(ms, 99))}
