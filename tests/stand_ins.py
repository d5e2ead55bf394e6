"""Small stand-ins for the expensive inputs of the pipeline and report tests."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from collections.abc import Set as AbstractSet
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from softbend.actuators import Actuator, Design, DesignParameter
from softbend.design import DesignSpace
from softbend.errors import ConvergenceError, InputError
from softbend.fem.families import FEM_FAMILIES, FEMFamily
from softbend.models import SweepResult


def small_space() -> DesignSpace:
    """Two levels of l, t and b: enough for the regression, fast enough for CI (8 designs)."""
    return DesignSpace.grid(
        {
            "l_mm": [100.0, 130.0],
            "r_mm": [6.0],
            "t_mm": [2.0, 3.0],
            "b_mm": [2.0, 3.0],
            "phi_deg": [5.0],
            "lc_mm": [8.0],
        },
        name="small",
    )


def stand_in_fem_dataset(folder: Path) -> Path:
    """A small dataset in the shipped format (analytical sweeps of 15 designs: fast, same table)."""
    from softbend.campaign import run_campaign
    from softbend.dataset_writing import write_dataset

    db = folder / "stand_in.duckdb"
    run_campaign(db, DesignSpace.sample(15, seed=4), backend="analytical", workers=0)
    write_dataset(db, folder / "dataset", command="stand-in for the test")
    return folder / "dataset"


def web_server():
    """A local TCP server answering every connection like a web server; returns (port, close)."""
    import socket
    import threading

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    server.settimeout(0.1)
    stop = threading.Event()

    def serve() -> None:
        while not stop.is_set():
            try:
                conn, _ = server.accept()
            except OSError:
                continue
            with conn:
                conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()

    def close() -> None:
        stop.set()
        thread.join()
        server.close()

    return server.getsockname()[1], close


class StuckOpen:
    """A controller that keeps the inlet open: only a watchdog can vent after the link goes."""

    predicted_deg = float("nan")

    def reset(self):
        pass

    def step(self, measurement_mpa, reference_deg, t_s):
        return (True, False)


# --- an actuator other than paper B's: a simulation table by named columns -----------------

ACTUATOR_COLUMNS = "n_chambers,wall_mm,height_mm,layer"


def actuator_law(n, wall, height, layer, p_kpa):
    """A made-up bending law of a four-parameter actuator, degrees (pre-curved by -3°)."""
    stiffness = wall * (1.3 if layer == "fabric" else 1.0)
    return -3.0 + n * height * (p_kpa / 50.0) ** 1.2 / stiffness


def actuator_table(designs: int = 24, seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(designs):
        n = int(rng.integers(6, 15))
        wall = round(float(rng.uniform(1.0, 3.0)), 1)
        height = round(float(rng.uniform(8.0, 16.0)), 1)
        layer = str(rng.choice(["paper", "fabric"]))
        for p in np.linspace(0.0, 50.0, 6):
            rows.append(
                {
                    "design_id": f"d{i:02d}",
                    "n_chambers": n,
                    "wall_mm": wall,
                    "height_mm": height,
                    "layer": layer,
                    "p_kpa": p,
                    "angle_deg": actuator_law(n, wall, height, layer, p),
                }
            )
    return pd.DataFrame(rows)


def actuator_plr_base(sims: Path, folder: Path, pressure_column: str = "p_kpa") -> Path:
    """A quick polynomial surrogate of a table of :func:`actuator_table`, saved under ``folder``.

    The pressure unit is the column's (``p_kpa`` → kPa, ``p_psi`` → psi). Returns the
    model file, ``folder/models/plr.json``.
    """
    from softbend.surrogates.simulation_table import table_training_data
    from softbend.surrogates.workflow import train_surrogates
    from softbend.units import column_unit

    data = table_training_data(
        sims,
        design_columns=ACTUATOR_COLUMNS,
        pressure_column=pressure_column,
        pressure_unit=column_unit(pressure_column),
    )
    train_surrogates(data, folder, models="plr", grid_name="quick", folds=3, export_onnx=False)
    return folder / "models" / "plr.json"


# --- a stand-in FEM family: a closed-form sweep behind softbend.fem.families ----------------


#: The design parameters of a stand-in family of cells: a count and two lengths (mm).
CELL_PARAMETERS = (
    DesignParameter("n_cells", "", 2, 5, kind="integer"),
    DesignParameter("width_mm", "mm", 1.0, 3.0, resolution=0.1),
    DesignParameter("height_mm", "mm", 2.0, 6.0, resolution=0.5),
)
#: Its constraint between the two lengths, and its reference design.
CELL_CONSTRAINTS = ("width_mm < height_mm - 0.5",)
CELL_REFERENCE = {"n_cells": 3, "width_mm": 2.0, "height_mm": 4.0}


@dataclass(frozen=True)
class StandInDesigns:
    """A stand-in family's ``make_design``: designs with 5 cells cap one value.

    ``cap = (name, limit)`` refuses a design with ``n_cells == 5`` and
    ``values[name] > limit + slack`` (mm), as a family refuses walls too thick
    for its chambers; ``cap`` None accepts every design.
    """

    actuator: Actuator
    cap: tuple[str, float] | None = None
    slack: float = 0.0

    def __call__(self, values: dict[str, float]) -> Design:
        if self.cap is not None:
            name, limit = self.cap
            if values["n_cells"] == 5 and values[name] > limit + self.slack:
                raise InputError(f"must be at most {limit:g} mm with 5 cells", key=name)
        return Design(self.actuator, values)


@dataclass(frozen=True)
class ClosedFormSweep:
    """A stand-in family's sweep: ``angle = k_deg_per_mpa · p · (sum of the design's values)``.

    Parameters
    ----------
    k_deg_per_mpa : float
        The closed form's factor, degrees per MPa per unit of the summed values.
    touch_mpa : callable, optional
        ``touch_mpa(values[touch_parameter])``: the pressure, MPa, where
        neighbouring walls touch; the sweep keeps the pressures up to it and
        records the stop ``"neighbouring walls touch at X kPa"`` when it falls
        before the last pressure (``"reached the last pressure"`` otherwise).
        A function of an importable module, so the sweep pickles to workers.
    touch_parameter : str
        The design value ``touch_mpa`` takes.
    stop_reasons : mapping of int to str, optional
        The recorded stop reason of a design with each number of cells.
    failing : set of str
        Design ids whose sweep raises ConvergenceError (a solver that does not converge).
    solver_record : bool
        Record what a solver would: tip at x = 40 mm and z = -p, 2 Newton
        iterations a step, 0.5 s, a mesh of 7 elements, and the stats of every
        load step, one rejected step, 300 degrees of freedom and an options
        hash; False records zeros, 1 iteration, 0 s and a mesh of 1.
    """

    k_deg_per_mpa: float
    touch_mpa: Callable[[float], float] | None = None
    touch_parameter: str = "width_mm"
    stop_reasons: Mapping[int, str] | None = None
    failing: AbstractSet[str] = frozenset()
    solver_record: bool = False

    def __call__(
        self, design, pressures_mpa, options=None, *, progress=None, keep_states=False
    ) -> tuple[SweepResult, None, None]:
        if design.design_id in self.failing:
            raise ConvergenceError("stand-in does not converge", pressure_mpa=0.0)
        p = np.asarray(pressures_mpa, dtype=float)
        stats: dict = {}
        if self.touch_mpa is not None:
            touch = self.touch_mpa(design.values[self.touch_parameter])
            p = p[p <= touch]
            stats["stop_reason"] = (
                f"neighbouring walls touch at {touch * 1000:.2f} kPa"
                if touch < float(np.max(pressures_mpa))
                else "reached the last pressure"
            )
        if self.stop_reasons is not None:
            stats["stop_reason"] = self.stop_reasons[round(design.values["n_cells"])]
        angle = self.k_deg_per_mpa * p * sum(design.values.values())
        if self.solver_record:
            stats.update(steps_mpa=p.tolist(), rejected_steps=1, ndof=300, options_sha256="ab" * 32)
            record = dict(
                tip_x_mm=np.full_like(p, 40.0),
                tip_z_mm=-p,
                newton_iterations=np.full(len(p), 2),
                wall_time_s=0.5,
                mesh_size=7,
            )
        else:
            record = dict(
                tip_x_mm=np.zeros_like(p),
                tip_z_mm=np.zeros_like(p),
                newton_iterations=np.ones(len(p), dtype=int),
                wall_time_s=0.0,
                mesh_size=1,
            )
        result = SweepResult(
            design=design,
            pressure_mpa=p,
            angle_deg=angle,
            converged=np.ones(len(p), dtype=bool),
            stats=stats,
            **record,
        )
        return result, None, None


def stand_in_family(
    name: str,
    parameters: tuple[DesignParameter, ...],
    k_deg_per_mpa: float,
    *,
    title: str = "stand-in actuator with a closed-form sweep",
    actuator_title: str = "stand-in actuator",
    reference: Mapping[str, float],
    pmax_mpa: float,
    pstep_mpa: float,
    maxh_mm: float = 2.0,
    cap: tuple[str, float] | None = None,
    cap_slack: float = 0.0,
    touch_mpa: Callable[[float], float] | None = None,
    stop_reasons: Mapping[int, str] | None = None,
    failing: AbstractSet[str] = frozenset(),
    solver_record: bool = False,
    **actuator: Any,
) -> FEMFamily:
    """An FEM family ``name`` whose sweep is :class:`ClosedFormSweep` (no NGSolve).

    Parameters
    ----------
    name : str
        The family's name, also its actuator's and its designs' family.
    parameters : tuple of DesignParameter
        The actuator's design parameters (one of them ``n_cells``).
    k_deg_per_mpa : float
        The closed form's factor, degrees per MPa (see :class:`ClosedFormSweep`).
    title, reference, pmax_mpa, pstep_mpa, maxh_mm
        As :class:`~softbend.fem.families.FEMFamily` (MPa, mm).
    actuator_title : str
        The title of the family's :class:`~softbend.actuators.Actuator`.
    cap, cap_slack
        The design a family refuses (see :class:`StandInDesigns`), mm.
    touch_mpa, stop_reasons, failing, solver_record
        As :class:`ClosedFormSweep`.
    **actuator
        Further fields of the actuator (``constraints``, ``pressure_unit``, ...).
    """
    described = Actuator(
        name=name, title=actuator_title, parameters=parameters, fem_family=name, **actuator
    )
    return FEMFamily(
        name=name,
        title=title,
        actuator=described,
        reference=reference,
        pmax_mpa=pmax_mpa,
        pstep_mpa=pstep_mpa,
        maxh_mm=maxh_mm,
        make_design=StandInDesigns(described, cap, cap_slack),
        sweep=ClosedFormSweep(
            k_deg_per_mpa,
            touch_mpa=touch_mpa,
            stop_reasons=stop_reasons,
            failing=failing,
            solver_record=solver_record,
        ),
    )


@contextmanager
def registered_family(family: FEMFamily) -> Iterator[FEMFamily]:
    """``family`` registered in ``FEM_FAMILIES`` (replacing one of its name), removed after."""
    FEM_FAMILIES.register(family.name, family, replace=True)
    try:
        yield family
    finally:
        FEM_FAMILIES.unregister(family.name)


def check_closed_form_samples(samples: pd.DataFrame, names, k_deg_per_mpa: float, rows: int):
    """Assert a stand-in family's samples: the campaign's columns, the closed-form angle
    ``k · p · (sum of the design's values)`` and ``rows`` rows."""
    assert list(samples.columns) == [
        "design_id",
        *names,
        "pressure_mpa",
        "angle_deg",
        "tip_x_mm",
        "tip_z_mm",
        "converged",
    ]
    expected = k_deg_per_mpa * samples["pressure_mpa"] * samples[list(names)].sum(axis=1)
    assert np.allclose(samples["angle_deg"], expected) and len(samples) == rows


@dataclass(frozen=True)
class CompilingSweep:
    """A campaign backend that runs a child process for $COMPILE_S s before each sweep.

    As the FEM runs its compilers: a process a worker starts, in the worker's
    process group, with the worker's stderr; the child appends its process id
    to ``started`` (a file). With ``compiled`` the child runs through the C
    library's ``system()``, as NGSolve runs them when the FEM compiles its
    energy (the caller ignores SIGINT meanwhile). Then the analytical model
    sweeps the design. The time is read from the environment, so that it is no
    setting the campaign records.
    """

    started: str
    compiled: bool = False
    name: str = "compiling"

    def sweep(self, design, pressures_mpa):
        import os
        import shlex
        import subprocess
        import sys

        from softbend.campaign import get_backend

        seconds = float(os.environ.get("COMPILE_S", "0"))
        code = (
            f"import os, time; open({self.started!r}, 'a').write(f'{{os.getpid()}}\\n'); "
            f"time.sleep({seconds!r})"
        )
        if self.compiled:
            status = os.system(shlex.join([sys.executable, "-c", code]))
        else:
            status = subprocess.run([sys.executable, "-c", code]).returncode
        if status != 0:
            raise RuntimeError(f"the child process ended with {status}")
        return get_backend("analytical").sweep(design, pressures_mpa)


def running(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie (Linux)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "\nState:\tZ" not in status


def train_closed_form(
    folder: Path, actuator: Actuator, angle: Callable[[float, float, float], float]
) -> Path:
    """A polynomial surrogate of ``angle(n_cells, width_mm, p_mpa)`` (degrees), trained on
    a 4 × 5 grid of designs (n_cells 2–5, width_mm 1–3) swept 0 to 50 kPa in 5 kPa steps,
    the table in kPa as ``actuator`` describes it; the saved model's path."""
    import itertools

    from softbend.surrogates.simulation_table import table_training_data
    from softbend.surrogates.workflow import train_surrogates

    rows = []
    designs = itertools.product((2, 3, 4, 5), (1.0, 1.5, 2.0, 2.5, 3.0))
    for i, (n, w) in enumerate(designs):
        for p_kpa in np.linspace(0.0, 50.0, 11):
            rows.append(
                {"design_id": f"d{i:02d}", "n_cells": n, "width_mm": w, "p_kpa": p_kpa,
                 "angle_deg": angle(n, w, p_kpa / 1000)}
            )  # fmt: skip
    table = Path(folder) / "sims.csv"
    pd.DataFrame(rows).to_csv(table, index=False)
    data = table_training_data(table, actuator=actuator)
    train_surrogates(data, Path(folder) / "m", models="plr", grid_name="quick", export_onnx=False)
    return Path(folder) / "m" / "models" / "plr.json"
