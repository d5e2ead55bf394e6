"""The FEM as the plant of any buildable design: swept on demand, kept on disk.

The shipped Table 1 dataset covers 972 designs; a lab's prototype is usually
not one of them. :func:`fem_curve` sweeps such a design with the FEM once
(seconds to a minute) and keeps the curve and the cavity's dV/dp in a cache
folder, so the next control run of that design starts at once. The curve gives
the plant's θ(p) (:meth:`FEMCurve.table`); the dV/dp gives the chamber's
compliance for the rig model (:meth:`FEMCurve.compliance_mm3_per_mpa`), instead
of the (100, 6, 2, 2, 5, 8) actuator's default.

The cache folder is ``$SOFTBEND_CACHE_DIR/fem-plants`` if that variable is set,
else ``~/.cache/softbend/fem-plants``; an entry is keyed by the design and the
FEM options, written atomically, and checked on reading (a damaged entry is
swept again).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._io import json_text, write_text_atomic
from softbend._progress import report
from softbend.actuators import Design
from softbend.control.rig import AngleTable, cavity_compliance_mm3_per_mpa
from softbend.design import sfrba_design

if TYPE_CHECKING:
    from softbend.fem.options import FEMOptions

__all__ = ["FEMCurve", "cache_dir", "fem_curve"]

#: The sweep's top pressure, MPa (paper B's grid; the sweep stops earlier at 300°).
PMAX_MPA = 0.5


def cache_dir() -> Path:
    """Where swept plants are kept: ``$SOFTBEND_CACHE_DIR/fem-plants`` or ``~/.cache/...``."""
    root = os.environ.get("SOFTBEND_CACHE_DIR")
    base = Path(root) if root else Path.home() / ".cache" / "softbend"
    return base / "fem-plants"


@dataclass(frozen=True)
class FEMCurve:
    """An FEM sweep of one design, as a plant needs it.

    Attributes
    ----------
    design : Design
    pressure_mpa, angle_deg : ndarray
        The converged samples of the sweep (MPa, degrees).
    steps_mpa, volume_rate_mm3_per_mpa : ndarray
        The solver's load steps and the cavity's dV/dp at each, mm³/MPa.
    stop_reason : str
        Why the sweep ended (the last pressure, 300°, an instability).
    """

    design: Design
    pressure_mpa: np.ndarray
    angle_deg: np.ndarray
    steps_mpa: np.ndarray
    volume_rate_mm3_per_mpa: np.ndarray
    stop_reason: str

    def table(self, pmax_mpa: float = 0.5, points: int = 501) -> AngleTable:
        """θ(p) on the table's grid: linear between samples, the last slope beyond them."""
        p, a = self.pressure_mpa, self.angle_deg
        slope = (a[-1] - a[-2]) / (p[-1] - p[-2])

        def angle(q: np.ndarray) -> np.ndarray:
            return np.where(q > p[-1], a[-1] + slope * (q - p[-1]), np.interp(q, p, a))

        return AngleTable.from_callable(angle, pmax_mpa=pmax_mpa, points=points)

    def compliance_mm3_per_mpa(self, up_to_mpa: float) -> float:
        """The cavity's dV/dp fitted by a line up to ``up_to_mpa`` (the supply), mm³/MPa."""
        return cavity_compliance_mm3_per_mpa(
            self.steps_mpa, self.volume_rate_mm3_per_mpa, up_to_mpa
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form (the cache entry)."""
        return {
            "design": self.design.as_dict(),
            "pressure_mpa": self.pressure_mpa.tolist(),
            "angle_deg": self.angle_deg.tolist(),
            "steps_mpa": self.steps_mpa.tolist(),
            "volume_rate_mm3_per_mpa": self.volume_rate_mm3_per_mpa.tolist(),
            "stop_reason": self.stop_reason,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> FEMCurve:
        """Rebuild from :meth:`to_dict`; ``ValueError``/``KeyError``/``TypeError`` if damaged."""
        curve = cls(
            design=sfrba_design(**data["design"]),
            pressure_mpa=np.asarray(data["pressure_mpa"], dtype=float),
            angle_deg=np.asarray(data["angle_deg"], dtype=float),
            steps_mpa=np.asarray(data["steps_mpa"], dtype=float),
            volume_rate_mm3_per_mpa=np.asarray(data["volume_rate_mm3_per_mpa"], dtype=float),
            stop_reason=str(data["stop_reason"]),
        )
        arrays = (curve.pressure_mpa, curve.angle_deg)
        if arrays[0].shape != arrays[1].shape or arrays[0].size < 2:
            raise ValueError("a cached FEM curve needs at least two samples")
        if not all(np.isfinite(a).all() for a in arrays):
            raise ValueError("a cached FEM curve holds a non-finite sample")
        return curve


def _key(design: Design, options: FEMOptions) -> str:
    described = json_text({"design": design.as_dict(), "options": options.to_dict()}, indent=None)
    return hashlib.sha256(described.encode()).hexdigest()[:16]


def fem_curve(
    design: Design,
    options: FEMOptions | None = None,
    *,
    progress: Callable[[float, float, float], None] | None = None,
    cache: bool = True,
) -> FEMCurve:
    """The FEM sweep of ``design`` up to 0.5 MPa: from the cache, else solved and kept.

    Parameters
    ----------
    design : Design
        Any design the FEM can build.
    options : FEMOptions, optional
        The FEM's settings (default :class:`~softbend.fem.FEMOptions`); part of the key.
    progress : callable, optional
        Passed to :func:`softbend.fem.simulate` (``progress(p, angle, pmax)``);
        default: reported to the listener of :mod:`softbend._progress`.
    cache : bool, default True
        Read and write the cache folder (:func:`cache_dir`).

    Raises
    ------
    ValueError
        The sweep converged at fewer than two pressures.
    """
    from softbend.fem import FEMOptions, simulate
    from softbend.models import default_pressures_mpa

    options = FEMOptions() if options is None else options
    path = cache_dir() / f"{design.design_id}-{_key(design, options)}.json"
    if cache and path.is_file():
        try:
            return FEMCurve.from_dict(json.loads(path.read_text(encoding="utf-8")))
        except (ValueError, KeyError, TypeError):
            pass  # damaged: solve again and overwrite
    if progress is None:  # whoever listens hears the sweep, in kPa of the 0.5 MPa
        phase = f"FEM sweep of {design} (kPa)"

        def progress(p: float, angle: float, pmax: float) -> None:
            report(phase, round(1000 * p), round(1000 * pmax))

    result = simulate(design, default_pressures_mpa(PMAX_MPA), options, progress=progress)
    ok = np.asarray(result.converged, dtype=bool)
    if ok.sum() < 2:
        raise ValueError(
            f"The FEM sweep of design {design} converged at fewer than two pressures; it "
            "cannot play the plant."
        )
    stats = result.stats
    curve = FEMCurve(
        design=design,
        pressure_mpa=np.asarray(result.pressure_mpa, dtype=float)[ok],
        angle_deg=np.asarray(result.angle_deg, dtype=float)[ok],
        steps_mpa=np.asarray(stats["steps_mpa"], dtype=float),
        volume_rate_mm3_per_mpa=np.asarray(stats["step_volume_rate_mm3_per_mpa"], dtype=float),
        stop_reason=str(stats.get("stop_reason", "")),
    )
    if cache:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(path, json_text(curve.to_dict()))
    return curve
