"""Add a controller of your own: one factory, one ``register`` call, then every tool uses it.

The controller here is paper B's deadzone bang-bang with a lead: it switches on
the virtual angle predicted ``lead`` seconds ahead (θp + lead·dθp/dt), meant to
close the valves before the angle reaches the band rather than after.
Registered as ``"lead-bang-bang"``, it runs through the same code as the
built-in controllers: ``softbend control simulate --controller lead-bang-bang
--set lead=0.05`` works once this module is imported (e.g. from a plugin
package), and its parameters are checked against their declared ranges, listed and recorded like
theirs.

The comparison it prints is an honest one: on the simulated rig the lead does
not beat paper B's controller. The rate comes from successive readings of a
noisy pressure sensor, so the prediction jitters across the band and the valves
switch about twice as often, with a little more overshoot; a lead would need a
filtered rate (or the rig model, as the ``predictive`` controller uses).

Run::

    python examples/custom_controller.py
"""

from __future__ import annotations

import math

from softbend.control import CONTROLLERS
from softbend.control.controllers import ValveCommand
from softbend.control.runs import simulate_control
from softbend.parameters import Range, declare_ranges


class LeadBangBang:
    """Deadzone bang-bang on the virtual angle extrapolated ``lead_s`` ahead.

    Parameters
    ----------
    virtual_sensor : callable
        Gauge pressure, MPa → angle, degrees.
    deadzone : float
        Half-width of the band around the reference, as a fraction of |θr|.
    lead_s : float
        How far ahead the angle is extrapolated, s (0: paper B's controller).
    period_s : float
        Control period, s.
    """

    def __init__(self, virtual_sensor, deadzone: float, lead_s: float, period_s: float) -> None:
        if not (0.0 <= deadzone < 1.0 and 0.0 <= lead_s <= 1.0 and 0.0 < period_s <= 1.0):
            raise ValueError(
                "The parameters of lead-bang-bang must be 0 <= deadzone < 1, 0 <= lead <= 1 s "
                f"and 0 < period <= 1 s. Got {deadzone}, {lead_s}, {period_s}."
            )
        self.sensor, self.deadzone, self.lead_s, self.period_s = (
            virtual_sensor, deadzone, lead_s, period_s,
        )  # fmt: skip
        self.reset()

    def reset(self) -> None:
        self.predicted_deg = math.nan
        self._command = ValveCommand(False, False)
        self._next_s = -math.inf
        self._last: tuple[float, float] | None = None

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand:
        if t_s < self._next_s:
            return self._command
        self._next_s = t_s + self.period_s - 1e-9
        theta = self.sensor(measurement_mpa)
        rate = 0.0 if self._last is None else (theta - self._last[1]) / (t_s - self._last[0])
        self._last = (t_s, theta)
        self.predicted_deg = theta + self.lead_s * rate
        error = reference_deg - self.predicted_deg
        band = self.deadzone * abs(reference_deg)
        if error > band:
            self._command = ValveCommand(True, False)
        elif error < -band:
            self._command = ValveCommand(False, True)
        return self._command


@declare_ranges(
    deadzone=Range(0.0, 1.0, "fraction of |θr|", high_inclusive=False),
    lead=Range(0.0, 1.0, "s", "longer than the slowest valve and angle lag together"),
    period=Range(0.0, 1.0, "s", low_inclusive=False),
)
def lead_bang_bang(
    model, *, deadzone: float = 0.05, lead: float = 0.05, period: float = 0.01
) -> LeadBangBang:
    """Bang-bang on the virtual angle predicted ``lead`` seconds ahead.

    Its parameters declare their ranges (``declare_ranges``): ``--set lead=5`` is
    refused before the run, naming the range, as for the built-in controllers.

    Parameters
    ----------
    deadzone : float, default 0.05
        Band around the reference, fraction of |θr| (paper B: 5 %).
    lead : float, default 0.05
        Look-ahead of the angle, s.
    period : float, default 0.01
        Control period, s (100 Hz).
    """
    return LeadBangBang(model.virtual_sensor, deadzone, lead, period)


CONTROLLERS.register("lead-bang-bang", lead_bang_bang, replace=True)


def main(reference: str = "square:90:4", duration_s: float = 12.0, seed: int = 0) -> dict:
    """Paper B's bang-bang and the lead variant on the same simulated rig; their metrics."""
    results = {}
    for name, settings in (("bang-bang", ()), ("lead-bang-bang", ("lead=0.05",))):
        run = simulate_control(
            reference=reference,
            controller=name,
            assignments=settings,
            plant="surrogate",
            duration_s=duration_s,
            seed=seed,
        )
        metrics = run.summary["metrics"]
        results[name] = metrics
        print(
            f"{name:15s} {run.summary['controller_params']}: MAPE {metrics['mape_pct']:.1f} %, "
            f"overshoot {metrics['overshoot_pct']:.1f} %, {metrics['switches']} valve switches"
        )
    return results


if __name__ == "__main__":
    main()
